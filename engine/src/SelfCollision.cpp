#include "SelfCollision.h"

#include <weft/collision/ContinuousCollision.h>
#include <weft/collision/Proximity.h>
#include <weft/threading/Profiler.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

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

Index findRoot(std::vector<Index>& parent, Index vertex) {
  while (parent[vertex] != vertex) {
    parent[vertex] = parent[parent[vertex]];  // path halving
    vertex = parent[vertex];
  }
  return vertex;
}

}  // namespace

void SelfCollision::refitAndQuery(const Vec3Array& from, const Vec3Array& to, Real inflate) {
  WEFT_PROFILE_ZONE("broad phase");
  m_bvh.refit(from, to, inflate, m_tasks);
  if (m_tasks && m_workerPairs) {
    m_bvh.querySelf(m_trianglePairs, *m_tasks, *m_workerPairs);
    // Which worker finds which pairs depends on scheduling, so a worker's list may need any
    // share of the total: give each room for all of it, so that allocation follows the number
    // of pairs (which grows only with contact) and never the timing of the threads.
    const std::size_t total = m_trianglePairs.size();
    m_workerPairs->forEach([total](std::vector<TrianglePair>& pairs) {
      if (pairs.capacity() < total) pairs.reserve(total);
    });
  } else {
    m_bvh.querySelf(m_trianglePairs);
  }
}

SelfCollision::SelfCollision(const ClothModel& model, TaskSystem* tasks)
    : m_rest(model.restPositions()), m_tasks(tasks) {
  if (m_tasks) {
    m_workerPairs = std::make_unique<PerWorker<std::vector<TrianglePair>>>(*m_tasks);
  }
  m_bvh = Bvh::build(model.indices(), model.restPositions()).value();
  std::unordered_map<std::uint64_t, Index> edgeOfKey;
  for (Index e = 0; e < model.edges().size(); ++e) {
    const auto& vertices = model.edges()[e].vertices;
    m_edges.push_back(vertices);
    edgeOfKey[(std::uint64_t(vertices[0]) << 32) | vertices[1]] = e;
  }
  const std::vector<Index>& indices = model.indices();
  m_triangleEdges.resize(model.triangleCount());
  for (Index t = 0; t < model.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      Index a = indices[3 * t + k], b = indices[3 * t + (k + 1) % 3];
      if (a > b) std::swap(a, b);
      m_triangleEdges[t][k] = edgeOfKey.at((std::uint64_t(a) << 32) | b);
    }
  }
  m_zoneParent.resize(model.vertexCount());
}

void SelfCollision::collectFeaturePairs(const Vec3Array& from, const Vec3Array& to, Real margin) {
  m_vertexTriangle.clear();
  m_edgeEdge.clear();
  auto box = [&](std::initializer_list<Index> vertices, Real inflate) {
    Aabb bounds = Aabb::empty();
    for (Index vertex : vertices) {
      bounds.expand(from[vertex]);
      bounds.expand(to[vertex]);
    }
    bounds.inflate(inflate);
    return bounds;
  };
  // Most candidate triangle pairs are neighbours whose inflated boxes just touch; testing the
  // features' own boxes first keeps the exact tests (and the sort below) to the few that matter.
  for (const TrianglePair& pair : m_trianglePairs) {
    const std::array<Index, 3>& first = m_bvh.triangle(pair.first);
    const std::array<Index, 3>& second = m_bvh.triangle(pair.second);
    const Aabb firstBox = box({first[0], first[1], first[2]}, 0);
    const Aabb secondBox = box({second[0], second[1], second[2]}, 0);
    for (Index vertex : first) {
      if (box({vertex}, margin).overlaps(secondBox)) m_vertexTriangle.push_back({vertex, pair.second});
    }
    for (Index vertex : second) {
      if (box({vertex}, margin).overlaps(firstBox)) m_vertexTriangle.push_back({vertex, pair.first});
    }
    // The BVH reports only triangles that share no vertex, so their edges share none either.
    for (Index a : m_triangleEdges[pair.first]) {
      const Aabb edgeBox = box({m_edges[a][0], m_edges[a][1]}, margin);
      if (!edgeBox.overlaps(secondBox)) continue;
      for (Index b : m_triangleEdges[pair.second]) {
        if (edgeBox.overlaps(box({m_edges[b][0], m_edges[b][1]}, 0))) {
          m_edgeEdge.push_back({std::min(a, b), std::max(a, b)});
        }
      }
    }
  }
  // A feature pair reached through several triangle pairs is tested once, in a fixed order.
  std::sort(m_vertexTriangle.begin(), m_vertexTriangle.end());
  m_vertexTriangle.erase(std::unique(m_vertexTriangle.begin(), m_vertexTriangle.end()),
                         m_vertexTriangle.end());
  std::sort(m_edgeEdge.begin(), m_edgeEdge.end());
  m_edgeEdge.erase(std::unique(m_edgeEdge.begin(), m_edgeEdge.end()), m_edgeEdge.end());
}

void SelfCollision::applyImpulse(const Contact& contact, Real targetNormalSpeed, Real friction,
                                 const std::vector<Real>& inverseMasses) {
  Vec3 relative = Vec3::Zero();
  Real effectiveInverseMass = 0;
  for (int k = 0; k < 4; ++k) {
    relative += contact.weights[k] * m_velocity[contact.vertices[k]];
    effectiveInverseMass += contact.weights[k] * contact.weights[k] * inverseMasses[contact.vertices[k]];
  }
  if (effectiveInverseMass <= 0) return;  // all four pinned: nothing can move
  const Real normalSpeed = relative.dot(contact.normal);
  if (normalSpeed >= targetNormalSpeed) return;
  const Real normalChange = targetNormalSpeed - normalSpeed;
  Vec3 change = normalChange * contact.normal;
  // Coulomb friction: remove at most μ·|Δu_n| of relative tangential speed.
  const Vec3 tangential = relative - normalSpeed * contact.normal;
  const Real tangentialSpeed = tangential.norm();
  if (friction > 0 && tangentialSpeed > 0) {
    change -= std::min<Real>(1, friction * normalChange / tangentialSpeed) * tangential;
  }
  // Δv_i = w_i λ / m_i with λ = Δu / Σ w_j² / m_j gives exactly the relative change Δu.
  const Vec3 lambda = change / effectiveInverseMass;
  for (int k = 0; k < 4; ++k) {
    const Index vertex = contact.vertices[k];
    m_velocity[vertex] += contact.weights[k] * inverseMasses[vertex] * lambda;
    m_touched[vertex] = 1;
  }
}

bool SelfCollision::findImpacts(const Vec3Array& start, Real h) {
  m_contacts.clear();
  for (std::size_t i = 0; i < start.size(); ++i) m_end[i] = start[i] + h * m_velocity[i];
  // The CCD tolerance is 1 µm: boxes inflated by a little more catch every contact it reports.
  refitAndQuery(start, m_end, 2 * kDefaultContactTolerance);
  collectFeaturePairs(start, m_end, 2 * kDefaultContactTolerance);
  WEFT_PROFILE_ZONE("narrow phase");
  for (const auto& [vertex, triangle] : m_vertexTriangle) {
    const std::array<Index, 3>& corners = m_bvh.triangle(triangle);
    const std::array<Vec3, 3> triangleStart{start[corners[0]], start[corners[1]], start[corners[2]]};
    const std::array<Vec3, 3> triangleEnd{m_end[corners[0]], m_end[corners[1]], m_end[corners[2]]};
    const std::optional<VertexTriangleImpact> impact =
        sweptVertexTriangle(start[vertex], m_end[vertex], triangleStart, triangleEnd);
    if (!impact) continue;
    const Real t = impact->time;
    auto at = [&](Index i) { return Vec3(start[i] + t * (m_end[i] - start[i])); };
    Vec3 normal = (at(corners[1]) - at(corners[0])).cross(at(corners[2]) - at(corners[0]));
    if (normal.norm() == 0) continue;  // degenerate at impact; the zones catch it if it matters
    normal.normalize();
    // Orient the normal from the triangle towards the side the vertex came from.
    const Vec3 startPoint = impact->barycentric[0] * triangleStart[0] +
                            impact->barycentric[1] * triangleStart[1] +
                            impact->barycentric[2] * triangleStart[2];
    if (normal.dot(start[vertex] - startPoint) < 0) normal = -normal;
    m_contacts.push_back({{vertex, corners[0], corners[1], corners[2]},
                          {1, -impact->barycentric[0], -impact->barycentric[1], -impact->barycentric[2]},
                          normal, 0});
  }
  for (const auto& [firstEdge, secondEdge] : m_edgeEdge) {
    const std::array<Index, 2>& p = m_edges[firstEdge];
    const std::array<Index, 2>& q = m_edges[secondEdge];
    const std::optional<EdgeEdgeImpact> impact =
        sweptEdgeEdge({start[p[0]], start[p[1]]}, {m_end[p[0]], m_end[p[1]]},
                      {start[q[0]], start[q[1]]}, {m_end[q[0]], m_end[q[1]]});
    if (!impact) continue;
    const Real t = impact->time, s = impact->firstParameter, u = impact->secondParameter;
    auto at = [&](Index i) { return Vec3(start[i] + t * (m_end[i] - start[i])); };
    Vec3 normal = (at(p[1]) - at(p[0])).cross(at(q[1]) - at(q[0]));
    const Vec3 startGap = ((1 - s) * start[p[0]] + s * start[p[1]]) - ((1 - u) * start[q[0]] + u * start[q[1]]);
    if (normal.norm() < 1e-12) normal = startGap;  // parallel edges: the gap is the direction
    if (normal.norm() == 0) continue;
    normal.normalize();
    if (normal.dot(startGap) < 0) normal = -normal;
    m_contacts.push_back({{p[0], p[1], q[0], q[1]}, {1 - s, s, -(1 - u), -u}, normal, 0});
  }
  return !m_contacts.empty();
}

void SelfCollision::rigidifyZones(const Vec3Array& start, const std::vector<Real>& inverseMasses) {
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

SelfCollisionReport SelfCollision::resolve(const Vec3Array& start, Real h, Real thickness,
                                           Real friction, const std::vector<Real>& inverseMasses,
                                           Vec3Array& x, Vec3Array& v) {
  WEFT_PROFILE_ZONE("self collision");
  SelfCollisionReport report;
  const std::size_t n = start.size();
  m_velocity.resize(n);
  m_end.resize(n);
  m_touched.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) m_velocity[i] = (x[i] - start[i]) / h;

  // 1. Proximity at the step start: repulsion, inelastic contact and friction.
  refitAndQuery(start, start, thickness);
  collectFeaturePairs(start, start, thickness);
  {
    // Proximity: the exact distance tests and the impulses they call for, pair by pair.
    WEFT_PROFILE_ZONE("response");
    for (const auto& [vertex, triangle] : m_vertexTriangle) {
      const std::array<Index, 3>& c = m_bvh.triangle(triangle);
      const TriangleClosestPoint closest =
          closestPointOnTriangle(start[vertex], start[c[0]], start[c[1]], start[c[2]]);
      if (closest.distance >= thickness) continue;
      // Features that are this close in the rest shape are neighbours in the material (a mesh
      // finer than the thickness): the elastic forces keep them apart, repulsion would fight them.
      if (closestPointOnTriangle(m_rest[vertex], m_rest[c[0]], m_rest[c[1]], m_rest[c[2]]).distance <
          thickness) {
        continue;
      }
      Vec3 normal = start[vertex] - closest.point;
      if (closest.distance < 1e-9 * thickness) {
        normal = (start[c[1]] - start[c[0]]).cross(start[c[2]] - start[c[0]]);
      }
      if (normal.norm() == 0) continue;
      const Contact contact{{vertex, c[0], c[1], c[2]},
                            {1, -closest.barycentric[0], -closest.barycentric[1], -closest.barycentric[2]},
                            normal.normalized(), closest.distance};
      applyImpulse(contact, kRepulsionRate * (thickness - contact.gap) / h, friction, inverseMasses);
      ++report.proximityContacts;
    }
    for (const auto& [firstEdge, secondEdge] : m_edgeEdge) {
      const std::array<Index, 2>& p = m_edges[firstEdge];
      const std::array<Index, 2>& q = m_edges[secondEdge];
      const SegmentClosestPoints closest =
          closestPointsOnSegments(start[p[0]], start[p[1]], start[q[0]], start[q[1]]);
      if (closest.distance >= thickness) continue;
      if (closestPointsOnSegments(m_rest[p[0]], m_rest[p[1]], m_rest[q[0]], m_rest[q[1]]).distance <
          thickness) {
        continue;  // neighbours in the material, as above
      }
      const Real s = closest.firstParameter, u = closest.secondParameter;
      Vec3 normal = ((1 - s) * start[p[0]] + s * start[p[1]]) - ((1 - u) * start[q[0]] + u * start[q[1]]);
      if (closest.distance < 1e-9 * thickness) {
        normal = (start[p[1]] - start[p[0]]).cross(start[q[1]] - start[q[0]]);
      }
      if (normal.norm() == 0) continue;
      const Contact contact{{p[0], p[1], q[0], q[1]}, {1 - s, s, -(1 - u), -u}, normal.normalized(),
                            closest.distance};
      applyImpulse(contact, kRepulsionRate * (thickness - contact.gap) / h, friction, inverseMasses);
      ++report.proximityContacts;
    }
  }

  // 2. Continuous detection of the corrected motion, impulses until clean (bounded).
  const Real separationSpeed = kImpactSeparation * thickness / h;
  bool colliding = false;
  for (int pass = 0; pass < kImpulsePasses; ++pass) {
    colliding = findImpacts(start, h);
    if (!colliding) break;
    WEFT_PROFILE_ZONE("response");
    for (const Contact& contact : m_contacts) {
      applyImpulse(contact, separationSpeed, friction, inverseMasses);
      ++report.impacts;
    }
  }

  // 3. Fail-safe: rigid impact zones, merged until clean; the last resort freezes.
  if (colliding) {
    for (Index vertex = 0; vertex < m_zoneParent.size(); ++vertex) m_zoneParent[vertex] = vertex;
    m_inZone.assign(n, 0);
    for (int pass = 0; pass < kZonePasses && colliding; ++pass) {
      for (const Contact& contact : m_contacts) {
        for (Index vertex : contact.vertices) m_inZone[vertex] = 1;
        const Index root = findRoot(m_zoneParent, contact.vertices[0]);
        for (int k = 1; k < 4; ++k) m_zoneParent[findRoot(m_zoneParent, contact.vertices[k])] = root;
      }
      rigidifyZones(start, inverseMasses);
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
    v[i] = m_velocity[i];
    x[i] = start[i] + h * m_velocity[i];
  }
  return report;
}

}  // namespace weft
