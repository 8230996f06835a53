#include "contact/ContactDetector.h"

#include <weft/collision/ContinuousCollision.h>
#include <weft/collision/Proximity.h>
#include <weft/threading/Profiler.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>

namespace weft {
namespace {

// A vertex resting on a collider within this fraction of the thickness beyond it is constrained
// in the solve: every vertex of a cloth lying on a body then takes its own weight from the solve.
// Left to round-off, some were and their neighbours were not, and the constrained ones carried
// their neighbours' weight into friction's bound. A constraint that pulls is released by the
// solve (ImplicitEuler), so the shell never glues.
constexpr Real kPressedShell = 0.01;
// A face within this fraction of the thickness beyond its reach at the substep start rests on
// the body: it takes friction on its whole displacement.
constexpr Real kRestingFaceShell = 0.01;
// A pair that passed through itself within the substep is put back on its side this share of its
// thickness apart (the impact stage's separation).
constexpr Real kImpactSeparation = 0.25;
// Two collider contacts of a vertex whose normals meet at more than 120° (cosine below this)
// face each other across the vertex: the room between the bodies along them is the sum of the
// vertex's distances to both. A wider wedge leaves the vertex a way out, which the projection
// finds.
constexpr Real kOpposedNormals = -0.5;
// Feature pairs per parallel block: a closest-point test costs ~50–100 ns, so 128 pairs are
// 5–15 µs of work, above a fork/join.
constexpr TaskSystem::Index kGrainFeaturePairs = 128;
// Faces per parallel block of face-contact detection: a face away from the body costs ~40 ns,
// one over a mesh a few µs (its tree's box query), so 256 faces are 10 µs to a millisecond.
constexpr TaskSystem::Index kGrainFaces = 256;

// Thickness of a vertex's cloth.
Real thicknessOf(const ContactSpace& space, Index vertex) {
  return space.owners[space.owner[vertex]].thickness;
}

}  // namespace

void ContactDetector::build(const ContactSpace& space, TaskSystem* tasks) {
  m_tasks = tasks;
  m_features.build(space, tasks);
  m_pairFilter.build(tasks);
}

void ContactDetector::selectNear(const ContactSpace& space,
                                 std::span<const ColliderFrame> colliders, const Vec3Array& end,
                                 Real margin, DetectionCounts& counts) {
  m_near.clear();
  if (colliders.empty()) return;
  const Real thickness = space.maxThickness();
  // The paths of the free vertices; for a moving body, their starts carried with it too.
  const Aabb path = space.movablePaths(end);
  const Real reach = thickness * (1 + 1e-6) + margin + 1e-9;
  for (Index k = 0; k < Index(colliders.size()); ++k) {
    const ColliderFrame& collider = colliders[k];
    Aabb box = path;
    if (!collider.still()) {
      // A turning body: the paths relative to it are arcs, which stray from their chords.
      Real bulge = 0;
      for (Index i = 0; i < space.vertexCount(); ++i) {
        if (space.inverseMass[i] == 0) continue;
        addRelativePath(collider, space.startX[i], end[i], box, bulge);
      }
      box.inflate(bulge);
    }
    if (!m_skip || mayTouch(collider.shape, box, reach)) {
      m_near.push_back(k);
      ++counts.colliderPairsTested;
    } else {
      ++counts.colliderPairsSkipped;
    }
  }
}

template <class Fn>
void ContactDetector::forEachBlock(Index count, Index grain, Fn&& fn) {
  if (m_tasks) {
    m_tasks->parallelFor(count, grain, [&](Index begin, Index end, int) { fn(begin, end); });
    return;
  }
  for (Index begin = 0; begin < count; begin += grain) fn(begin, std::min(begin + grain, count));
}

ContactDetector::DeepestContact ContactDetector::deepestContact(
    const ContactSpace& space, std::span<const ColliderFrame> colliders, Index i) const {
  if (space.inverseMass[i] == 0) return {};
  const Real thickness = thicknessOf(space, i);
  const Vec3& predicted = m_predicted[i];
  // The deepest contact wins when a vertex touches several colliders: one direction per
  // vertex in the solve; the projector then keeps it off the others.
  Real deepest = (1 + kPressedShell) * thickness;
  Vec3 normal = Vec3::Zero();
  Index touched = kInvalidIndex;
  for (Index k : m_near) {
    const ColliderFrame& collider = colliders[k];
    Vec3 direction = Vec3::Zero();
    Real depth = 0;
    // Where the predicted motion relative to the body first meets it gives the face to stop
    // on: the end pose alone would push a vertex a fast body overran out through its far side.
    const std::optional<PathContact> hit =
        firstContactAlong(collider, space.startX[i], predicted, thickness);
    if (!hit) {
      // Only an end deeper than the deepest so far counts.
      const std::optional<ShapeContact> below =
          queryPointBelow(collider.shape, predicted, deepest);
      if (!below) continue;
      direction = below->normal;
      depth = below->distance;
    } else {
      const ShapeContact contact = queryPoint(collider.shape, predicted);
      direction = contact.normal;
      depth = contact.distance;
      // A path that stays outside after it comes near is a graze: the end's own distance
      // holds. Extrapolating the hit's tangent plane would overshoot on a curved body. A
      // two-sided shell (an open mesh) has no inside to show the middle in: there the path
      // from the hit on is tested for a crossing instead.
      const bool graze =
          contact.distance > 0 && contact.normal.dot(hit->normal) > 0 &&
          queryPoint(collider.shape, 0.5 * (hit->point + predicted)).distance > 0 &&
          !shellCrossing(collider.shape, hit->point, predicted);
      if (!graze) {
        direction = hit->impactNormal;
        depth = hit->distance + hit->normal.dot(predicted - hit->point);
      }
    }
    if (depth < deepest) {
      deepest = depth;
      normal = direction;
      touched = k;
    }
  }
  if (touched == kInvalidIndex) return {};
  return {normal, deepest, touched};
}

void ContactDetector::constrain(const ContactSpace& space,
                                std::span<const ColliderFrame> colliders, Real h,
                                std::span<const FaceSupport> supports,
                                std::vector<SolveConstraint>& out, DetectionCounts& counts) {
  out.clear();
  WEFT_PROFILE_ZONE("constrain");
  const Index n = space.vertexCount();
  // The predicted ends, for the box test (kept in the space's velocity-sized scratch below).
  m_predicted.resize(n);
  for (Index i = 0; i < n; ++i) m_predicted[i] = space.startX[i] + h * space.startV[i];
  selectNear(space, colliders, m_predicted, 0, counts);
  m_constrained.assign(n, 0);
  if (!m_near.empty()) {
    // Each vertex's deepest contact, in parallel (a query against a mesh costs microseconds);
    // the constraints are then listed in vertex order.
    m_deepest.resize(n);
    forEachBlock(n, kGrainVertexQueries, [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i) m_deepest[i] = deepestContact(space, colliders, i);
    });
    for (Index i = 0; i < n; ++i) {
      const DeepestContact& deepest = m_deepest[i];
      if (deepest.collider == kInvalidIndex) continue;
      // n·Δv that ends the step at the thickness: d(x + h(v + Δv)) ≈ d(x + h v) + h n·Δv.
      out.push_back({i, deepest.normal, (thicknessOf(space, i) - deepest.depth) / h,
                     deepest.collider});
      m_constrained[i] = 1;
    }
  }
  // Faces resting on a body by their interior: their corners are clear of it, so the vertex
  // constraints do not hold them, and the solve would sink the face h² g a step into the body.
  // Each corner is constrained along the support's normal so that the face point ends the step
  // at its level; one that rests a little clear comes down onto it, as a pressed vertex does.
  for (const FaceSupport& support : supports) {
    Vec3 point = Vec3::Zero(), velocity = Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      point += support.barycentric[k] * space.startX[support.corners[k]];
      velocity += support.barycentric[k] * space.startV[support.corners[k]];
    }
    const Real thickness = thicknessOf(space, support.corners[0]);
    const Real gap = support.normal.dot(point) - support.level;
    if (gap > kPressedShell * thickness && gap + h * support.normal.dot(velocity) > 0) continue;
    const Real speed = -gap / h;
    for (int k = 0; k < 3; ++k) {
      const Index corner = support.corners[k];
      if (!(support.barycentric[k] > 0) || space.inverseMass[corner] == 0 || m_constrained[corner]) {
        continue;
      }
      out.push_back({corner, support.normal, speed - support.normal.dot(space.startV[corner]),
                     kFaceCornerConstraint});
      m_constrained[corner] = 1;
    }
  }
  // By vertex: the filter is written in this order.
  std::sort(out.begin(), out.end(),
            [](const SolveConstraint& a, const SolveConstraint& b) { return a.vertex < b.vertex; });
}

void ContactDetector::detect(const ContactSpace& space, std::span<const ColliderFrame> colliders,
                             std::span<const Real> solveImpulses,
                             std::span<const Index> constrainedCollider, bool pairs, Real margin,
                             ContactSet& set, DetectionCounts& counts) {
  WEFT_PROFILE_ZONE("detect");
  set.clear();
  selectNear(space, colliders, space.x, margin, counts);
  if (!m_near.empty()) {
    detectColliderVertices(space, colliders, solveImpulses, constrainedCollider, margin, set,
                           counts);
    detectColliderFaces(space, colliders, solveImpulses, constrainedCollider, margin, set);
  }
  set.firstPair = set.contacts.size();
  if (pairs) detectPairs(space, set);
}

ContactDetector::VertexQuery ContactDetector::queryVertex(const ContactSpace& space,
                                                         const ColliderFrame& collider,
                                                         Real margin, Index i) {
  const Real thickness = thicknessOf(space, i);
  VertexQuery query;
  // An end within the margin is a contact; one beyond it, only where the path hit the body.
  query.end = queryPointBelow(collider.shape, space.x[i], thickness + margin);
  if (!query.end) {
    query.hit = firstContactAlong(collider, space.startX[i], space.x[i], thickness);
    if (!query.hit) return query;
    query.end = queryPoint(collider.shape, space.x[i]);
  }
  const Vec3 start = collider.carry(space.startX[i]);
  query.resting =
      queryPointBelow(collider.shape, start, (1 + kPressedShell) * thickness).has_value();
  return query;
}

void ContactDetector::detectColliderVertices(const ContactSpace& space,
                                             std::span<const ColliderFrame> colliders,
                                             std::span<const Real> solveImpulses,
                                             std::span<const Index> constrainedCollider,
                                             Real margin, ContactSet& set,
                                             DetectionCounts& counts) {
  const Index n = space.vertexCount();
  const std::size_t near = m_near.size();
  // The queries, in parallel (a query against a mesh costs microseconds); the contacts are then
  // listed in vertex order.
  m_vertexQueries.resize(n * near);
  forEachBlock(n, kGrainVertexQueries, [&](Index begin, Index end) {
    for (Index i = begin; i < end; ++i) {
      if (space.inverseMass[i] == 0) continue;
      for (std::size_t j = 0; j < near; ++j) {
        m_vertexQueries[i * near + j] = queryVertex(space, colliders[m_near[j]], margin, i);
      }
    }
  });
  m_vertexContacts.resize(n + 1);
  for (Index i = 0; i < n; ++i) {
    m_vertexContacts[i] = set.contacts.size();
    if (space.inverseMass[i] == 0) continue;
    const Real thickness = thicknessOf(space, i);
    const Real friction = space.owners[space.owner[i]].friction;
    const std::size_t first = set.contacts.size();
    m_surfaceNormals.clear();
    for (std::size_t j = 0; j < near; ++j) {
      const Index k = m_near[j];
      const VertexQuery& query = m_vertexQueries[i * near + j];
      if (!query.end) continue;
      Contact contact;
      contact.kind = ContactKind::VertexCollider;
      contact.vertices[0] = i;
      contact.normal = query.hit ? query.hit->normal : query.end->normal;
      m_surfaceNormals.push_back(query.end->normal);
      contact.separation = thickness;
      contact.gap = query.end->distance;
      contact.friction = std::sqrt(std::max<Real>(0, colliders[k].friction) * friction);
      contact.collider = k;
      contact.resting = query.resting;
      if (!solveImpulses.empty() && constrainedCollider[i] == k) {
        contact.solveImpulse = std::max<Real>(0, solveImpulses[i]);
      }
      set.contacts.push_back(contact);
    }
    // Squeezed between two bodies closer than twice the thickness: no position keeps the
    // thickness from both, and keeping it from one pushes the vertex into the other. Each
    // contact keeps half the room instead, which holds the vertex midway, outside both.
    bool squeezed = false;
    for (std::size_t a = first; a < set.contacts.size(); ++a) {
      for (std::size_t b = a + 1; b < set.contacts.size(); ++b) {
        Contact& one = set.contacts[a];
        Contact& other = set.contacts[b];
        Real room = one.gap + other.gap;
        if (!(one.normal.dot(other.normal) < kOpposedNormals)) {
          // The normals of the contacts need not face each other where the vertex came in
          // through a side (under a press's edge): the bodies' surfaces may still do, across it.
          const Vec3& x = space.x[i];
          room = std::min(roomAcross(colliders, x, one, m_surfaceNormals[a - first], other),
                          roomAcross(colliders, x, other, m_surfaceNormals[b - first], one));
        }
        if (!(room < one.separation + other.separation)) continue;
        const Real half = std::max<Real>(0, room / 2);
        one.separation = std::min(one.separation, half);
        other.separation = std::min(other.separation, half);
        squeezed = true;
      }
    }
    counts.squeezedVertices += squeezed;
  }
  m_vertexContacts[space.vertexCount()] = set.contacts.size();
}

void ContactDetector::findFaceCores(const ContactSpace& space, const ColliderFrame& collider,
                                    const Aabb& body, Real margin, Index face,
                                    FaceBlock& block) const {
  const std::array<Index, 3>& corner = space.triangles[face];
  if (!space.faceContacts(corner[0])) return;
  if (space.inverseMass[corner[0]] == 0 && space.inverseMass[corner[1]] == 0 &&
      space.inverseMass[corner[2]] == 0) {
    return;
  }
  // The face's path relative to the body, against the body at its end pose: its start carried
  // with the body, and its end. A face may cross a thin body within one substep, and a fast body
  // may cross a face that barely moves (its box at the end pose alone is then far from the
  // face). With the margin: the projection may move a face that far towards the body; with the
  // bulge: a turning body's relative paths are arcs.
  Aabb box = Aabb::empty();
  Real bulge = 0;
  for (Index i : corner) addRelativePath(collider, space.startX[i], space.x[i], box, bulge);
  box.inflate(margin + bulge);
  if (!box.overlaps(body)) return;
  const TriangleMeshShape* mesh = std::get_if<TriangleMeshShape>(&collider.shape);
  const Real allowance = thicknessOf(space, corner[0]);
  block.cores.clear();
  appendCores(collider.shape, allowance, block.cores);
  if (block.cores.empty() && !mesh) return;  // a plane: vertices only
  // The face's path in the body's frame (start and end), against each core's box.
  const Pose& endPose = collider.end.pose;
  const Pose& startPose = collider.start.pose;
  Aabb path = Aabb::empty();
  std::array<Vec3, 3> startLocal;
  for (int j = 0; j < 3; ++j) {
    startLocal[j] = startPose.toLocal(space.startX[corner[j]]);
    path.expand(startLocal[j]);
    path.expand(endPose.toLocal(space.x[corner[j]]));
  }
  path.inflate(margin);
  if (mesh) {
    Aabb near = path;
    near.inflate(0.5 * allowance);
    // The face's extent: its longest edge at the start or the end.
    Real span = 0;
    for (int j = 0; j < 3; ++j) {
      const Index from = corner[j], to = corner[(j + 1) % 3];
      span = std::max({span, (space.startX[to] - space.startX[from]).norm(),
                       (space.x[to] - space.x[from]).norm()});
    }
    appendMeshCores(*mesh, near, allowance, span, block.cores, block.triangles, block.edges);
  }
  for (const FaceCore& core : block.cores) {
    if (!core.box.overlaps(path)) continue;
    // Which side of the core the face started on (zero: it started on the core).
    const SegmentTriangleClosestPoints before = closestPointsOnSegmentAndTriangle(
        core.start, core.end, startLocal[0], startLocal[1], startLocal[2]);
    block.found.push_back({face, core, before});
  }
}

void ContactDetector::detectColliderFaces(const ContactSpace& space,
                                          std::span<const ColliderFrame> colliders,
                                          std::span<const Real> solveImpulses,
                                          std::span<const Index> constrainedCollider,
                                          Real margin, ContactSet& set) {
  WEFT_PROFILE_ZONE("face contacts");
  const Index faces = Index(space.triangles.size());
  const Index blocks = TaskSystem::blockCount(faces, kGrainFaces);
  if (m_faceBlocks.size() < blocks) m_faceBlocks.resize(blocks);
  for (Index k : m_near) {
    const ColliderFrame& collider = colliders[k];
    const Aabb body = bounds(collider.shape);
    // The cores each face may touch, in parallel over fixed blocks of faces (a face over a mesh
    // queries the mesh's tree); then, in face order, the contacts.
    forEachBlock(faces, kGrainFaces, [&](Index begin, Index end) {
      FaceBlock& block = m_faceBlocks[begin / kGrainFaces];
      block.found.clear();
      for (Index t = begin; t < end; ++t) findFaceCores(space, collider, body, margin, t, block);
    });
    const Pose& endPose = collider.end.pose;
    for (Index b = 0; b < blocks; ++b) {
      for (const FaceCandidate& found : m_faceBlocks[b].found) {
        const std::array<Index, 3>& corner = space.triangles[found.face];
        const Real allowance = thicknessOf(space, corner[0]);
        const SegmentTriangleClosestPoints& before = found.before;
        Contact contact;
        contact.kind = ContactKind::FaceCollider;
        contact.vertices = {corner[0], corner[1], corner[2], kInvalidIndex};
        contact.weights = {0, 0, 0, 0};
        if (before.distance > 0) {
          contact.normal = (before.pointOnTriangle - before.pointOnSegment) / before.distance;
        }
        contact.separation = found.core.reach;
        contact.gap = before.distance - found.core.reach;
        contact.friction = std::sqrt(std::max<Real>(0, collider.friction) *
                                     space.owners[space.owner[corner[0]]].friction);
        contact.collider = k;
        contact.core = Index(set.cores.size());
        contact.resting = before.distance <= found.core.reach + kRestingFaceShell * allowance;
        // The solve's support of a face resting on the body: its corners' constraints, averaged
        // as the centroid where friction acts takes them.
        if (!solveImpulses.empty()) {
          for (Index i : corner) {
            if (constrainedCollider[i] == kFaceCornerConstraint) {
              contact.solveImpulse += std::max<Real>(0, solveImpulses[i]) / 3;
            }
          }
        }
        set.cores.push_back(found.core);
        if (before.distance > 0) {
          squeezeFace(colliders, contact, endPose.toWorld(before.pointOnSegment),
                      endPose.rotation * contact.normal, allowance, set);
        }
        set.contacts.push_back(contact);
      }
    }
  }
}

Real ContactDetector::roomAcross(std::span<const ColliderFrame> colliders, const Vec3& x,
                                 const Contact& from, const Vec3& surfaceNormal,
                                 const Contact& to) {
  // From the point of `from`'s body nearest the vertex, across to `to`'s body: the room between
  // them when `to`'s surface there faces `from`'s back.
  const Vec3 surfacePoint = x - from.gap * surfaceNormal;
  const ShapeContact across = queryPoint(colliders[to.collider].shape, surfacePoint);
  if (!(across.normal.dot(surfaceNormal) < kOpposedNormals)) {
    return std::numeric_limits<Real>::infinity();
  }
  return across.distance;
}

void ContactDetector::squeezeFace(std::span<const ColliderFrame> colliders, const Contact& face,
                                  const Vec3& corePoint, const Vec3& normal, Real thickness,
                                  ContactSet& set) const {
  // A face lies between the core and another body when the core point is outside that body and
  // the body's normal there meets the core-to-face direction head on (a press's edge over a sheet
  // on a floor). The face keeps the core's reach from the core, and its corners the thickness
  // from the body: where the two are farther apart than their distance, each gives up the same
  // share, and so do the corners' contacts with the core's own body, as a squeezed vertex's two
  // contacts do. A corner kept its thickness from either body would hold the face into the core
  // or push it into the other body. A core point inside the other body (capsules overlapping in a
  // ring) has no face between them.
  FaceCore& core = set.cores[face.core];
  for (Index j : m_near) {
    if (j == face.collider) continue;
    const ShapeContact other = queryPoint(colliders[j].shape, corePoint);
    const Real wanted = core.reach + thickness;
    if (!(other.distance > 0 && other.distance < wanted) ||
        !(other.normal.dot(normal) < kOpposedNormals)) {
      continue;
    }
    const Real share = other.distance / wanted;
    core.reach *= share;
    // A corner may slide anywhere under the core's body, where the two are as near: it keeps no
    // more than half their distance from either.
    const Real corners = std::min(share * thickness, other.distance / 2);
    for (int k = 0; k < 3; ++k) {
      const Index corner = face.vertices[k];
      for (std::size_t c = m_vertexContacts[corner]; c < m_vertexContacts[corner + 1]; ++c) {
        Contact& contact = set.contacts[c];
        if (contact.collider == j || contact.collider == face.collider) {
          contact.separation = std::min(contact.separation, corners);
        }
      }
    }
  }
}

void ContactDetector::detectPairs(const ContactSpace& space, ContactSet& set) {
  m_pairMargin = kPairReach * space.maxThickness();
  m_features.find(space, space.startX, space.x, m_pairMargin);
  const auto& vertexTriangle = m_features.vertexTriangle();
  const auto& edgeEdgePairs = m_features.edgeEdge();
  const Index vertexTriangleCount = Index(vertexTriangle.size());
  const Index total = vertexTriangleCount + Index(edgeEdgePairs.size());
  const Vec3Array& x0 = space.startX;
  const Vec3Array& x1 = space.x;
  // The contact of a pair (see the file comment): closer than its thickness at the start, with
  // the start's closest points, whose side x₀ (free of crossings) gives (Bridson, Fedkiw &
  // Anderson 2002's proximity); or passed through itself within the motion (a change of side of
  // the vertex against the face's plane, or of the edges against each other, is the cheap sign,
  // the swept test decides), with the point of the hit and the side it came from. A pair that
  // only ends close is left to the next substep's start, where its side is known.
  auto vertexFace = [&](Index vertex, Index triangle, Contact& contact) -> bool {
    const std::array<Index, 3>& c = space.triangles[triangle];
    const Real thickness = space.pairThickness(vertex, c[0]);
    const Vec3 n0 = (x0[c[1]] - x0[c[0]]).cross(x0[c[2]] - x0[c[0]]);
    const Vec3 n1 = (x1[c[1]] - x1[c[0]]).cross(x1[c[2]] - x1[c[0]]);
    const bool sideChanged = n0.dot(x0[vertex] - x0[c[0]]) * n1.dot(x1[vertex] - x1[c[0]]) <= 0;
    if (!sideChanged &&
        !featureBoxesWithin({vertex}, {c[0], c[1], c[2]}, x0, x0, kPairReach * thickness)) {
      return false;
    }
    const TriangleClosestPoint start = closestPointOnTriangle(x0[vertex], x0[c[0]], x0[c[1]], x0[c[2]]);
    if (!(start.distance < kPairReach * thickness) && !sideChanged) return false;
    // Neighbours in the material (within the pairs' reach at rest): the elastic forces keep
    // them apart.
    if (space.restNeighbours(vertex, c)) return false;
    contact.kind = ContactKind::VertexFace;
    contact.vertices = {vertex, c[0], c[1], c[2]};
    contact.separation = thickness;
    contact.friction = space.pairFriction(vertex, c[0]);
    contact.resting = start.distance < thickness;
    contact.gap = start.distance;
    if (!(start.distance < kPairReach * thickness)) {
      const std::optional<VertexTriangleImpact> hit = sweptVertexTriangle(
          x0[vertex], x1[vertex], {x0[c[0]], x0[c[1]], x0[c[2]]}, {x1[c[0]], x1[c[1]], x1[c[2]]});
      if (!hit) return false;
      contact.weights = {1, -hit->barycentric[0], -hit->barycentric[1], -hit->barycentric[2]};
      contact.normal = hit->normal;
      contact.gap = 0;
      contact.separation = kImpactSeparation * thickness;
      return true;
    }
    contact.weights = {1, -start.barycentric[0], -start.barycentric[1], -start.barycentric[2]};
    Vec3 normal = x0[vertex] - start.point;
    if (start.distance < 1e-9 * thickness) normal = n0;
    if (normal.norm() == 0) return false;
    contact.normal = normal.normalized();
    return true;
  };
  auto edgeEdge = [&](Index firstEdge, Index secondEdge, Contact& contact) -> bool {
    const std::array<Index, 2>& p = space.edges[firstEdge];
    const std::array<Index, 2>& q = space.edges[secondEdge];
    const Real thickness = space.pairThickness(p[0], q[0]);
    const Vec3 n0 = (x0[p[1]] - x0[p[0]]).cross(x0[q[1]] - x0[q[0]]);
    const Vec3 n1 = (x1[p[1]] - x1[p[0]]).cross(x1[q[1]] - x1[q[0]]);
    const bool sideChanged = n0.dot(x0[p[0]] - x0[q[0]]) * n1.dot(x1[p[0]] - x1[q[0]]) <= 0;
    if (!sideChanged &&
        !featureBoxesWithin({p[0], p[1]}, {q[0], q[1]}, x0, x0, kPairReach * thickness)) {
      return false;
    }
    const SegmentClosestPoints start = closestPointsOnSegments(x0[p[0]], x0[p[1]], x0[q[0]], x0[q[1]]);
    if (!(start.distance < kPairReach * thickness) && !sideChanged) return false;
    if (space.restNeighbours(p, q)) return false;
    contact.kind = ContactKind::EdgeEdge;
    contact.vertices = {p[0], p[1], q[0], q[1]};
    contact.separation = thickness;
    contact.friction = space.pairFriction(p[0], q[0]);
    contact.resting = start.distance < thickness;
    contact.gap = start.distance;
    if (!(start.distance < kPairReach * thickness)) {
      const std::optional<EdgeEdgeImpact> hit =
          sweptEdgeEdge({x0[p[0]], x0[p[1]]}, {x1[p[0]], x1[p[1]]}, {x0[q[0]], x0[q[1]]},
                        {x1[q[0]], x1[q[1]]});
      if (!hit) return false;
      const Real s = hit->firstParameter, u = hit->secondParameter;
      contact.weights = {1 - s, s, -(1 - u), -u};
      contact.normal = hit->normal;
      contact.gap = 0;
      contact.separation = kImpactSeparation * thickness;
      return true;
    }
    const Real s = start.firstParameter, u = start.secondParameter;
    contact.weights = {1 - s, s, -(1 - u), -u};
    Vec3 normal = ((1 - s) * x0[p[0]] + s * x0[p[1]]) - ((1 - u) * x0[q[0]] + u * x0[q[1]]);
    if (start.distance < 1e-9 * thickness) normal = n0;
    if (normal.norm() == 0) return false;
    contact.normal = normal.normalized();
    return true;
  };
  auto test = [&](Index pair, Contact& contact) -> bool {
    const bool found =
        pair < vertexTriangleCount
            ? vertexFace(vertexTriangle[pair][0], vertexTriangle[pair][1], contact)
            : edgeEdge(edgeEdgePairs[pair - vertexTriangleCount][0],
                       edgeEdgePairs[pair - vertexTriangleCount][1], contact);
    if (found && contact.resting) {
      // A pair that starts the substep closer than its thickness need only part of the way back
      // to it in one substep (Bridson, Fedkiw & Anderson 2002's repulsion rate), never closer
      // than it started: folds pressed tighter than two thicknesses (a sandwiched layer) would
      // otherwise ask for positions no projection can reach.
      const Real startGap = std::max<Real>(0, contact.normal.dot(contact.relativePosition(x0)));
      if (startGap < contact.separation) {
        contact.separation = startGap + kRepulsionRate * (contact.separation - startGap);
      }
    }
    return found;
  };
  WEFT_PROFILE_ZONE("narrow phase");
  m_pairFilter.run(total, kGrainFeaturePairs, test, set.contacts);
}

}  // namespace weft
