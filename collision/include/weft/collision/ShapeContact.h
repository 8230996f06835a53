// ShapeContact: what a collider says about a point near it.
#pragma once

#include <weft/Math.h>

namespace weft {

/// Signed distance, closest surface point, outward normal and surface velocity for one query
/// point. The query point equals point + distance · normal (up to rounding) whenever the
/// closest point is unique.
struct ShapeContact {
  Real distance = 0;              ///< m, signed: > 0 outside, < 0 inside (−penetration depth)
  Vec3 normal = Vec3::UnitY();    ///< unit outward surface normal at `point`
  Vec3 point = Vec3::Zero();      ///< m, closest point on the surface
  Vec3 velocity = Vec3::Zero();   ///< m/s, velocity of the surface at `point` (kinematic motion)
};

}  // namespace weft
