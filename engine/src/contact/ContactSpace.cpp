#include "contact/ContactSpace.h"

#include "Cloth.h"

#include <weft/collision/Proximity.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <unordered_map>

namespace weft {

void ContactSpace::build(std::span<Cloth* const> cloths) {
  m_cloths.assign(cloths.begin(), cloths.end());
  m_firstVertex.clear();
  x.clear();
  v.clear();
  inverseMass.clear();
  owner.clear();
  rest.clear();
  owners.clear();
  triangles.clear();
  triangleEdges.clear();
  edges.clear();
  restLengths.clear();
  longest.clear();
  tetherAnchor.clear();
  tetherLength.clear();
  anchorDistance.clear();
  edgeOrder.clear();
  edgeSlotBegin.clear();
  edgeSlots.clear();
  m_faceContacts.clear();
  for (std::size_t c = 0; c < m_cloths.size(); ++c) {
    const Cloth& cloth = *m_cloths[c];
    const ClothModel& model = cloth.model();
    const ClothSettings& settings = cloth.settings();
    const Index offset = Index(x.size());
    m_firstVertex.push_back(offset);
    owners.push_back(ContactOwner{settings.material.thickness, settings.material.friction,
                                  settings.selfCollision, settings.collideWithOtherCloths});
    m_faceContacts.push_back(settings.faceContacts);
    x.insert(x.end(), cloth.positions().begin(), cloth.positions().end());
    v.insert(v.end(), cloth.velocities().begin(), cloth.velocities().end());
    inverseMass.insert(inverseMass.end(), cloth.inverseMasses().begin(),
                       cloth.inverseMasses().end());
    owner.insert(owner.end(), model.vertexCount(), Index(c));
    rest.insert(rest.end(), model.restPositions().begin(), model.restPositions().end());
    // A limit of 0 or infinity means none.
    const Real limit = settings.material.strainLimit;
    const Real factor = limit > 0 && std::isfinite(limit) ? 1 + limit
                                                          : std::numeric_limits<Real>::infinity();
    std::unordered_map<std::uint64_t, Index> edgeOfKey;
    for (const Edge& edge : model.edges()) {
      edgeOfKey[(std::uint64_t(edge.vertices[0]) << 32) | edge.vertices[1]] = Index(edges.size());
      edges.push_back({edge.vertices[0] + offset, edge.vertices[1] + offset});
      restLengths.push_back(edge.restLength);
      longest.push_back(factor * edge.restLength);
    }
    const std::vector<Index>& indices = model.indices();
    for (Index t = 0; t < model.triangleCount(); ++t) {
      std::array<Index, 3> corners, sides;
      for (int k = 0; k < 3; ++k) {
        corners[k] = indices[3 * t + k] + offset;
        Index a = indices[3 * t + k], b = indices[3 * t + (k + 1) % 3];
        if (a > b) std::swap(a, b);
        sides[k] = edgeOfKey.at((std::uint64_t(a) << 32) | b);
      }
      triangles.push_back(corners);
      triangleEdges.push_back(sides);
    }
    buildTethers(cloth, offset, factor);
  }
  edgeOrder.resize(edges.size());
  for (Index e = 0; e < Index(edges.size()); ++e) edgeOrder[e] = e;
  const auto nearer = [&](Index e) {
    return std::min(anchorDistance[edges[e][0]], anchorDistance[edges[e][1]]);
  };
  std::stable_sort(edgeOrder.begin(), edgeOrder.end(),
                   [&](Index a, Index b) { return nearer(a) < nearer(b); });
  listEdgeSlots();
  startX = x;
  startV = v;
}

void ContactSpace::listEdgeSlots() {
  if (edgeOrder.size() != edges.size()) {
    edgeOrder.resize(edges.size());
    for (Index e = 0; e < Index(edges.size()); ++e) edgeOrder[e] = e;
  }
  edgeSlotBegin.assign(x.size() + 1, 0);
  for (const std::array<Index, 2>& edge : edges) {
    ++edgeSlotBegin[edge[0] + 1];
    ++edgeSlotBegin[edge[1] + 1];
  }
  for (std::size_t i = 0; i < x.size(); ++i) edgeSlotBegin[i + 1] += edgeSlotBegin[i];
  edgeSlots.resize(2 * edges.size());
  std::vector<Index> fill(edgeSlotBegin.begin(), edgeSlotBegin.end() - 1);
  for (Index slot = 0; slot < Index(edges.size()); ++slot) {
    for (Index vertex : edges[edgeOrder[slot]]) edgeSlots[fill[vertex]++] = slot;
  }
}

void ContactSpace::setMovable(std::size_t cloth, bool movable) {
  const std::vector<Real>& own = m_cloths[cloth]->inverseMasses();
  const auto first = inverseMass.begin() + m_firstVertex[cloth];
  if (movable) {
    std::copy(own.begin(), own.end(), first);
  } else {
    std::fill(first, first + own.size(), Real(0));
  }
}

void ContactSpace::buildTethers(const Cloth& cloth, Index offset, Real factor) {
  const Index n = cloth.vertexCount();
  tetherAnchor.resize(offset + n, kInvalidIndex);
  tetherLength.resize(offset + n, std::numeric_limits<Real>::infinity());
  anchorDistance.resize(offset + n, std::numeric_limits<Real>::infinity());
  const std::vector<Index>& pins = cloth.settings().pinnedVertices;
  if (pins.empty() || !std::isfinite(factor)) return;
  // Dijkstra from every pin at once over the mesh edges at their rest lengths: the shortest path
  // is at least the geodesic, so the tether is never tighter than the edges allow.
  std::vector<std::vector<std::pair<Index, Real>>> neighbours(n);
  for (const Edge& edge : cloth.model().edges()) {
    neighbours[edge.vertices[0]].push_back({edge.vertices[1], edge.restLength});
    neighbours[edge.vertices[1]].push_back({edge.vertices[0], edge.restLength});
  }
  std::vector<Real> distance(n, std::numeric_limits<Real>::infinity());
  std::vector<Index> anchor(n, kInvalidIndex);
  using Item = std::pair<Real, Index>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (Index pin : pins) {
    distance[pin] = 0;
    anchor[pin] = pin;
    queue.push({0, pin});
  }
  while (!queue.empty()) {
    const auto [d, vertex] = queue.top();
    queue.pop();
    if (d > distance[vertex]) continue;
    for (const auto& [next, length] : neighbours[vertex]) {
      // Ties go to the lower anchor, so the tethers do not depend on the queue's order.
      const Real through = d + length;
      if (through < distance[next] || (through == distance[next] && anchor[vertex] < anchor[next])) {
        distance[next] = through;
        anchor[next] = anchor[vertex];
        queue.push({through, next});
      }
    }
  }
  for (Index i = 0; i < n; ++i) anchorDistance[offset + i] = distance[i];
  for (Index i = 0; i < n; ++i) {
    if (cloth.pinnedMask()[i] || anchor[i] == kInvalidIndex) continue;
    tetherAnchor[offset + i] = offset + anchor[i];
    tetherLength[offset + i] = factor * distance[i];
  }
}

bool ContactSpace::builtFor(std::span<Cloth* const> cloths) const {
  return std::equal(cloths.begin(), cloths.end(), m_cloths.begin(), m_cloths.end());
}

Index ContactSpace::edgesOverLimit(Real tolerance) const {
  Index over = 0;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const Index a = edges[e][0], b = edges[e][1];
    if (inverseMass[a] == 0 && inverseMass[b] == 0) continue;
    over += (x[b] - x[a]).norm() > longest[e] + tolerance * restLengths[e];
  }
  return over;
}

void ContactSpace::gather() {
  for (std::size_t c = 0; c < m_cloths.size(); ++c) {
    const Cloth& cloth = *m_cloths[c];
    std::copy(cloth.positions().begin(), cloth.positions().end(), x.begin() + m_firstVertex[c]);
    std::copy(cloth.velocities().begin(), cloth.velocities().end(), v.begin() + m_firstVertex[c]);
  }
}

void ContactSpace::scatter() const {
  for (std::size_t c = 0; c < m_cloths.size(); ++c) {
    Cloth& cloth = *m_cloths[c];
    const Index first = m_firstVertex[c], count = cloth.vertexCount();
    cloth.setContactResult(std::span<const Vec3>(x).subspan(first, count),
                           std::span<const Vec3>(v).subspan(first, count));
  }
}

Real ContactSpace::maxThickness() const {
  Real thickness = 0;
  for (const ContactOwner& o : owners) thickness = std::max(thickness, o.thickness);
  return thickness;
}

Aabb ContactSpace::movablePaths(std::span<const Vec3> end) const {
  Aabb paths = Aabb::empty();
  for (Index i = 0; i < vertexCount(); ++i) {
    if (inverseMass[i] == 0) continue;
    paths.expand(startX[i]);
    paths.expand(end[i]);
  }
  return paths;
}

Real ContactSpace::pairThickness(Index a, Index b) const {
  return std::max(owners[owner[a]].thickness, owners[owner[b]].thickness);
}

bool ContactSpace::restNeighbours(Index vertex, const std::array<Index, 3>& triangle) const {
  const auto& c = triangle;
  return owner[vertex] == owner[c[0]] &&
         closestPointOnTriangle(rest[vertex], rest[c[0]], rest[c[1]], rest[c[2]]).distance <
             kPairReach * pairThickness(vertex, c[0]);
}

bool ContactSpace::restNeighbours(const std::array<Index, 2>& p,
                                  const std::array<Index, 2>& q) const {
  return owner[p[0]] == owner[q[0]] &&
         closestPointsOnSegments(rest[p[0]], rest[p[1]], rest[q[0]], rest[q[1]]).distance <
             kPairReach * pairThickness(p[0], q[0]);
}

Real ContactSpace::pairFriction(Index a, Index b) const {
  if (owner[a] == owner[b]) return owners[owner[a]].friction;
  return std::sqrt(owners[owner[a]].friction * owners[owner[b]].friction);
}

bool ContactSpace::pairsAllowed(Index a, Index b) const {
  const ContactOwner& first = owners[owner[a]];
  if (owner[a] == owner[b]) return first.selfCollision;
  return first.otherCloths && owners[owner[b]].otherCloths;
}

}  // namespace weft
