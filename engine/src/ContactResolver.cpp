#include "ContactResolver.h"

#include <weft/collision/ContinuousCollision.h>
#include <weft/collision/Proximity.h>
#include <weft/threading/GrainSizes.h>
#include <weft/threading/Profiler.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

namespace weft {
namespace {

// Passes of impulse-based continuous detection before the impact-zone fail-safe takes over.
constexpr int kImpulsePasses = 6;
// Merging passes of the impact zones before the last resort freezes what still collides.
constexpr int kZonePasses = 12;
// Share of the remaining overlap that proximity repulsion removes per step (BFA02 use 0.1).
constexpr Real kRepulsionRate = 0.1;
// A swept hit is resolved to a separating speed that opens this share of the thickness within
// the step, so the pair is not found touching again at the end of the step.
constexpr Real kImpactSeparation = 0.25;
// Feature pairs per parallel block: a closest-point test costs ~50–100 ns and a swept test a few
// hundred, so 128 pairs are ~5–40 µs of work, above a fork/join (GrainSizes.h); the curtain's
// few thousand pairs still make tens of blocks.
constexpr TaskSystem::Index kGrainFeaturePairs = 128;
// Candidate triangle pairs per parallel block when collecting feature pairs: a few box tests
// each, ~50–100 ns, so 256 pairs are ~15–25 µs.
constexpr TaskSystem::Index kGrainTrianglePairs = 256;

// A vertex that ends within this many thicknesses of a collider is held by it (the collider
// response leaves its contacts at exactly one thickness).
constexpr Real kHeldReach = 1.5;
// A held vertex counts as this much lighter in inverse mass (1000× heavier) in impulses.
constexpr Real kHeldInverseMassScale = 1e-3;
// Sweeps of the proximity impulses when colliders are given (one otherwise): between sweeps the
// clamp puts back what an impulse pushed into a collider, and the next sweep gives the rest of
// the separation to the other side (1 − 2⁻⁴ of it when both vertices count as held).
constexpr int kProximitySweepsWithColliders = 4;

Index findRoot(std::vector<Index>& parent, Index vertex) {
  while (parent[vertex] != vertex) {
    parent[vertex] = parent[parent[vertex]];  // path halving
    vertex = parent[vertex];
  }
  return vertex;
}

}  // namespace

ContactResolver::ContactResolver(TaskSystem* tasks) : m_tasks(tasks) {
  if (m_tasks && !m_tasks->isSerial()) {
    m_workerContacts = std::make_unique<PerWorker<std::vector<FoundContact>>>(*m_tasks);
  }
}

void ContactResolver::setTopology(std::vector<std::array<Index, 3>> triangles,
                                  std::vector<std::array<Index, 3>> triangleEdges,
                                  std::vector<std::array<Index, 2>> edges, Vec3Array rest,
                                  std::vector<Index> owners) {
  m_triangles = std::move(triangles);
  m_triangleEdges = std::move(triangleEdges);
  m_edges = std::move(edges);
  m_rest = std::move(rest);
  m_owner = std::move(owners);
  m_proximityCached = false;
  m_certificateValid = false;
  m_zoneParent.resize(m_rest.size());
  // Triangles around every vertex (ascending) and the one or two triangles of every edge.
  const Index vertexCount = Index(m_rest.size());
  m_vertexTriangleBegin.assign(vertexCount + 1, 0);
  for (const auto& triangle : m_triangles) {
    for (Index vertex : triangle) ++m_vertexTriangleBegin[vertex + 1];
  }
  for (Index i = 0; i < vertexCount; ++i) m_vertexTriangleBegin[i + 1] += m_vertexTriangleBegin[i];
  m_vertexTriangles.resize(m_vertexTriangleBegin[vertexCount]);
  std::vector<Index> fill(m_vertexTriangleBegin.begin(), m_vertexTriangleBegin.end() - 1);
  for (Index t = 0; t < m_triangles.size(); ++t) {
    for (Index vertex : m_triangles[t]) m_vertexTriangles[fill[vertex]++] = t;
  }
  m_edgeTriangles.assign(m_edges.size(), {kInvalidIndex, kInvalidIndex});
  for (Index t = 0; t < m_triangleEdges.size(); ++t) {
    for (Index edge : m_triangleEdges[t]) {
      std::array<Index, 2>& slots = m_edgeTriangles[edge];
      (slots[0] == kInvalidIndex ? slots[0] : slots[1]) = t;
    }
  }
}

void ContactResolver::pairParameters(Index first, Index second, Real& thickness,
                                     Real& friction) const {
  const ContactOwner& a = m_owners[m_owner[first]];
  const ContactOwner& b = m_owners[m_owner[second]];
  if (m_owner[first] == m_owner[second]) {
    thickness = a.thickness;
    friction = a.friction;
  } else {
    // As for cloth against colliders: the larger thickness, the geometric mean of the frictions.
    thickness = std::max(a.thickness, b.thickness);
    friction = std::sqrt(a.friction * b.friction);
  }
}

inline bool ContactResolver::sharesVertex(Index first, Index second) const {
  return trianglesShareVertex(m_triangles[first], m_triangles[second]);
}

void ContactResolver::findTrianglePairsTouching(const Vec3Array& from, const Vec3Array& to,
                                                Real inflate, const std::vector<char>& marked,
                                                std::vector<TrianglePair>& pairs) {
  findTrianglePairs(from, to, inflate, false, pairs);
  std::erase_if(pairs, [&](const TrianglePair& pair) {
    return !marked[pair.first] && !marked[pair.second];
  });
}

void ContactResolver::collectFeaturePairs(const Vec3Array& from, const Vec3Array& to, Real margin,
                                          const std::vector<char>* dirty) {
  WEFT_PROFILE_ZONE("feature pairs");
  // Every vertex's box over the step, once, instead of once per triangle pair it is in.
  const Index vertexCount = Index(from.size());
  m_vertexBoxes.resize(vertexCount);
  auto boxVertices = [&](Index begin, Index end, int) {
    for (Index i = begin; i < end; ++i) m_vertexBoxes[i] = Aabb::fromCorners(from[i], to[i]);
  };
  if (m_tasks) {
    m_tasks->parallelFor(vertexCount, kGrainVertices, boxVertices);
  } else {
    boxVertices(0, vertexCount, 0);
  }
  // Likewise every triangle's and edge's box (the same min and max, so the same bits): a
  // triangle is in a few candidate pairs, an edge's box is asked for by each of them.
  const Index triangleCount = Index(m_triangles.size());
  const Index edgeCount = Index(m_edges.size());
  m_triangleBoxes.resize(triangleCount);
  m_edgeBoxes.resize(edgeCount);
  auto boxFeatures = [&](Index begin, Index end, int) {
    for (Index i = begin; i < end; ++i) {
      if (i < triangleCount) {
        const std::array<Index, 3>& c = m_triangles[i];
        Aabb box = m_vertexBoxes[c[0]];
        box.expand(m_vertexBoxes[c[1]]);
        box.expand(m_vertexBoxes[c[2]]);
        m_triangleBoxes[i] = box;
      } else {
        const std::array<Index, 2>& c = m_edges[i - triangleCount];
        Aabb box = m_vertexBoxes[c[0]];
        box.expand(m_vertexBoxes[c[1]]);
        m_edgeBoxes[i - triangleCount] = box;
      }
    }
  };
  if (m_tasks) {
    m_tasks->parallelFor(triangleCount + edgeCount, kGrainVertices, boxFeatures);
  } else {
    boxFeatures(0, triangleCount + edgeCount, 0);
  }
  auto triangleBox = [&](Index triangle) -> const Aabb& { return m_triangleBoxes[triangle]; };
  auto edgeBox = [&](Index edge) -> const Aabb& { return m_edgeBoxes[edge]; };
  // A feature pair is reached through several triangle pairs; it is taken from one of them
  // only, its canonical pair, so no sort is needed to remove the others and the features come
  // out in the (sorted) order of the triangle pairs. Vertex v against triangle B: from the
  // lowest-numbered triangle around v that shares no vertex with B. Edge a against edge b: from
  // the lowest (lo, hi) of their triangles that share no vertex. The broad phase reports that
  // pair whenever it reports any (its boxes hold the features' boxes; margin ≤ 2 × inflate), so
  // nothing is lost.
  //
  // Both tests below ask only whether the pair at hand is the canonical one, so they stop at the
  // first candidate that beats it and test the cheap order before the vertex sharing: the same
  // answers as finding the canonical pair and comparing, for less work (most of this stage's).
  // A pair whose triangles share a vertex is canonical for nothing; collect() skips it, so both
  // tests are asked only about pairs that share none.
  auto isVertexOwner = [&](Index vertex, Index owner, Index triangle) {
    // The triangles around the vertex are ascending: `owner` (sharing no vertex with
    // `triangle`) is the lowest that shares none when every one before it shares one.
    for (Index k = m_vertexTriangleBegin[vertex]; k < m_vertexTriangleBegin[vertex + 1]; ++k) {
      const Index candidate = m_vertexTriangles[k];
      if (candidate == owner) return true;
      if (!sharesVertex(candidate, triangle)) return false;
    }
    return false;
  };
  auto isEdgeOwner = [&](Index a, Index b, const TrianglePair& pair) {
    // `pair` (a triangle of each edge, sharing no vertex) is the canonical pair when it is one
    // of the edges' pairs of triangles and no other of those that shares none orders before it.
    bool listed = false;
    for (Index ta : m_edgeTriangles[a]) {
      for (Index tb : m_edgeTriangles[b]) {
        if (ta == kInvalidIndex || tb == kInvalidIndex) continue;
        const TrianglePair candidate{std::min(ta, tb), std::max(ta, tb)};
        if (candidate < pair && !sharesVertex(ta, tb)) return false;
        listed = listed || candidate == pair;
      }
    }
    return listed;
  };
  auto touchesDirty = [&](Index vertex, const std::array<Index, 3>& triangle) {
    return !dirty || (*dirty)[vertex] || (*dirty)[triangle[0]] || (*dirty)[triangle[1]] ||
           (*dirty)[triangle[2]];
  };
  auto collect = [&](Index begin, Index end, std::vector<std::array<Index, 2>>& vertexTriangle,
                     std::vector<std::array<Index, 2>>& edgeEdge) {
    for (Index k = begin; k < end; ++k) {
      const TrianglePair& pair = m_trianglePairs[k];
      if (sharesVertex(pair.first, pair.second)) continue;  // none from the broad phase
      const Aabb& firstBox = triangleBox(pair.first);
      const Aabb& secondBox = triangleBox(pair.second);
      // Every vertex and edge box of a triangle lies in its box, and rounding is monotone, so
      // each one inflated by the margin lies in the triangle's box inflated by it: when that
      // misses the other triangle's box, so does every test of that side below. (The broad
      // phase inflates both boxes and refits loosely: about one curtain pair in eight drops.)
      Aabb firstReach = firstBox;
      firstReach.inflate(margin);
      Aabb secondReach = secondBox;
      secondReach.inflate(margin);
      const bool firstReaches = firstReach.overlaps(secondBox);
      const bool secondReaches = secondReach.overlaps(firstBox);
      if (!firstReaches && !secondReaches) continue;
      // The vertices of triangle `from` that reach triangle `to` (box `toBox`) and own the pair.
      const auto addVertexContacts = [&](Index from, Index to, const Aabb& toBox) {
        for (Index vertex : m_triangles[from]) {
          Aabb box = m_vertexBoxes[vertex];
          box.inflate(margin);
          if (box.overlaps(toBox) && touchesDirty(vertex, m_triangles[to]) &&
              isVertexOwner(vertex, from, to)) {
            vertexTriangle.push_back({vertex, to});
          }
        }
      };
      if (firstReaches) addVertexContacts(pair.first, pair.second, secondBox);
      if (secondReaches) addVertexContacts(pair.second, pair.first, firstBox);
      if (!firstReaches) continue;
      // The broad phase reports only triangles that share no vertex, so their edges share none
      // either.
      const std::array<Index, 3>& secondEdges = m_triangleEdges[pair.second];
      for (Index a : m_triangleEdges[pair.first]) {
        Aabb first = edgeBox(a);
        first.inflate(margin);
        if (!first.overlaps(secondBox)) continue;
        for (int j = 0; j < 3; ++j) {
          const Index b = secondEdges[j];
          if (first.overlaps(edgeBox(b)) &&
              (!dirty || (*dirty)[m_edges[a][0]] || (*dirty)[m_edges[a][1]] ||
               (*dirty)[m_edges[b][0]] || (*dirty)[m_edges[b][1]]) &&
              isEdgeOwner(a, b, pair)) {
            edgeEdge.push_back({std::min(a, b), std::max(a, b)});
          }
        }
      }
    }
  };
  m_vertexTriangle.clear();
  m_edgeEdge.clear();
  const Index pairCount = Index(m_trianglePairs.size());
  if (!m_tasks || m_tasks->isSerial() || pairCount <= kGrainTrianglePairs) {
    collect(0, pairCount, m_vertexTriangle, m_edgeEdge);
    return;
  }
  // In parallel over fixed blocks, each block into its own lists, joined in block order: the
  // same lists as the serial loop.
  const Index blocks = TaskSystem::blockCount(pairCount, kGrainTrianglePairs);
  if (m_blockFeatures.size() < blocks) m_blockFeatures.resize(blocks);
  m_tasks->parallelFor(pairCount, kGrainTrianglePairs, [&](Index begin, Index end, int) {
    BlockFeatures& block = m_blockFeatures[begin / kGrainTrianglePairs];
    block.vertexTriangle.clear();
    block.edgeEdge.clear();
    collect(begin, end, block.vertexTriangle, block.edgeEdge);
  });
  for (Index b = 0; b < blocks; ++b) {
    const BlockFeatures& block = m_blockFeatures[b];
    m_vertexTriangle.insert(m_vertexTriangle.end(), block.vertexTriangle.begin(), block.vertexTriangle.end());
    m_edgeEdge.insert(m_edgeEdge.end(), block.edgeEdge.begin(), block.edgeEdge.end());
  }
}

template <class Test>
void ContactResolver::findContacts(Test&& test) {
  WEFT_PROFILE_ZONE("narrow phase");
  const Index total = Index(m_vertexTriangle.size() + m_edgeEdge.size());
  m_contacts.clear();
  if (!m_workerContacts || total <= kGrainFeaturePairs) {
    Contact contact;
    for (Index pair = 0; pair < total; ++pair) {
      if (test(pair, contact)) m_contacts.push_back(contact);
    }
    return;
  }
  m_workerContacts->forEach([](std::vector<FoundContact>& found) { found.clear(); });
  m_tasks->parallelFor(total, kGrainFeaturePairs, [&](Index begin, Index end, int worker) {
    std::vector<FoundContact>& found = (*m_workerContacts)[worker];
    Contact contact;
    for (Index pair = begin; pair < end; ++pair) {
      if (test(pair, contact)) found.push_back({pair, contact});
    }
  });
  // Which worker found which contact depends on timing; the pair index puts them back in the
  // order the serial loop finds them, so the impulses that follow see the same sequence.
  m_found.clear();
  m_workerContacts->forEach([this](std::vector<FoundContact>& found) {
    m_found.insert(m_found.end(), found.begin(), found.end());
  });
  std::sort(m_found.begin(), m_found.end(),
            [](const FoundContact& a, const FoundContact& b) { return a.pair < b.pair; });
  for (const FoundContact& found : m_found) m_contacts.push_back(found.contact);
  // A worker may find any share of them next time: room for all, so that allocation follows the
  // number of contacts and never the timing of the threads.
  const std::size_t count = m_found.size();
  m_workerContacts->forEach([count](std::vector<FoundContact>& found) {
    if (found.capacity() < count) found.reserve(count);
  });
}

Real ContactResolver::impulseInverseMass(Index vertex, const std::vector<Real>& inverseMasses) {
  if (m_colliders.empty() || inverseMasses[vertex] == 0) return inverseMasses[vertex];
  // Decided on first use, from where the step was to end: impulses run serially, so the cache
  // fills in the same order on any thread count (and depends only on x₁ anyway).
  if (m_held[vertex] < 0) {
    const Real reach = kHeldReach * m_owners[m_owner[vertex]].thickness;
    m_held[vertex] = 0;
    for (const ColliderFrame& collider : m_colliders) {
      if (queryPoint(*collider.shape, (*m_stepEnd)[vertex]).distance < reach) m_held[vertex] = 1;
    }
  }
  return m_held[vertex] ? kHeldInverseMassScale * inverseMasses[vertex] : inverseMasses[vertex];
}

void ContactResolver::clampToColliders(const Vec3Array& start, Real h) {
  if (m_colliders.empty()) return;
  for (Index i = 0; i < m_touched.size(); ++i) {
    if (!m_touched[i]) continue;
    const Real thickness = m_owners[m_owner[i]].thickness;
    for (const ColliderFrame& collider : m_colliders) {
      // Not only where the corrected step ends but the way there, relative to the body: an
      // impulse may send a vertex through a thin or fast body without ending inside it.
      const Vec3 end = start[i] + h * m_velocity[i];
      const Vec3 outside = keepOutside(collider, start[i], end, thickness);
      if (outside != end) m_velocity[i] = (outside - start[i]) / h;
    }
  }
}

void ContactResolver::applyImpulse(const Contact& contact, Real targetNormalSpeed,
                                   const std::vector<Real>& inverseMasses) {
  // A pair already separating fast enough needs nothing: decided before the masses, whose held
  // test queries the colliders.
  Vec3 relative = Vec3::Zero();
  for (int k = 0; k < 4; ++k) relative += contact.weights[k] * m_velocity[contact.vertices[k]];
  const Real normalSpeed = relative.dot(contact.normal);
  if (normalSpeed >= targetNormalSpeed) return;
  Real effectiveInverseMass = 0;
  std::array<Real, 4> inverseMass;
  for (int k = 0; k < 4; ++k) {
    inverseMass[k] = impulseInverseMass(contact.vertices[k], inverseMasses);
    effectiveInverseMass += contact.weights[k] * contact.weights[k] * inverseMass[k];
  }
  if (effectiveInverseMass <= 0) return;  // all four pinned: nothing can move
  // Held vertices count as heavy so that the free side takes the impulse. But when the free side
  // holds the pair point only with a small weight w (a vertex near the end of an edge, near a
  // corner of a triangle), taking all of the relative change throws that vertex at Δu / w: a
  // layer landing on another draped over a sphere got 10–20 m/s this way. When any vertex would
  // change by more than the relative change, the true masses share the impulse instead (with
  // equal masses no vertex then changes by more than Δu); the clamp afterwards puts back what
  // reaches into a collider, and the next sweep gives the rest to the free side.
  Real largestShare = 0;
  for (int k = 0; k < 4; ++k) {
    largestShare = std::max(largestShare, std::abs(contact.weights[k]) * inverseMass[k]);
  }
  if (largestShare > effectiveInverseMass) {
    effectiveInverseMass = 0;
    for (int k = 0; k < 4; ++k) {
      inverseMass[k] = inverseMasses[contact.vertices[k]];
      effectiveInverseMass += contact.weights[k] * contact.weights[k] * inverseMass[k];
    }
  }
  const Real normalChange = targetNormalSpeed - normalSpeed;
  Vec3 change = normalChange * contact.normal;
  // Coulomb friction: remove at most μ·|Δu_n| of relative tangential speed.
  const Vec3 tangential = relative - normalSpeed * contact.normal;
  const Real tangentialSpeed = tangential.norm();
  if (contact.friction > 0 && tangentialSpeed > 0) {
    change -= std::min<Real>(1, contact.friction * normalChange / tangentialSpeed) * tangential;
  }
  // Δv_i = w_i λ / m_i with λ = Δu / Σ w_j² / m_j gives exactly the relative change Δu.
  const Vec3 lambda = change / effectiveInverseMass;
  for (int k = 0; k < 4; ++k) {
    const Index vertex = contact.vertices[k];
    m_velocity[vertex] += contact.weights[k] * inverseMass[k] * lambda;
    m_touched[vertex] = 1;
  }
}

void ContactResolver::holdContacts(const std::vector<Contact>& contacts) {
  if (!m_recordSeparations) return;
  for (const Contact& contact : contacts) {
    m_separationHolds.push_back(SeparationHold{contact.vertices, contact.weights, contact.normal,
                                               contact.thickness});
  }
}

bool ContactResolver::findImpacts(const Vec3Array& start, Real h) {
  for (std::size_t i = 0; i < start.size(); ++i) m_end[i] = start[i] + h * m_velocity[i];
  // The CCD tolerance is 1 µm: boxes inflated by a little more catch every contact it reports.
  const Real inflate = 2 * kDefaultContactTolerance;
  if (m_certificateUsable) {
    // Only pairs with a vertex whose end moved since the last test, or that was in one of its
    // contacts, can test positive (setBroadPhaseIsPure); the others would test exactly as then,
    // negative.
    Index dirtyCount = 0;
    m_dirtyVertex.assign(start.size(), 0);
    for (std::size_t i = 0; i < start.size(); ++i) {
      if (m_certificateForced[i] || std::memcmp(&m_end[i], &m_certificateEnd[i], sizeof(Vec3)) != 0) {
        m_dirtyVertex[i] = 1;
        ++dirtyCount;
      }
    }
    m_contacts.clear();
    if (dirtyCount == 0) return false;
    m_dirtyTriangle.assign(m_triangles.size(), 0);
    for (Index t = 0; t < m_triangles.size(); ++t) {
      const std::array<Index, 3>& c = m_triangles[t];
      m_dirtyTriangle[t] = m_dirtyVertex[c[0]] | m_dirtyVertex[c[1]] | m_dirtyVertex[c[2]];
    }
    findTrianglePairsTouching(start, m_end, inflate, m_dirtyTriangle, m_trianglePairs);
    collectFeaturePairs(start, m_end, inflate, &m_dirtyVertex);
  } else {
    findTrianglePairs(start, m_end, inflate, false, m_trianglePairs);
    collectFeaturePairs(start, m_end, inflate);
  }
  const Index vertexTriangleCount = Index(m_vertexTriangle.size());
  findContacts([&](Index pair, Contact& contact) {
    if (pair < vertexTriangleCount) {
      const auto& [vertex, triangle] = m_vertexTriangle[pair];
      const std::array<Index, 3>& corners = m_triangles[triangle];
      const std::array<Vec3, 3> triangleStart{start[corners[0]], start[corners[1]], start[corners[2]]};
      const std::array<Vec3, 3> triangleEnd{m_end[corners[0]], m_end[corners[1]], m_end[corners[2]]};
      const std::optional<VertexTriangleImpact> impact =
          sweptVertexTriangle(start[vertex], m_end[vertex], triangleStart, triangleEnd);
      if (!impact) return false;
      const Real t = impact->time;
      auto at = [&](Index i) { return Vec3(start[i] + t * (m_end[i] - start[i])); };
      Vec3 normal = (at(corners[1]) - at(corners[0])).cross(at(corners[2]) - at(corners[0]));
      if (normal.norm() == 0) return false;  // degenerate at impact; the zones catch it if it matters
      normal.normalize();
      // Orient the normal from the triangle towards the side the vertex came from.
      const Vec3 startPoint = impact->barycentric[0] * triangleStart[0] +
                              impact->barycentric[1] * triangleStart[1] +
                              impact->barycentric[2] * triangleStart[2];
      if (normal.dot(start[vertex] - startPoint) < 0) normal = -normal;
      contact = {{vertex, corners[0], corners[1], corners[2]},
                 {1, -impact->barycentric[0], -impact->barycentric[1], -impact->barycentric[2]},
                 normal, 0, 0, 0};
      pairParameters(vertex, corners[0], contact.thickness, contact.friction);
      return true;
    }
    const auto& [firstEdge, secondEdge] = m_edgeEdge[pair - vertexTriangleCount];
    const std::array<Index, 2>& p = m_edges[firstEdge];
    const std::array<Index, 2>& q = m_edges[secondEdge];
    const std::optional<EdgeEdgeImpact> impact =
        sweptEdgeEdge({start[p[0]], start[p[1]]}, {m_end[p[0]], m_end[p[1]]},
                      {start[q[0]], start[q[1]]}, {m_end[q[0]], m_end[q[1]]});
    if (!impact) return false;
    const Real t = impact->time, s = impact->firstParameter, u = impact->secondParameter;
    auto at = [&](Index i) { return Vec3(start[i] + t * (m_end[i] - start[i])); };
    Vec3 normal = (at(p[1]) - at(p[0])).cross(at(q[1]) - at(q[0]));
    const Vec3 startGap = ((1 - s) * start[p[0]] + s * start[p[1]]) - ((1 - u) * start[q[0]] + u * start[q[1]]);
    if (normal.norm() < 1e-12) normal = startGap;  // parallel edges: the gap is the direction
    if (normal.norm() == 0) return false;
    normal.normalize();
    if (normal.dot(startGap) < 0) normal = -normal;
    contact = {{p[0], p[1], q[0], q[1]}, {1 - s, s, -(1 - u), -u}, normal, 0, 0, 0};
    pairParameters(p[0], q[0], contact.thickness, contact.friction);
    return true;
  });
  if (m_broadPhaseIsPure) {
    // Every pair outside m_contacts tests negative along start → m_end: the certificate for the
    // next tests of this start, with the vertices of the contacts always tested again.
    if (!m_certificateUsable) m_certificateStart = start;
    m_certificateEnd = m_end;
    m_certificateForced.assign(start.size(), 0);
    for (const Contact& contact : m_contacts) {
      for (Index vertex : contact.vertices) m_certificateForced[vertex] = 1;
    }
    m_certificateValid = m_certificateUsable = true;
  }
  return !m_contacts.empty();
}

void ContactResolver::rigidifyZones(const Vec3Array& start, const std::vector<Real>& inverseMasses) {
  // Gather each zone's vertices (ordered by root, then vertex: deterministic), then give them one
  // rigid velocity that keeps the zone's linear and angular momentum. Pinned vertices, of
  // infinite mass, make the zone move with them instead.
  std::map<Index, std::vector<Index>> zones;
  for (Index vertex = 0; vertex < m_zoneParent.size(); ++vertex) {
    if (m_inZone[vertex]) zones[findRoot(m_zoneParent, vertex)].push_back(vertex);
  }
  for (const auto& [root, members] : zones) {
    Real mass = 0;
    Vec3 centre = Vec3::Zero(), momentum = Vec3::Zero(), pinnedVelocity = Vec3::Zero();
    int pinned = 0;
    for (Index vertex : members) {
      if (inverseMasses[vertex] == 0) {
        pinnedVelocity += m_velocity[vertex];
        ++pinned;
        continue;
      }
      const Real m = 1 / inverseMasses[vertex];
      mass += m;
      centre += m * start[vertex];
      momentum += m * m_velocity[vertex];
    }
    for (Index vertex : members) m_touched[vertex] |= inverseMasses[vertex] != 0;
    if (pinned > 0) {
      for (Index vertex : members) {
        if (inverseMasses[vertex] != 0) m_velocity[vertex] = pinnedVelocity / pinned;
      }
      continue;
    }
    if (mass == 0) continue;
    centre /= mass;
    const Vec3 linear = momentum / mass;
    Vec3 angularMomentum = Vec3::Zero();
    Mat3 inertia = Mat3::Zero();
    for (Index vertex : members) {
      const Real m = 1 / inverseMasses[vertex];
      const Vec3 r = start[vertex] - centre;
      angularMomentum += m * r.cross(m_velocity[vertex] - linear);
      inertia += m * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
    }
    // Collinear zones have a singular inertia tensor; the pseudo-inverse drops the spin about
    // their line, which no contact could have set anyway.
    const Vec3 omega = inertia.completeOrthogonalDecomposition().solve(angularMomentum);
    for (Index vertex : members) m_velocity[vertex] = linear + omega.cross(start[vertex] - centre);
  }
}

bool ContactResolver::proximityCacheMatches(const Vec3Array& start,
                                            std::span<const ContactOwner> owners) const {
  if (!m_proximityCached || start.size() != m_proximityStart.size() ||
      owners.size() != m_proximityOwners.size()) {
    return false;
  }
  // Bit for bit (memcmp: −0 and +0 differ, NaN never matches itself), the strictest test.
  if (std::memcmp(start.data(), m_proximityStart.data(), start.size() * sizeof(Vec3)) != 0) return false;
  for (std::size_t k = 0; k < owners.size(); ++k) {
    if (std::memcmp(&owners[k].thickness, &m_proximityOwners[k].thickness, sizeof(Real)) != 0 ||
        std::memcmp(&owners[k].friction, &m_proximityOwners[k].friction, sizeof(Real)) != 0) {
      return false;
    }
  }
  return true;
}

void ContactResolver::findProximityContacts(const Vec3Array& start, Real maxThickness) {
  findTrianglePairs(start, start, maxThickness, true, m_trianglePairs);
  collectFeaturePairs(start, start, maxThickness);
  const Index vertexTriangleCount = Index(m_vertexTriangle.size());
  // The exact distance tests, in parallel: they read only x₀ and the rest shape.
  findContacts([&](Index pair, Contact& contact) {
    if (pair < vertexTriangleCount) {
      const auto& [vertex, triangle] = m_vertexTriangle[pair];
      const std::array<Index, 3>& c = m_triangles[triangle];
      Real thickness, friction;
      pairParameters(vertex, c[0], thickness, friction);
      const TriangleClosestPoint closest =
          closestPointOnTriangle(start[vertex], start[c[0]], start[c[1]], start[c[2]]);
      if (closest.distance >= thickness) return false;
      // Features that are this close in the rest shape are neighbours in the material (a mesh
      // finer than the thickness): the elastic forces keep them apart, repulsion would fight
      // them.
      if (m_owner[vertex] == m_owner[c[0]] &&
          closestPointOnTriangle(m_rest[vertex], m_rest[c[0]], m_rest[c[1]], m_rest[c[2]]).distance <
              thickness) {
        return false;
      }
      Vec3 normal = start[vertex] - closest.point;
      if (closest.distance < 1e-9 * thickness) {
        normal = (start[c[1]] - start[c[0]]).cross(start[c[2]] - start[c[0]]);
      }
      if (normal.norm() == 0) return false;
      contact = {{vertex, c[0], c[1], c[2]},
                 {1, -closest.barycentric[0], -closest.barycentric[1], -closest.barycentric[2]},
                 normal.normalized(), closest.distance, thickness, friction};
      return true;
    }
    const auto& [firstEdge, secondEdge] = m_edgeEdge[pair - vertexTriangleCount];
    const std::array<Index, 2>& p = m_edges[firstEdge];
    const std::array<Index, 2>& q = m_edges[secondEdge];
    Real thickness, friction;
    pairParameters(p[0], q[0], thickness, friction);
    const SegmentClosestPoints closest =
        closestPointsOnSegments(start[p[0]], start[p[1]], start[q[0]], start[q[1]]);
    if (closest.distance >= thickness) return false;
    if (m_owner[p[0]] == m_owner[q[0]] &&
        closestPointsOnSegments(m_rest[p[0]], m_rest[p[1]], m_rest[q[0]], m_rest[q[1]]).distance <
            thickness) {
      return false;  // neighbours in the material, as above
    }
    const Real s = closest.firstParameter, u = closest.secondParameter;
    Vec3 normal = ((1 - s) * start[p[0]] + s * start[p[1]]) - ((1 - u) * start[q[0]] + u * start[q[1]]);
    if (closest.distance < 1e-9 * thickness) {
      normal = (start[p[1]] - start[p[0]]).cross(start[q[1]] - start[q[0]]);
    }
    if (normal.norm() == 0) return false;
    contact = {{p[0], p[1], q[0], q[1]}, {1 - s, s, -(1 - u), -u}, normal.normalized(),
               closest.distance, thickness, friction};
    return true;
  });
}

const std::vector<ContactResolver::Contact>& ContactResolver::proximityContacts(
    const Vec3Array& start, std::span<const ContactOwner> owners) {
  Real maxThickness = 0;
  for (const ContactOwner& owner : owners) maxThickness = std::max(maxThickness, owner.thickness);
  if (!m_broadPhaseIsPure) {
    findProximityContacts(start, maxThickness);
    return m_contacts;
  }
  if (!proximityCacheMatches(start, owners)) {
    findProximityContacts(start, maxThickness);
    m_proximityContacts = m_contacts;
    m_proximityStart = start;
    m_proximityOwners.assign(owners.begin(), owners.end());
    m_proximityCached = true;
  }
  return m_proximityContacts;
}

void ContactResolver::findProximityPairs(const Vec3Array& start,
                                         std::span<const ContactOwner> owners,
                                         std::vector<SeparationHold>& pairs) {
  m_owners = owners;
  pairs.clear();  // keeps its capacity
  for (const Contact& contact : proximityContacts(start, owners)) {
    pairs.push_back(SeparationHold{contact.vertices, contact.weights, contact.normal, contact.thickness});
  }
  m_owners = {};
}

SelfCollisionReport ContactResolver::resolve(const Vec3Array& start, Real h,
                                             std::span<const ContactOwner> owners,
                                             const std::vector<Real>& inverseMasses,
                                             const ContactOptions& options, Vec3Array& x,
                                             Vec3Array& v) {
  SelfCollisionReport report;
  m_owners = owners;
  const std::size_t n = start.size();
  m_velocity.resize(n);
  m_end.resize(n);
  m_touched.assign(n, 0);
  m_separationHolds.clear();
  if (!m_colliders.empty()) m_held.assign(n, -1);
  m_stepEnd = &x;
  m_certificateUsable = m_broadPhaseIsPure && m_certificateValid &&
                        m_certificateStart.size() == n &&
                        std::memcmp(start.data(), m_certificateStart.data(), n * sizeof(Vec3)) == 0;
  for (std::size_t i = 0; i < n; ++i) m_velocity[i] = (x[i] - start[i]) / h;
  // 1. Proximity at the step start: repulsion, inelastic contact and friction.
  if (options.proximity) {
    const std::vector<Contact>* proximity = &proximityContacts(start, owners);
    // The impulses, one after the other in pair order (Gauss–Seidel).
    WEFT_PROFILE_ZONE("response");
    const int sweeps = m_colliders.empty() ? 1 : kProximitySweepsWithColliders;
    for (int sweep = 0; sweep < sweeps; ++sweep) {
      for (const Contact& contact : *proximity) {
        applyImpulse(contact, kRepulsionRate * (contact.thickness - contact.gap) / h, inverseMasses);
      }
      clampToColliders(start, h);
    }
    report.proximityContacts += Index(proximity->size());
    holdContacts(*proximity);
  }

  // 2. Continuous detection of the corrected motion, impulses until clean (bounded).
  bool colliding = false;
  for (int pass = 0; pass < kImpulsePasses; ++pass) {
    colliding = findImpacts(start, h);
    if (!colliding) break;
    WEFT_PROFILE_ZONE("response");
    for (const Contact& contact : m_contacts) {
      applyImpulse(contact, kImpactSeparation * contact.thickness / h, inverseMasses);
      ++report.impacts;
    }
    holdContacts(m_contacts);
    clampToColliders(start, h);
  }

  // 3. Fail-safe: rigid impact zones, merged until clean; the last resort freezes.
  if (colliding) {
    WEFT_PROFILE_ZONE("impact zones");
    for (Index vertex = 0; vertex < m_zoneParent.size(); ++vertex) m_zoneParent[vertex] = vertex;
    m_inZone.assign(n, 0);
    for (int pass = 0; pass < kZonePasses && colliding; ++pass) {
      for (const Contact& contact : m_contacts) {
        for (Index vertex : contact.vertices) m_inZone[vertex] = 1;
        const Index root = findRoot(m_zoneParent, contact.vertices[0]);
        for (int k = 1; k < 4; ++k) m_zoneParent[findRoot(m_zoneParent, contact.vertices[k])] = root;
      }
      rigidifyZones(start, inverseMasses);
      clampToColliders(start, h);
      ++report.impactZones;
      colliding = findImpacts(start, h);
    }
    // Vertices that start free of crossings and do not move cannot cross: hold the rest.
    while (colliding) {
      const Index frozenBefore = report.frozenVertices;
      for (const Contact& contact : m_contacts) {
        for (Index vertex : contact.vertices) {
          if (inverseMasses[vertex] == 0 || m_velocity[vertex].isZero()) continue;
          ++report.frozenVertices;
          m_velocity[vertex].setZero();
          m_touched[vertex] = 1;
        }
      }
      // Nothing left to hold still: the pairs are between pinned vertices, which move as
      // scripted; the caller's pins are beyond what the cloth can answer for.
      if (report.frozenVertices == frozenBefore) break;
      colliding = findImpacts(start, h);
    }
  }

  // Only corrected vertices change: the others keep the integrator's bits.
  for (std::size_t i = 0; i < n; ++i) {
    if (!m_touched[i]) continue;
    if (options.velocityIsAverage) {
      v[i] = m_velocity[i];
    } else {
      v[i] += m_velocity[i] - (x[i] - start[i]) / h;
    }
    x[i] = start[i] + h * m_velocity[i];
  }
  // Each held pair may not end closer than it is now (nor need be farther than its thickness).
  for (SeparationHold& hold : m_separationHolds) {
    Vec3 point = Vec3::Zero();
    for (int k = 0; k < 4; ++k) point += hold.weights[k] * x[hold.vertices[k]];
    hold.separation = std::min(hold.separation, hold.normal.dot(point));
  }
  return report;
}

}  // namespace weft
