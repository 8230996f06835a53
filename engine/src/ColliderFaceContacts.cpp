#include "ColliderFaceContacts.h"

#include <weft/collision/Proximity.h>
#include <weft/collision/Shape.h>
#include <weft/threading/Profiler.h>

#include <algorithm>
#include <limits>
#include <variant>

namespace weft {
namespace {

// Sweeps over the contacts at most: the first finds and resolves them, later ones fix what a
// neighbouring face's correction undid. Faces rarely share a contact with more than two or three
// neighbours, so the sweeps converge fast; what is left is within the vertices' thickness.
constexpr int kMaxSweeps = 4;
// m: a sweep that moved no face point farther than this ends the loop (round-off, not contact).
constexpr Real kSettledDepth = 1e-9;

// A core from `start` to `end` kept `reach` away from, with its box.
FaceCore makeCore(const Vec3& start, const Vec3& end, Real reach) {
  FaceCore core{start, end, reach, Aabb::empty()};
  core.box.expand(start);
  core.box.expand(end);
  core.box.inflate(std::max<Real>(reach, 0));
  return core;
}

// The cores of a body in its own frame that faces are kept away from (see the design note): a
// sphere's centre (a segment of length 0) and a capsule's segment, each `radius` − allowance (at
// least half the allowance); a
// box's twelve edges, half the allowance (a face need not keep the thickness from an edge that
// pokes into it between its vertices, only stay on its side). Appends to `cores`; a mesh's
// edges are found per face (resolve()).
void appendCores(const Shape& shape, Real allowance, std::vector<FaceCore>& cores) {
  // A ball or capsule thinner than the allowance is kept away from as an edge is: a negative
  // reach would let a face rest past the core, on the far side it must not reach.
  const auto roundReach = [&](Real radius) {
    return std::max(radius - allowance, 0.5 * allowance);
  };
  if (const Sphere* sphere = std::get_if<Sphere>(&shape)) {
    cores.push_back(makeCore(Vec3::Zero(), Vec3::Zero(), roundReach(sphere->radius())));
  } else if (const Capsule* capsule = std::get_if<Capsule>(&shape)) {
    const Vec3 half(0, capsule->halfLength(), 0);
    cores.push_back(makeCore(-half, half, roundReach(capsule->radius())));
  } else if (const Box* box = std::get_if<Box>(&shape)) {
    const Vec3& e = box->halfExtents();
    for (int axis = 0; axis < 3; ++axis) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      for (int corner = 0; corner < 4; ++corner) {
        Vec3 a = Vec3::Zero();
        a[u] = (corner & 1) ? e[u] : -e[u];
        a[w] = (corner & 2) ? e[w] : -e[w];
        Vec3 b = a;
        a[axis] = -e[axis];
        b[axis] = e[axis];
        cores.push_back(makeCore(a, b, 0.5 * allowance));
      }
    }
  }
}

// A point where a face meets a core, in the body's frame: the face point (barycentric weights of
// the corners), the unit normal from the core to the face, the core point, and how far the face
// point must move along the normal to be `reach` from the core (≤ 0: it is).
struct FacePoint {
  Vec3 barycentric = Vec3::Zero();
  Vec3 normal = Vec3::Zero();
  Vec3 corePoint = Vec3::Zero();
  Real depth = 0;
};

// A face within this fraction of the allowance beyond its reach at the step start began the step
// on the body: friction may move its position (ColliderResponse's pressed shell, for faces).
constexpr Real kStartedOnShell = 0.01;

// A face whose normal leans less than this (the cosine of its angle to the plane across a line
// core) is pushed along its own normal: one nearly across the core, which pierces it.
constexpr Real kLeastAcross = 0.5;

// Points closer than this (m) outside the reach still count as touching: they get a limiter hold
// and their approach velocity removed (a face the sweeps just put at the reach is at -1e-17).
constexpr Real kTouching = 1e-9;

// The contact points of face (a, b, c) with `core` (body frame), at most three, into `points`;
// returns how many: those deeper than `minDepth`. `cameFrom`: the core-to-face normal at the step
// start (zero if unknown).
//  - Over the face's interior: the part of the core segment above the face (clipped to the
//    triangle's prism) is a line whose height over the plane is linear, so its two ends are
//    the deepest points: a box edge or a capsule lying parallel to the face touches it along a
//    line, which one closest point (the kernel's, on an edge of the face) would push only at one
//    end, tilting the face round the other.
//  - Beside the face: the closest points of the segment and the triangle, when they lie on the
//    face's boundary.
// The side: the one the face came from when it crossed the core within the step (its own normal
// then points through the body), else its own.
int facePoints(const FaceCore& core, const Vec3& cameFrom, const Vec3& a, const Vec3& b,
               const Vec3& c, Real minDepth, std::array<FacePoint, 3>& points) {
  int count = 0;
  const Vec3 segment = core.end - core.start;
  const Vec3 plane = (b - a).cross(c - a);
  const Real twiceArea = plane.norm();
  const Real longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  if (twiceArea > 1e-6 * longest * longest) {
    const Vec3 up = plane / twiceArea;
    // Clip the segment to the prism over the triangle: each edge's inward half-space.
    Real low = 0, high = 1;
    const Vec3* corners[3] = {&a, &b, &c};
    for (int edge = 0; edge < 3 && low <= high; ++edge) {
      const Vec3& from = *corners[edge];
      const Vec3& to = *corners[(edge + 1) % 3];
      const Vec3 inward = up.cross(to - from);  // into the triangle (counter-clockwise about up)
      const Real at = inward.dot(core.start - from), rate = inward.dot(segment);
      if (rate == 0) {
        if (at < 0) high = -1;  // parallel to this edge and outside
      } else if (rate > 0) {
        low = std::max(low, -at / rate);
      } else {
        high = std::min(high, -at / rate);
      }
    }
    if (low <= high) {
      const Real ends[2] = {low, high};
      const bool line = high > low && segment.squaredNorm() > 0;
      for (int k = 0; k < (line ? 2 : 1); ++k) {
        const Vec3 corePoint = core.start + ends[k] * segment;
        const Real height = up.dot(corePoint - a);  // of the core point over the face's plane
        Real side = cameFrom.isZero() ? 0 : (cameFrom.dot(up) > 0 ? 1 : -1);
        if (side == 0) side = height < 0 ? 1 : (height > 0 ? -1 : 0);
        if (side == 0) continue;  // on the face, with no start to tell the side
        const Vec3 onPlane = corePoint - height * up;
        // Barycentric weights from the sub-triangle areas (clamped: the point is in the prism).
        Vec3 weights((b - onPlane).cross(c - onPlane).dot(up),
                     (c - onPlane).cross(a - onPlane).dot(up),
                     (a - onPlane).cross(b - onPlane).dot(up));
        weights = weights.cwiseMax(0);
        const Real total = weights.sum();
        if (!(total > 0)) continue;
        FacePoint& point = points[count];
        point.barycentric = weights / total;
        point.normal = side * up;
        point.corePoint = corePoint;
        point.depth = core.reach + side * height;  // the face point is −side·height from the core
        if (line) {
          // A line core (a capsule's axis, a box's edge) pushes across itself: the face's normal
          // without its part along the core, which a face tilted along a rod would otherwise
          // turn into a push along the rod (see the note). The depth is along that direction:
          // moving the face point by it lifts the face's plane there by the height it lacks.
          const Vec3 along = segment.normalized();
          const Vec3 across = point.normal - point.normal.dot(along) * along;
          const Real lift = across.norm();  // = cos of the tilt: its dot with the face normal
          if (lift > kLeastAcross) {
            point.normal = across / lift;
            point.depth /= lift;
          }
        }
        if (point.depth > minDepth) ++count;
      }
    }
  }
  const SegmentTriangleClosestPoints closest =
      closestPointsOnSegmentAndTriangle(core.start, core.end, a, b, c);
  if (closest.barycentric.minCoeff() == 0 && closest.distance > 0) {
    Vec3 normal = (closest.pointOnTriangle - closest.pointOnSegment) / closest.distance;
    if (!cameFrom.isZero() && normal.dot(cameFrom) < 0) normal = cameFrom;
    FacePoint& point = points[count];
    point.barycentric = closest.barycentric;
    point.normal = normal;
    point.corePoint = closest.pointOnSegment;
    point.depth = core.reach - normal.dot(closest.pointOnTriangle - closest.pointOnSegment);
    if (point.depth > minDepth) ++count;
  }
  return count;
}

// Σ b_k² w_k over a face's corners: the inverse mass a face point of barycentric weights `b` has
// against an immovable body.
Real pointInverseMass(const Vec3& b, const std::array<Index, 3>& corner,
                      std::span<const Real> inverseMasses) {
  Real weight = 0;
  for (int j = 0; j < 3; ++j) weight += b[j] * b[j] * inverseMasses[corner[j]];
  return weight;
}

// Moves the face point of weights `b` by amount · direction in `values` (positions or
// velocities): corner k by b_k w_k / weight · amount · direction, weight = pointInverseMass.
void moveFacePoint(const Vec3& b, const std::array<Index, 3>& corner,
                   std::span<const Real> inverseMasses, Real weight, Real amount,
                   const Vec3& direction, std::span<Vec3> values) {
  for (int j = 0; j < 3; ++j) {
    values[corner[j]] += (b[j] * inverseMasses[corner[j]] / weight * amount) * direction;
  }
}

// Pushes each point where the face of `corner` is short of its reach from `core` out to it, one
// after the other, each seeing the face where the last push left it (x; the body posed at
// `endPose`); with inverseStep > 0 each shift Δx is made as the velocity change Δx · inverseStep
// in `v` too. Every contact point is listed, shallow ones too, so that the list recomputed after
// a push enumerates the same points in the same order (with only the deep ones kept, a push that
// made the first point shallow shifted the others down, and the loop skipped the last one: a
// face edge beside a rod stayed 0.12 mm inside the reach). Returns how many points were deeper
// than `counted` (m); `pushed` is set when a point moved.
int pushFaceOut(const FaceCore& core, const Vec3& cameFrom, const Pose& endPose,
                const std::array<Index, 3>& corner, std::span<const Real> inverseMasses,
                Real counted, std::span<Vec3> x, std::span<Vec3> v, Real inverseStep,
                bool& pushed) {
  std::array<FacePoint, 3> points;
  std::array<Vec3, 3> local;
  const auto findPoints = [&] {
    for (int j = 0; j < 3; ++j) local[j] = endPose.toLocal(x[corner[j]]);
    return facePoints(core, cameFrom, local[0], local[1], local[2],
                      -std::numeric_limits<Real>::infinity(), points);
  };
  int deep = 0;
  int count = findPoints();
  for (int p = 0; p < count; ++p) {
    const FacePoint& point = points[p];
    if (!(point.depth > 0)) continue;
    const Vec3& b = point.barycentric;
    const Real weight = pointInverseMass(b, corner, inverseMasses);
    if (!(weight > 0)) continue;
    const Vec3 normal = endPose.directionToWorld(point.normal);
    for (int j = 0; j < 3; ++j) {
      // moveFacePoint's distribution, by the depth along the normal.
      const Vec3 shift = (b[j] * inverseMasses[corner[j]] / weight * point.depth) * normal;
      x[corner[j]] += shift;
      if (inverseStep > 0) v[corner[j]] += inverseStep * shift;
    }
    pushed = true;
    deep += point.depth > counted;
    if (p + 1 < count) count = findPoints();
  }
  return deep;
}

}  // namespace

ColliderFaceReport ColliderFaceContacts::resolve(std::span<const ColliderFrame> colliders,
                                                 std::span<const TriangleRest> triangles,
                                                 const Vec3Array& xStart,
                                                 std::span<const Real> inverseMasses,
                                                 Real allowance, Vec3Array& x, Vec3Array& v,
                                                 bool friction, Real positionStep,
                                                 std::span<const Real> solveImpulses) {
  ColliderFaceReport report;
  m_holds.clear();
  m_candidates.clear();
  WEFT_PROFILE_ZONE("face contacts");
  m_cores.clear();
  for (Index k = 0; k < Index(colliders.size()); ++k) {
    const Index firstCore = Index(m_cores.size());
    appendCores(*colliders[k].shape, allowance, m_cores);
    const TriangleMeshShape* mesh = std::get_if<TriangleMeshShape>(colliders[k].shape);
    const Index lastCore = Index(m_cores.size());
    if (lastCore == firstCore && !mesh) continue;  // a plane: vertices only
    const Aabb body = bounds(*colliders[k].shape);
    const Pose& endPose = colliders[k].end.pose;
    const Pose& startPose = colliders[k].start.pose;
    for (Index t = 0; t < Index(triangles.size()); ++t) {
      const std::array<Index, 3>& corner = triangles[t].vertices;
      if (inverseMasses[corner[0]] == 0 && inverseMasses[corner[1]] == 0 &&
          inverseMasses[corner[2]] == 0) {
        continue;
      }
      // Start and end: a face may cross a thin body within one step (a sheet falling at 1.4 m/s
      // moves 2.3 cm a step, past a 2 cm plank).
      Aabb box = Aabb::empty();
      for (Index i : corner) {
        box.expand(x[i]);
        box.expand(xStart[i]);
      }
      if (!box.overlaps(body)) continue;
      // The face's path in the body's frame (start and end), against each core's box: a face
      // that crossed a box's edge within the step may end beside it.
      Aabb path = Aabb::empty();
      std::array<Vec3, 3> startLocal;
      for (int j = 0; j < 3; ++j) {
        startLocal[j] = startPose.toLocal(xStart[corner[j]]);
        path.expand(startLocal[j]);
        path.expand(endPose.toLocal(x[corner[j]]));
      }
      Index coresBegin = firstCore, coresEnd = lastCore;
      if (mesh) {
        // A mesh's cores are the edges of its triangles near this face's path, one core per edge
        // (an edge of two triangles is met twice).
        Aabb near = path;
        near.inflate(0.5 * allowance);
        m_meshTriangles.clear();
        mesh->localBvh().queryBox(near, m_meshTriangles);
        m_meshEdges.clear();
        for (Index meshTriangle : m_meshTriangles) {
          for (int j = 0; j < 3; ++j) {
            const Index a = mesh->indices()[3 * meshTriangle + j];
            const Index b = mesh->indices()[3 * meshTriangle + (j + 1) % 3];
            m_meshEdges.push_back({std::min(a, b), std::max(a, b)});
          }
        }
        std::sort(m_meshEdges.begin(), m_meshEdges.end());
        m_meshEdges.erase(std::unique(m_meshEdges.begin(), m_meshEdges.end()), m_meshEdges.end());
        coresBegin = Index(m_cores.size());
        for (const auto& [a, b] : m_meshEdges) {
          m_cores.push_back(
              makeCore(mesh->localVertices()[a], mesh->localVertices()[b], 0.5 * allowance));
        }
        coresEnd = Index(m_cores.size());
      }
      for (Index c = coresBegin; c < coresEnd; ++c) {
        const FaceCore& core = m_cores[c];
        if (!core.box.overlaps(path)) continue;
        // Which side of the core the face started on (zero: it started on the core).
        const SegmentTriangleClosestPoints before = closestPointsOnSegmentAndTriangle(
            core.start, core.end, startLocal[0], startLocal[1], startLocal[2]);
        Candidate candidate;
        candidate.triangle = t;
        candidate.collider = k;
        candidate.core = c;
        if (before.distance > 0) {
          candidate.cameFrom = (before.pointOnTriangle - before.pointOnSegment) / before.distance;
        }
        candidate.startedOn = before.distance <= core.reach + kStartedOnShell * allowance;
        m_candidates.push_back(candidate);
      }
    }
  }
  if (m_candidates.empty()) return report;
  if (friction) m_cornerSlot.resize(x.size(), kInvalidIndex);  // allocates only when the cloth grows

  std::array<FacePoint, 3> points;
  const auto cornersInBody = [&](const Candidate& candidate, std::array<Vec3, 3>& local) {
    const std::array<Index, 3>& corner = triangles[candidate.triangle].vertices;
    const Pose& endPose = colliders[candidate.collider].end.pose;
    for (int j = 0; j < 3; ++j) local[j] = endPose.toLocal(x[corner[j]]);
  };
  // Pushes every face point short of its reach out, Gauss–Seidel in candidate order, sweeping
  // again while a sweep moved a face, kMaxSweeps times at most.
  const auto sweepOut = [&] {
    for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
      ++report.sweeps;
      bool moved = false;
      for (Candidate& candidate : m_candidates) {
        bool pushed = false;
        const int deep = pushFaceOut(m_cores[candidate.core], candidate.cameFrom,
                                     colliders[candidate.collider].end.pose,
                                     triangles[candidate.triangle].vertices, inverseMasses,
                                     kSettledDepth, x, {}, 0, pushed);
        moved = moved || deep > 0;
        if (pushed && !candidate.pushed) ++report.contacts;
        candidate.pushed = candidate.pushed || pushed;
      }
      if (!moved) break;
    }
  };
  sweepOut();
  // Once the positions have settled: each touching face point is held one-sided in the strain
  // limiter (it slides the cloth round the body instead of pulling the face back in), and keeps
  // no velocity into the body (inelastic, relative to the body's surface there). Removed in
  // every sweep instead, the pushes of the successive contacts of one face added up and the face
  // left faster than the body (a rod rising at 1.8 m/s into a face sent its corners off at up to
  // 2.5 m/s).
  for (const Candidate& candidate : m_candidates) {
    const std::array<Index, 3>& corner = triangles[candidate.triangle].vertices;
    const RigidMotion& body = colliders[candidate.collider].end;
    std::array<Vec3, 3> local;
    cornersInBody(candidate, local);
    // A face the sweeps pushed keeps the body's pace even where the push carried it past the
    // reach; the others count where they touch.
    const Real minDepth = candidate.pushed ? -std::numeric_limits<Real>::infinity() : -kTouching;
    const int count = facePoints(m_cores[candidate.core], candidate.cameFrom, local[0], local[1],
                                 local[2], minDepth, points);
    for (int p = 0; p < count; ++p) {
      const FacePoint& point = points[p];
      const Vec3& b = point.barycentric;
      const Vec3 normal = body.pose.directionToWorld(point.normal);
      const Vec3 corePoint = body.pose.toWorld(point.corePoint);
      SeparationHold hold;
      hold.vertices = {corner[0], corner[1], corner[2], corner[0]};
      hold.weights = {b[0], b[1], b[2], 0};
      hold.normal = normal;
      hold.separation = normal.dot(corePoint) + m_cores[candidate.core].reach;
      m_holds.push_back(hold);
      const Real weight = pointInverseMass(b, corner, inverseMasses);
      if (!(weight > 0)) continue;
      Vec3 facePoint = Vec3::Zero(), faceVelocity = Vec3::Zero();
      for (int j = 0; j < 3; ++j) {
        facePoint += b[j] * x[corner[j]];
        faceVelocity += b[j] * v[corner[j]];
      }
      const Real approach =
          std::min<Real>(0, (faceVelocity - body.velocityAt(facePoint)).dot(normal));
      if (approach < 0) moveFacePoint(b, corner, inverseMasses, weight, -approach, normal, v);
      if (!friction || !candidate.startedOn) continue;
      for (int j = 0; j < 3; ++j) {
        const Index i = corner[j];
        if (!(b[j] > 0) || inverseMasses[i] == 0) continue;
        if (m_cornerSlot[i] == kInvalidIndex) {
          // A corner resting on the body itself is a vertex contact: the vertex pass took its
          // friction, bounded by its own constraint's impulse.
          if (queryPoint(*colliders[candidate.collider].shape, x[i]).distance <
              (1 + kStartedOnShell) * allowance) {
            continue;
          }
          // Its solve impulse is the face constraint's (Cloth::constrainFaceCorners).
          const Real solvePart = solveImpulses.empty() ? 0 : std::max<Real>(0, solveImpulses[i]);
          m_cornerSlot[i] = Index(m_frictionCorners.size());
          m_frictionCorners.push_back({i, normal, body.velocityAt(x[i]),
                                       colliders[candidate.collider].friction, solvePart});
        }
        // The corner's share of the push just made (moveFacePoint's).
        m_frictionCorners[m_cornerSlot[i]].normalChange -=
            b[j] * inverseMasses[i] / weight * approach;
      }
    }
  }
  for (const FrictionCorner& contact : m_frictionCorners) {
    const Index i = contact.vertex;
    m_cornerSlot[i] = kInvalidIndex;
    const Vec3 relative = v[i] - contact.bodyVelocity;
    const Vec3 tangential = relative - relative.dot(contact.normal) * contact.normal;
    const Vec3 change =
        coulombFriction(tangential, contact.normalChange, contact.friction) - tangential;
    v[i] += change;
    x[i] += positionStep * change;
  }
  // Friction's shift is along each corner's own tangent, which can tilt a face into the reach on
  // a curved body (4.1 mm into the test's rod without this): the faces are put back out.
  if (positionStep > 0 && !m_frictionCorners.empty()) sweepOut();
  m_frictionCorners.clear();
  return report;
}

Index ColliderFaceContacts::project(std::span<const ColliderFrame> colliders,
                                    std::span<const TriangleRest> triangles,
                                    std::span<const Real> inverseMasses, Real inverseStep,
                                    Real tolerance, std::span<Vec3> x, std::span<Vec3> v) const {
  Index violated = 0;
  for (const Candidate& candidate : m_candidates) {
    bool pushed = false;
    violated += pushFaceOut(m_cores[candidate.core], candidate.cameFrom,
                            colliders[candidate.collider].end.pose,
                            triangles[candidate.triangle].vertices, inverseMasses, tolerance, x,
                            v, inverseStep, pushed);
  }
  return violated;
}

}  // namespace weft
