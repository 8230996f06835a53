#include "ColliderProjection.h"

#include <weft/collision/Shape.h>

namespace weft {
namespace {

// A constraint violated by less than this fraction of the thickness counts as satisfied: the
// collider passes after the limiter remove such a remainder at a negligible cost in strain.
constexpr Real kViolationPerThickness = 0.01;

}  // namespace

void ColliderProjection::prepare(std::span<const ColliderFrame> colliders,
                                 const ColliderFaceContacts* faces,
                                 std::span<const ColliderFrame> faceColliders,
                                 std::span<const TriangleRest> triangles,
                                 std::span<const Real> inverseMasses, Real thickness, Real margin,
                                 std::span<const Vec3> x) {
  m_colliders = colliders;
  m_faces = faces;
  m_faceColliders = faceColliders;
  m_triangles = triangles;
  m_inverseMasses = inverseMasses;
  m_thickness = thickness;
  m_vertexContacts.clear();
  const Real reach = thickness + margin;
  m_boxes.clear();
  for (const ColliderFrame& collider : colliders) {
    m_boxes.push_back(bounds(*collider.shape));
    m_boxes.back().inflate(reach);
  }
  for (Index i = 0; i < Index(x.size()); ++i) {
    if (inverseMasses[i] == 0) continue;
    for (Index k = 0; k < Index(colliders.size()); ++k) {
      if (!m_boxes[k].contains(x[i])) continue;
      if (queryPoint(*colliders[k].shape, x[i]).distance < reach) {
        m_vertexContacts.push_back(VertexContact{i, k, x[i]});
      }
    }
  }
}

Index ColliderProjection::project(std::span<Vec3> x, std::span<Vec3> v, Real inverseStep) {
  const Real tolerance = kViolationPerThickness * m_thickness;
  Index violated = 0;
  if (m_faces) {
    violated += m_faces->project(m_faceColliders, m_triangles, m_inverseMasses, inverseStep,
                                 tolerance, x, v);
  }
  for (VertexContact& contact : m_vertexContacts) {
    // The path from where this vertex was last seen outside, against the body held still: an
    // edge or a face pulled it there, and pulled far enough it may have crossed a thin body
    // (a 2 cm capsule), where the nearest surface is on the far side.
    ColliderFrame still = m_colliders[contact.collider];
    still.start = still.end;
    const Vec3 outside = keepOutside(still, contact.lastOutside, x[contact.vertex], m_thickness);
    const Vec3 shift = outside - x[contact.vertex];
    contact.lastOutside = outside;
    if (shift.isZero()) continue;
    x[contact.vertex] = outside;
    v[contact.vertex] += inverseStep * shift;
    violated += shift.norm() > tolerance;
  }
  return violated;
}

}  // namespace weft
