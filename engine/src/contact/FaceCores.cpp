#include "contact/FaceCores.h"

#include <weft/collision/Proximity.h>

#include <algorithm>
#include <limits>
#include <variant>

namespace weft {
namespace {

// A face whose normal leans less than this (the cosine of its angle to the plane across a line
// core) is pushed along its own normal: one nearly across the core, which pierces it.
constexpr Real kLeastAcross = 0.5;

// The start's core-to-face normal decides the side of a core over the face's interior when it
// leans at least this far out of the face's plane (sine of the angle, 30°); nearer the plane its
// component along the face's normal is a rounding's sign, not a side.
constexpr Real kLeastStartLean = 0.5;

// A mesh edge is a core of reach kMeshEdgeReach · allowance where a face could reach it between
// its corners: where the surface round it bulges more than kMeshEdgeClearance · allowance into
// a face of the face's extent. Elsewhere a face whose corners keep the allowance stays twice the
// reach from the edge, so the vertex contacts may fall short by a quarter of it.
constexpr Real kMeshEdgeReach = 0.25;
constexpr Real kMeshEdgeClearance = 0.5;

}  // namespace

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
      // The side the face must end on (+1: above the core along up). The start's normal tells it
      // when it leans out of the face's plane (a face that crossed the core goes back); one
      // nearly in the plane (the face came from beside the core) does not, and each core point
      // then keeps the face on the side it is on now, as without a start.
      const Real startLean = cameFrom.isZero() ? 0 : cameFrom.dot(up) / cameFrom.norm();
      const Real startSide = std::abs(startLean) < kLeastStartLean ? 0 : (startLean > 0 ? 1 : -1);
      for (int k = 0; k < (line ? 2 : 1); ++k) {
        const Vec3 corePoint = core.start + ends[k] * segment;
        const Real height = up.dot(corePoint - a);  // of the core point over the face's plane
        Real side = startSide;
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

Real pushFaceOut(const FaceCore& core, const Vec3& cameFrom, const Pose& endPose,
                 const std::array<Index, 3>& corner, std::span<const Real> inverseMasses,
                 std::span<Vec3> x, std::span<Vec3> v, Real inverseStep, Vec3& normal) {
  std::array<FacePoint, 3> points;
  std::array<Vec3, 3> local;
  const auto toLocal = [&] {
    for (int j = 0; j < 3; ++j) local[j] = endPose.toLocal(x[corner[j]]);
  };
  const auto findPoints = [&] {
    return facePoints(core, cameFrom, local[0], local[1], local[2],
                      -std::numeric_limits<Real>::infinity(), points);
  };
  toLocal();
  if (faceClearOfCore(core, cameFrom, local[0], local[1], local[2])) return 0;
  Real deepest = 0;
  int count = findPoints();
  for (int p = 0; p < count; ++p) {
    const FacePoint& point = points[p];
    if (!(point.depth > 0)) continue;
    const Vec3& b = point.barycentric;
    const Real weight = pointInverseMass(b, corner, inverseMasses);
    if (!(weight > 0)) continue;
    const Vec3 direction = endPose.directionToWorld(point.normal);
    for (int j = 0; j < 3; ++j) {
      const Vec3 shift = (b[j] * inverseMasses[corner[j]] / weight * point.depth) * direction;
      x[corner[j]] += shift;
      v[corner[j]] += inverseStep * shift;
    }
    if (point.depth > deepest) {
      deepest = point.depth;
      normal = direction;
    }
    if (p + 1 < count) {
      toLocal();
      count = findPoints();
    }
  }
  return deepest;
}

namespace {

// `distance` with a part per billion to spare: a lower bound that beats it by this is beyond the
// rounding of the exact tests.
Real withRoundingSlack(Real distance) { return distance * (1 + 1e-9) + 1e-12; }

// Whether the boxes of face (a, b, c) and of the core are more than `distance` apart along an
// axis, which bounds the distance between them from below.
bool boxesApart(const FaceCore& core, const Vec3& a, const Vec3& b, const Vec3& c, Real distance) {
  Aabb face = Aabb::fromCorners(a, b);
  face.expand(c);
  Aabb segment = Aabb::fromCorners(core.start, core.end);
  segment.inflate(distance);
  return !face.overlaps(segment);
}

// How far every corner of face (a, b, c) lies beyond both core ends along the unit vector
// `along` (negative: not all of it does).
Real gapAlong(const Vec3& along, const FaceCore& core, const Vec3& a, const Vec3& b,
              const Vec3& c) {
  return std::min({along.dot(a), along.dot(b), along.dot(c)}) -
         std::max(along.dot(core.start), along.dot(core.end));
}

}  // namespace

bool faceFartherThan(const FaceCore& core, const Vec3& direction, const Vec3& a, const Vec3& b,
                     const Vec3& c, Real distance) {
  // The gap between the boxes along an axis, and the gap along `direction` on either side, each
  // bound the distance from below.
  const Real apart = withRoundingSlack(distance);
  if (boxesApart(core, a, b, c, apart)) return true;
  if (direction.isZero()) return false;
  const Vec3 along = direction.normalized();
  return gapAlong(along, core, a, b, c) > apart || gapAlong(-along, core, a, b, c) > apart;
}

bool faceClearOfCore(const FaceCore& core, const Vec3& cameFrom, const Vec3& a, const Vec3& b,
                     const Vec3& c) {
  const Real clear = withRoundingSlack(core.reach);
  if (!cameFrom.isZero()) {
    // facePoints sends a face back to the side it came from, however far it crossed: only a gap
    // along that side's direction, between every corner and both core ends, proves it clear.
    // Each face and core point is then farther apart than that along it, and on that side.
    return gapAlong(cameFrom.normalized(), core, a, b, c) > clear;
  }
  // No side: the gap between the boxes along an axis, or the distance of the segment from the
  // face's plane with both its ends on one side, bounds the distance from below.
  if (boxesApart(core, a, b, c, clear)) return true;
  const Vec3 plane = (b - a).cross(c - a);
  const Real twiceArea = plane.norm();
  if (!(twiceArea > 0)) return false;
  const Real start = plane.dot(core.start - a) / twiceArea;
  const Real end = plane.dot(core.end - a) / twiceArea;
  return (start > clear && end > clear) || (start < -clear && end < -clear);
}

void appendMeshCores(const TriangleMeshShape& mesh, const Aabb& near, Real allowance, Real span,
                     std::vector<FaceCore>& cores, std::vector<Index>& triangleScratch,
                     std::vector<Index>& edgeScratch) {
  // The edges and vertices that bulge into the face, each once (most of a smooth mesh's none,
  // and where nothing in the mesh bulges that far, no search of its tree).
  const Real clearance = kMeshEdgeClearance * allowance;
  if (!(mesh.maxBulge(span) > clearance)) return;
  mesh.localBvh().queryBox(near, triangleScratch);
  edgeScratch.clear();
  for (Index meshTriangle : triangleScratch) {
    for (Index edge : mesh.triangleEdges(meshTriangle)) {
      if (mesh.edges()[edge].bulge(span) > clearance) edgeScratch.push_back(edge);
    }
  }
  const std::size_t edgeCount = edgeScratch.size();
  for (Index meshTriangle : triangleScratch) {
    for (int k = 0; k < 3; ++k) {
      const Index v = mesh.indices()[3 * meshTriangle + k];
      if (mesh.vertexSlope(v) * span / 2 > clearance) edgeScratch.push_back(v);
    }
  }
  const auto edgesEnd = edgeScratch.begin() + std::ptrdiff_t(edgeCount);
  std::sort(edgeScratch.begin(), edgesEnd);
  std::sort(edgesEnd, edgeScratch.end());
  const Real reach = kMeshEdgeReach * allowance;
  const std::vector<Vec3>& x = mesh.localVertices();
  for (auto e = edgeScratch.begin(); e != edgesEnd; ++e) {
    if (e != edgeScratch.begin() && *e == *(e - 1)) continue;
    const MeshEdge& edge = mesh.edges()[*e];
    cores.push_back(makeCore(x[edge.a], x[edge.b], reach));
  }
  for (auto v = edgesEnd; v != edgeScratch.end(); ++v) {
    if (v != edgesEnd && *v == *(v - 1)) continue;
    cores.push_back(makeCore(x[*v], x[*v], reach));  // a vertex that peaks, as a point
  }
}

}  // namespace weft
