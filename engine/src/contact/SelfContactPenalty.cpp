#include "contact/SelfContactPenalty.h"

#include <weft/collision/Proximity.h>

namespace weft {
namespace {

// m, relative to reach: points closer than this coincide, and the detected normal orients them.
constexpr Real kCoincident = 1e-9;

}  // namespace

std::optional<SelfContactPair> selfContactAt(const SelfContactFeatures& features,
                                             std::span<const Vec3> x, Real reach) {
  const std::array<Index, 4>& v = features.vertices;
  SelfContactPair pair;
  pair.kind = features.kind;
  pair.vertices = v;
  Vec3 between = Vec3::Zero();
  Real distance = 0;
  Vec3 planeNormal = Vec3::Zero();
  if (features.kind == ContactKind::VertexFace) {
    const TriangleClosestPoint closest = closestPointOnTriangle(x[v[0]], x[v[1]], x[v[2]], x[v[3]]);
    pair.weights = {1, -closest.barycentric[0], -closest.barycentric[1], -closest.barycentric[2]};
    between = x[v[0]] - closest.point;
    distance = closest.distance;
    planeNormal = (x[v[2]] - x[v[1]]).cross(x[v[3]] - x[v[1]]);
  } else if (features.kind == ContactKind::EdgeEdge) {
    const SegmentClosestPoints closest = closestPointsOnSegments(x[v[0]], x[v[1]], x[v[2]], x[v[3]]);
    const Real s = closest.firstParameter, u = closest.secondParameter;
    pair.weights = {1 - s, s, -(1 - u), -u};
    between = closest.pointOnFirst - closest.pointOnSecond;
    distance = closest.distance;
    planeNormal = (x[v[1]] - x[v[0]]).cross(x[v[3]] - x[v[2]]);
  } else {
    return std::nullopt;
  }
  if (!(distance < reach)) return std::nullopt;
  if (distance > kCoincident * reach) {
    pair.normal = between / distance;
  } else {
    // The sides touch: the plane of the features, on the side the pair was detected on.
    if (planeNormal.norm() == 0) return std::nullopt;
    pair.normal = planeNormal.normalized();
    if (pair.normal.dot(features.normal) < 0) pair.normal = -pair.normal;
  }
  pair.gap = pair.normal.dot(between);
  return pair;
}

}  // namespace weft
