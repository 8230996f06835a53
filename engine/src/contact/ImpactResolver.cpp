#include "contact/ImpactResolver.h"

#include <weft/collision/ContinuousCollision.h>
#include <weft/threading/Profiler.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>

namespace weft {
namespace {

// The swept test's tolerance is 1 µm: broad-phase boxes inflated by a little more (m) catch
// every pair it reports.
constexpr Real kSweptInflate = 2 * kDefaultContactTolerance;
// Passes of impulse-based continuous detection before the impact zones take over.
constexpr int kImpulsePasses = 6;
// Merging passes of the impact zones before the last resort freezes what still collides.
constexpr int kZonePasses = 12;
// A swept hit is resolved to a separating speed that opens this share of the thickness within
// the substep, so the pair is not found touching again at its end.
constexpr Real kImpactSeparation = 0.25;
// Feature pairs per parallel block: a swept test costs a few hundred ns, so 128 pairs are tens
// of µs of work.
constexpr TaskSystem::Index kGrainFeaturePairs = 128;
// A vertex that ends within this many thicknesses of a collider is held by it in the impulses.
constexpr Real kHeldReach = 1.5;
// A held vertex counts as 1000× heavier in impulses, so the free side of a pair takes them.
constexpr Real kHeldInverseMassScale = 1e-3;
// Below this fraction of a pair's Σ w_k², its movable vertices cannot take an impulse: they would
// have to move at Δu / w_k (a point on a face whose pinned corners collapsed together flew at
// 10¹⁵ m/s). The impact zones, which move with the pins, take such a pair.
constexpr Real kSmallestMovableWeight = 1e-3;

Index findRoot(std::vector<Index>& parent, Index vertex) {
  while (parent[vertex] != vertex) {
    parent[vertex] = parent[parent[vertex]];  // path halving
    vertex = parent[vertex];
  }
  return vertex;
}

// Sweeps over the faces on thin bodies, until no point moves more than round-off (neighbouring
// faces share corners), a few at most.
constexpr int kFaceSweeps = 4;
constexpr Real kSettledDepth = 1e-9;

}  // namespace

void ImpactResolver::build(const ContactSpace& space, TaskSystem* tasks) {
  m_tasks = tasks;
  m_features.build(space, tasks);
  m_pairFilter.build(tasks);
  const Index n = space.vertexCount();
  m_zoneParent.resize(n);
  m_velocity.resize(n);
  m_end.resize(n);
  m_testedEnd.resize(n);
  m_beforeFaces.resize(n);
  m_faceCorner.assign(n, 0);
}

Index ImpactResolver::keepOutOfColliders(ContactSpace& space, const ContactSet& set,
                                         std::span<const ColliderFrame> colliders) {
  m_near.clear();
  if (colliders.empty()) return 0;
  const Real thickness = space.maxThickness();
  const Aabb path = space.movablePaths(space.x);
  for (Index k = 0; k < Index(colliders.size()); ++k) {
    Aabb box = path;
    if (!colliders[k].still()) {
      // A turning body: the paths relative to it are arcs, which stray from their chords.
      Real bulge = 0;
      for (Index i = 0; i < space.vertexCount(); ++i) {
        if (space.inverseMass[i] == 0) continue;
        addRelativePath(colliders[k], space.startX[i], space.x[i], box, bulge);
      }
      box.inflate(bulge);
    }
    if (!m_skip || mayTouch(colliders[k].shape, box, thickness * (1 + 1e-6) + 1e-9)) {
      m_near.push_back(k);
    }
  }
  if (m_near.empty()) return 0;  // and so no face contact either
  WEFT_PROFILE_ZONE("collider impacts");
  // Each vertex on its own (it reads and writes only its own slots), in parallel: a query against
  // a mesh costs microseconds.
  const auto keepBlockOutside = [&](Index begin, Index end) {
    Index moved = 0;
    for (Index i = begin; i < end; ++i) {
      if (space.inverseMass[i] == 0) continue;
      const Real thickness = m_colliderSeparation[i];
      bool kept = false;
      for (Index k : m_near) {
        const ColliderFrame& collider = colliders[k];
        const Vec3 outside = keepVertexOutside(i, collider, space, space.x[i], thickness);
        if (outside == space.x[i]) continue;
        space.x[i] = outside;
        // Inelastic: no relative velocity into the surface.
        const ShapeContact on = queryPoint(collider.shape, outside);
        const Real approach = (space.v[i] - on.velocity).dot(on.normal);
        if (approach < 0) space.v[i] -= approach * on.normal;
        kept = true;
      }
      moved += kept;
    }
    return moved;
  };
  const Index corrected =
      m_tasks ? m_tasks->parallelReduce(space.vertexCount(), kGrainVertexQueries, Index(0),
                                        keepBlockOutside, std::plus<Index>())
              : keepBlockOutside(0, space.vertexCount());
  // Then the faces on bodies thinner than the triangles, which have the last word: a vertex
  // pushed out of one capsule of a ring may tilt its face into the next.
  pushFacesOut(set, space.inverseMass, space.x, space.v, 0, false);
  return corrected;
}

Real ImpactResolver::impulseInverseMass(Index vertex, const ContactSpace& space) {
  const Real inverseMass = space.inverseMass[vertex];
  if (m_near.empty() || inverseMass == 0) return inverseMass;
  // Decided on first use, from where the substep was to end: impulses run serially, so the
  // cache fills in the same order on any thread count.
  if (m_held[vertex] < 0) {
    const Real reach = kHeldReach * space.owners[space.owner[vertex]].thickness;
    m_held[vertex] = 0;
    for (Index k : m_near) {
      if (queryPoint(m_colliders[k].shape, space.x[vertex]).distance < reach) m_held[vertex] = 1;
    }
  }
  return m_held[vertex] ? kHeldInverseMassScale * inverseMass : inverseMass;
}

Vec3 ImpactResolver::keepVertexOutside(Index vertex, const ColliderFrame& collider,
                                       const ContactSpace& space, const Vec3& end,
                                       Real thickness) const {
  if (m_tracked[vertex]) return keepOutsideFrom(collider.shape, m_projected[vertex], end, thickness);
  return keepOutside(collider, space.startX[vertex], end, thickness);
}

void ImpactResolver::clampToColliders(const ContactSpace& space, Real h) {
  if (m_near.empty()) return;
  for (Index i = 0; i < space.vertexCount(); ++i) {
    if (!m_touched[i]) continue;
    const Real thickness = m_colliderSeparation[i];
    for (Index k : m_near) {
      // The way there, relative to the body, not only the end: an impulse may send a vertex
      // through a thin or fast body.
      const Vec3 end = space.startX[i] + h * m_velocity[i];
      const Vec3 outside = keepVertexOutside(i, m_colliders[k], space, end, thickness);
      if (outside != end) m_velocity[i] = (outside - space.startX[i]) / h;
    }
  }
  // The faces on a body thinner than the triangles, whose corners an impulse moved: a face an
  // impulse pushed into a core goes back out to its reach, as a velocity change of its corners.
  if (m_set == nullptr || !m_faceContacts) return;
  for (Index i = 0; i < space.vertexCount(); ++i) m_end[i] = space.startX[i] + h * m_velocity[i];
  pushFacesOut(*m_set, space.inverseMass, m_end, m_velocity, 1 / h, true);
}

void ImpactResolver::pushFacesOut(const ContactSet& set, std::span<const Real> inverseMasses,
                                  std::span<Vec3> x, std::span<Vec3> v, Real inverseStep,
                                  bool touchedOnly) {
  m_faceCorners.clear();
  for (int sweep = 0; sweep < kFaceSweeps; ++sweep) {
    Real deepest = 0;
    for (std::size_t c = 0; c < set.firstPair; ++c) {
      const Contact& contact = set.contacts[c];
      if (contact.kind != ContactKind::FaceCollider) continue;
      const std::array<Index, 3> corner{contact.vertices[0], contact.vertices[1],
                                        contact.vertices[2]};
      if (touchedOnly && !m_touched[corner[0]] && !m_touched[corner[1]] && !m_touched[corner[2]]) {
        continue;
      }
      // Where each corner was before the faces moved it (outside every body).
      for (Index i : corner) {
        if (m_faceCorner[i]) continue;
        m_faceCorner[i] = 1;
        m_faceCorners.push_back(i);
        m_beforeFaces[i] = x[i];
      }
      Vec3 normal;
      const Real depth =
          pushFaceOut(set.cores[contact.core], contact.normal,
                      m_colliders[contact.collider].end.pose, corner, inverseMasses, x, v,
                      inverseStep, normal);
      if (touchedOnly && depth > 0) {
        for (Index i : corner) m_touched[i] = 1;
      }
      deepest = std::max(deepest, depth);
    }
    if (!(deepest > kSettledDepth)) break;
  }
  // A face pushed off a core may press a corner into a body beside it (a sheet under the edge
  // of a press, the floor beneath): the corner stops on that body's surface, on its way from
  // where it was before the faces moved it.
  for (Index i : m_faceCorners) {
    m_faceCorner[i] = 0;
    if (x[i] == m_beforeFaces[i]) continue;
    for (Index k : m_near) {
      const Vec3 outside =
          keepOutsideFrom(m_colliders[k].shape, m_beforeFaces[i], x[i], kDefaultContactTolerance);
      v[i] += inverseStep * (outside - x[i]);
      x[i] = outside;
    }
  }
}

void ImpactResolver::applyImpulse(const Impact& impact, Real targetNormalSpeed,
                                  const ContactSpace& space) {
  Vec3 relative = Vec3::Zero();
  for (int k = 0; k < 4; ++k) relative += impact.weights[k] * m_velocity[impact.vertices[k]];
  const Real normalSpeed = relative.dot(impact.normal);
  if (normalSpeed >= targetNormalSpeed) return;
  Real effective = 0;
  std::array<Real, 4> inverseMass;
  for (int k = 0; k < 4; ++k) {
    inverseMass[k] = impulseInverseMass(impact.vertices[k], space);
    effective += impact.weights[k] * impact.weights[k] * inverseMass[k];
  }
  if (effective <= 0) return;  // all four pinned
  Real whole = 0, movable = 0;
  for (int k = 0; k < 4; ++k) {
    const Real square = impact.weights[k] * impact.weights[k];
    whole += square;
    if (space.inverseMass[impact.vertices[k]] > 0) movable += square;
  }
  if (!(movable >= kSmallestMovableWeight * whole)) return;
  // When the free side holds the pair point only with a small weight, taking all of the
  // relative change would throw that vertex at Δu / w: the true masses share it instead, and the
  // clamp afterwards puts back what reaches into a collider.
  Real largestShare = 0;
  for (int k = 0; k < 4; ++k) {
    largestShare = std::max(largestShare, std::abs(impact.weights[k]) * inverseMass[k]);
  }
  if (largestShare > effective) {
    effective = 0;
    for (int k = 0; k < 4; ++k) {
      inverseMass[k] = space.inverseMass[impact.vertices[k]];
      effective += impact.weights[k] * impact.weights[k] * inverseMass[k];
    }
  }
  const Real normalChange = targetNormalSpeed - normalSpeed;
  Vec3 change = normalChange * impact.normal;
  // Coulomb friction: at most μ·|Δu_n| of relative tangential speed.
  const Vec3 tangential = relative - normalSpeed * impact.normal;
  const Real tangentialSpeed = tangential.norm();
  if (impact.friction > 0 && tangentialSpeed > 0) {
    change -= std::min<Real>(1, impact.friction * normalChange / tangentialSpeed) * tangential;
  }
  // Δv_i = w_i λ / m_i with λ = Δu / Σ w_j² / m_j gives exactly the relative change Δu.
  const Vec3 lambda = change / effective;
  for (int k = 0; k < 4; ++k) {
    const Index vertex = impact.vertices[k];
    m_velocity[vertex] += impact.weights[k] * inverseMass[k] * lambda;
    m_touched[vertex] = 1;
  }
}

Index ImpactResolver::markFarMovers() {
  // The detection's feature pairs were found over x₀ → x₁ with a margin R. A feature pair whose
  // vertices each moved at most d from x₁ to x₂ comes within δ over x₀ → x₂ only if it came
  // within δ + 2d over x₀ → x₁ (the paths share x₀ and part by at most d), so the detection
  // listed it when 2d + δ ≤ R. The vertices that moved farther are marked: only the pairs with
  // one of them need a search of their own.
  m_farMover.assign(m_end.size(), 0);
  const Real reach = (m_detected.margin - kSweptInflate) / 2;
  Index far = 0;
  for (std::size_t i = 0; i < m_end.size(); ++i) {
    if ((m_end[i] - m_detected.endPositions[i]).cwiseAbs().maxCoeff() > reach) {
      m_farMover[i] = 1;
      ++far;
    }
  }
  return far;
}

bool ImpactResolver::findImpacts(const ContactSpace& space, Real h) {
  const Vec3Array& start = space.startX;
  const Index n = space.vertexCount();
  for (Index i = 0; i < n; ++i) m_end[i] = start[i] + h * m_velocity[i];
  // Only pairs with a vertex whose end moved since the last test, or that was in one of its
  // hits, can test differently: the others would test exactly as then, negative.
  Index dirty = 0;
  for (Index i = 0; i < n; ++i) {
    if (m_dirty[i] || std::memcmp(&m_end[i], &m_testedEnd[i], sizeof(Vec3)) != 0) {
      m_dirty[i] = 1;
      ++dirty;
    }
  }
  m_impacts.clear();
  if (dirty == 0) return false;
  // The detection's feature pairs hold every pair this test could find whose vertices stayed
  // near the detection's ends (markFarMovers); the pairs with a vertex that moved farther get a
  // search of their own, when it is a local one. Without the detection's pairs, or when fewer
  // vertices are dirty than moved far (the later passes), or when so many moved far that their
  // search would query the whole tree anyway, a search over the dirty vertices alone, whose
  // list is shorter than the detection's.
  const FeaturePairs* reused = nullptr;
  bool skipFarMovers = false;
  if (m_detected.features && m_detected.endPositions.size() == m_end.size()) {
    const Index far = markFarMovers();
    if (far == 0) {
      reused = m_detected.features;
    } else if (far < dirty && FeaturePairs::searchesLocally(space, m_farMover)) {
      reused = m_detected.features;
      m_features.find(space, start, m_end, kSweptInflate, &m_farMover);
      skipFarMovers = true;
    }
  }
  if (!reused) m_features.find(space, start, m_end, kSweptInflate, &m_dirty);
  // Index space: the reused vertex–triangle and edge–edge pairs, then the searched ones.
  using PairList = std::span<const std::array<Index, 2>>;
  const PairList reusedVertexTriangle = reused ? PairList(reused->vertexTriangle()) : PairList();
  const PairList reusedEdgeEdge = reused ? PairList(reused->edgeEdge()) : PairList();
  const bool searched = !reused || skipFarMovers;
  const PairList searchedVertexTriangle =
      searched ? PairList(m_features.vertexTriangle()) : PairList();
  const PairList searchedEdgeEdge = searched ? PairList(m_features.edgeEdge()) : PairList();
  const Index reusedCount = Index(reusedVertexTriangle.size() + reusedEdgeEdge.size());
  const Index total = reusedCount + Index(searchedVertexTriangle.size() + searchedEdgeEdge.size());
  // Whether any of a pair's four vertices carries `flag`.
  auto anyFlagged = [](const std::vector<char>& flag, const std::array<Index, 4>& vertices) {
    return flag[vertices[0]] || flag[vertices[1]] || flag[vertices[2]] || flag[vertices[3]];
  };
  auto test = [&](Index pair, Impact& impact) -> bool {
    const bool fromReused = pair < reusedCount;
    const PairList vertexTriangle = fromReused ? reusedVertexTriangle : searchedVertexTriangle;
    const PairList edgeEdge = fromReused ? reusedEdgeEdge : searchedEdgeEdge;
    if (!fromReused) pair -= reusedCount;
    // A pair without a dirty vertex tests as it did last time: negative. A reused pair with a
    // far mover is among the searched ones.
    auto skipped = [&](const std::array<Index, 4>& vertices) {
      return !anyFlagged(m_dirty, vertices) ||
             (fromReused && skipFarMovers && anyFlagged(m_farMover, vertices));
    };
    const Index vertexTriangleCount = Index(vertexTriangle.size());
    if (pair < vertexTriangleCount) {
      const auto& [vertex, triangle] = vertexTriangle[pair];
      const std::array<Index, 3>& c = space.triangles[triangle];
      if (skipped({vertex, c[0], c[1], c[2]})) return false;
      // Most candidates the detection's wider margin kept end here, for a few comparisons.
      if (!featureBoxesWithin({vertex}, {c[0], c[1], c[2]}, start, m_end, kSweptInflate)) {
        return false;
      }
      const std::array<Vec3, 3> triangleStart{start[c[0]], start[c[1]], start[c[2]]};
      const std::array<Vec3, 3> triangleEnd{m_end[c[0]], m_end[c[1]], m_end[c[2]]};
      const std::optional<VertexTriangleImpact> hit =
          sweptVertexTriangle(start[vertex], m_end[vertex], triangleStart, triangleEnd);
      if (!hit) return false;
      const Real t = hit->time;
      auto at = [&](Index i) { return Vec3(start[i] + t * (m_end[i] - start[i])); };
      Vec3 normal = (at(c[1]) - at(c[0])).cross(at(c[2]) - at(c[0]));
      if (normal.norm() == 0) return false;  // degenerate at impact: the zones catch it
      normal.normalize();
      const Vec3 startPoint = hit->barycentric[0] * triangleStart[0] +
                              hit->barycentric[1] * triangleStart[1] +
                              hit->barycentric[2] * triangleStart[2];
      if (normal.dot(start[vertex] - startPoint) < 0) normal = -normal;
      impact = {{vertex, c[0], c[1], c[2]},
                {1, -hit->barycentric[0], -hit->barycentric[1], -hit->barycentric[2]},
                normal, space.pairThickness(vertex, c[0]), space.pairFriction(vertex, c[0])};
      return true;
    }
    const auto& [firstEdge, secondEdge] = edgeEdge[pair - vertexTriangleCount];
    const std::array<Index, 2>& p = space.edges[firstEdge];
    const std::array<Index, 2>& q = space.edges[secondEdge];
    if (skipped({p[0], p[1], q[0], q[1]})) return false;
    if (!featureBoxesWithin({p[0], p[1]}, {q[0], q[1]}, start, m_end, kSweptInflate)) return false;
    const std::optional<EdgeEdgeImpact> hit =
        sweptEdgeEdge({start[p[0]], start[p[1]]}, {m_end[p[0]], m_end[p[1]]},
                      {start[q[0]], start[q[1]]}, {m_end[q[0]], m_end[q[1]]});
    if (!hit) return false;
    const Real t = hit->time, s = hit->firstParameter, u = hit->secondParameter;
    auto at = [&](Index i) { return Vec3(start[i] + t * (m_end[i] - start[i])); };
    Vec3 normal = (at(p[1]) - at(p[0])).cross(at(q[1]) - at(q[0]));
    const Vec3 startGap =
        ((1 - s) * start[p[0]] + s * start[p[1]]) - ((1 - u) * start[q[0]] + u * start[q[1]]);
    if (normal.norm() < 1e-12) normal = startGap;  // parallel edges: the gap is the direction
    if (normal.norm() == 0) return false;
    normal.normalize();
    if (normal.dot(startGap) < 0) normal = -normal;
    impact = {{p[0], p[1], q[0], q[1]}, {1 - s, s, -(1 - u), -u}, normal,
              space.pairThickness(p[0], q[0]), space.pairFriction(p[0], q[0])};
    return true;
  };
  WEFT_PROFILE_ZONE("swept tests");
  m_pairFilter.run(total, kGrainFeaturePairs, test, m_impacts);
  // The next test needs only the vertices whose ends move from here, and those of the hits.
  m_testedEnd = m_end;
  std::fill(m_dirty.begin(), m_dirty.end(), char(0));
  for (const Impact& impact : m_impacts) {
    for (Index vertex : impact.vertices) m_dirty[vertex] = 1;
  }
  return !m_impacts.empty();
}

void ImpactResolver::rigidifyZones(const ContactSpace& space) {
  // Each zone's vertices (ordered by root, then vertex: deterministic) get one rigid velocity
  // that keeps the zone's linear and angular momentum. Pinned vertices, of infinite mass, make
  // the zone move with them instead.
  const Vec3Array& start = space.startX;
  m_zoneOrder.clear();
  for (Index vertex = 0; vertex < space.vertexCount(); ++vertex) {
    if (m_inZone[vertex]) m_zoneOrder.push_back(vertex);
  }
  std::stable_sort(m_zoneOrder.begin(), m_zoneOrder.end(), [&](Index a, Index b) {
    return findRoot(m_zoneParent, a) < findRoot(m_zoneParent, b);
  });
  for (std::size_t begin = 0; begin < m_zoneOrder.size();) {
    const Index root = findRoot(m_zoneParent, m_zoneOrder[begin]);
    std::size_t end = begin;
    while (end < m_zoneOrder.size() && findRoot(m_zoneParent, m_zoneOrder[end]) == root) ++end;
    const std::span<const Index> members(m_zoneOrder.data() + begin, end - begin);
    begin = end;
    Real mass = 0;
    Vec3 centre = Vec3::Zero(), momentum = Vec3::Zero(), pinnedVelocity = Vec3::Zero();
    int pinned = 0;
    for (Index vertex : members) {
      if (space.inverseMass[vertex] == 0) {
        pinnedVelocity += m_velocity[vertex];
        ++pinned;
        continue;
      }
      const Real m = 1 / space.inverseMass[vertex];
      mass += m;
      centre += m * start[vertex];
      momentum += m * m_velocity[vertex];
    }
    for (Index vertex : members) m_touched[vertex] |= space.inverseMass[vertex] != 0;
    if (pinned > 0) {
      for (Index vertex : members) {
        if (space.inverseMass[vertex] != 0) m_velocity[vertex] = pinnedVelocity / pinned;
      }
      continue;
    }
    if (mass == 0) continue;
    centre /= mass;
    const Vec3 linear = momentum / mass;
    Vec3 angularMomentum = Vec3::Zero();
    Mat3 inertia = Mat3::Zero();
    for (Index vertex : members) {
      const Real m = 1 / space.inverseMass[vertex];
      const Vec3 r = start[vertex] - centre;
      angularMomentum += m * r.cross(m_velocity[vertex] - linear);
      inertia += m * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
    }
    // A collinear zone has a singular inertia tensor: the pseudo-inverse drops the spin about its
    // line, which no contact could have set.
    const Vec3 omega = inertia.completeOrthogonalDecomposition().solve(angularMomentum);
    for (Index vertex : members) m_velocity[vertex] = linear + omega.cross(start[vertex] - centre);
  }
}

ImpactReport ImpactResolver::resolve(ContactSpace& space, const ContactSet& set,
                                     std::span<const ColliderFrame> colliders, Real h, bool pairs,
                                     const DetectedPairs& detected) {
  WEFT_PROFILE_ZONE("impacts");
  ImpactReport report;
  m_colliders = colliders;
  m_set = &set;
  m_faceContacts = std::any_of(set.contacts.begin(), set.contacts.begin() + set.firstPair,
                               [](const Contact& c) { return c.kind == ContactKind::FaceCollider; });
  // The projection followed its collider contacts along the way it moved them, so their
  // positions now are outside and reached legally; the fail-safe traces them from there. A
  // straight path from the substep's start may cut through a body the projection slid them
  // round, and putting them back on it would undo the projection's strain limit.
  m_projected = space.x;
  m_tracked.assign(space.vertexCount(), 0);
  // Each vertex is kept its thickness from every body, or less where the detection found it
  // squeezed between two (its contacts' separation).
  m_colliderSeparation.resize(space.vertexCount());
  for (Index i = 0; i < space.vertexCount(); ++i) {
    m_colliderSeparation[i] = space.owners[space.owner[i]].thickness;
  }
  for (std::size_t c = 0; c < set.firstPair; ++c) {
    const Contact& contact = set.contacts[c];
    if (contact.kind != ContactKind::VertexCollider) continue;
    const Index i = contact.vertices[0];
    m_tracked[i] = 1;
    m_colliderSeparation[i] = std::min(m_colliderSeparation[i], contact.separation);
  }
  report.colliderCorrections = keepOutOfColliders(space, set, colliders);
  if (!pairs) return report;
  m_detected = detected;
  const Index n = space.vertexCount();
  const Vec3Array& start = space.startX;
  for (Index i = 0; i < n; ++i) m_velocity[i] = (space.x[i] - start[i]) / h;
  m_touched.assign(n, 0);
  m_dirty.assign(n, 1);
  if (!m_near.empty()) m_held.assign(n, -1);

  bool colliding = false;
  for (int pass = 0; pass < kImpulsePasses; ++pass) {
    colliding = findImpacts(space, h);
    if (!colliding) break;
    for (const Impact& impact : m_impacts) {
      applyImpulse(impact, kImpactSeparation * impact.thickness / h, space);
      ++report.impacts;
    }
    clampToColliders(space, h);
  }
  if (colliding) {
    WEFT_PROFILE_ZONE("impact zones");
    for (Index vertex = 0; vertex < n; ++vertex) m_zoneParent[vertex] = vertex;
    m_inZone.assign(n, 0);
    for (int pass = 0; pass < kZonePasses && colliding; ++pass) {
      for (const Impact& impact : m_impacts) {
        for (Index vertex : impact.vertices) m_inZone[vertex] = 1;
        const Index root = findRoot(m_zoneParent, impact.vertices[0]);
        for (int k = 1; k < 4; ++k) m_zoneParent[findRoot(m_zoneParent, impact.vertices[k])] = root;
      }
      rigidifyZones(space);
      clampToColliders(space, h);
      ++report.impactZones;
      colliding = findImpacts(space, h);
    }
    // Vertices that start free of crossings and do not move cannot cross: hold the rest.
    while (colliding) {
      const Index frozenBefore = report.frozenVertices;
      for (const Impact& impact : m_impacts) {
        for (Index vertex : impact.vertices) {
          if (space.inverseMass[vertex] == 0 || m_velocity[vertex].isZero()) continue;
          ++report.frozenVertices;
          m_velocity[vertex].setZero();
          m_touched[vertex] = 1;
        }
      }
      // Nothing left to hold still: the pairs are between pinned vertices, which move as
      // scripted; the caller's pins are beyond what the cloth can answer for.
      if (report.frozenVertices == frozenBefore) break;
      colliding = findImpacts(space, h);
    }
  }
  // Only corrected vertices change; the velocity takes the change of the average velocity.
  for (Index i = 0; i < n; ++i) {
    if (!m_touched[i]) continue;
    space.v[i] += m_velocity[i] - (space.x[i] - start[i]) / h;
    space.x[i] = start[i] + h * m_velocity[i];
  }
  m_detected = {};  // its spans are the caller's, valid for this call only
  return report;
}

}  // namespace weft
