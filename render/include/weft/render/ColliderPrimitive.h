// Simple shapes the renderer draws next to the cloth: what colliders look like, not what they
// are (the collision module owns the real shapes). Each carries its own colour.
#pragma once

#include <weft/Math.h>
#include <weft/render/RenderSettings.h>

#include <variant>

namespace weft {

/// Default colour of collider primitives: a neutral grey that reads apart from the cloth.
inline constexpr ColorRgb kColliderColor{0.62f, 0.63f, 0.62f};

/// A sphere.
struct SpherePrimitive {
  Vec3 center{0.0, 0.0, 0.0};  ///< m
  Real radius = 0.25;          ///< m
  ColorRgb color = kColliderColor;  ///< surface colour
};

/// An infinite plane, drawn as a finite square patch centred at point.
struct PlanePrimitive {
  Vec3 point{0.0, 0.0, 0.0};   ///< m, a point on the plane; the patch is centred here
  Vec3 normal{0.0, 1.0, 0.0};  ///< the side that faces the cloth; need not be unit length
  Real halfSize = 3.0;         ///< m, half the side of the drawn square
  ColorRgb color{0.74f, 0.74f, 0.72f};  ///< surface colour
};

/// A capsule: all points within radius of the segment a–b.
struct CapsulePrimitive {
  Vec3 a{0.0, 0.0, 0.0};  ///< m, one end of the axis
  Vec3 b{0.0, 1.0, 0.0};  ///< m, the other end
  Real radius = 0.1;      ///< m
  ColorRgb color = kColliderColor;  ///< surface colour
};

/// An oriented box.
struct BoxPrimitive {
  Vec3 center{0.0, 0.0, 0.0};          ///< m
  Vec3 halfExtents{0.5, 0.5, 0.5};     ///< m, half the side along each local axis
  Mat3 rotation = Mat3::Identity();    ///< local → world rotation (orthonormal columns)
  ColorRgb color = kColliderColor;     ///< surface colour
};

/// Any drawable collider shape.
using ColliderPrimitive = std::variant<SpherePrimitive, PlanePrimitive, CapsulePrimitive, BoxPrimitive>;

}  // namespace weft
