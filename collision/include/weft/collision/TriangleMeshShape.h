// TriangleMeshShape: a static or kinematic collider made of triangles (a character, furniture).
//
// Design note
// -----------
// The mesh is stored in its body frame with an AABB tree over it (built once: the mesh is rigid,
// so the tree never needs a refit). queryPoint() moves the query point into the body frame, finds
// the closest triangle by a best-first descent of the tree (nearer child first, subtrees farther
// than the best distance so far pruned), and signs the distance with the angle-weighted
// pseudo-normal of the closest feature (Bærentzen & Aanæs 2005, "Signed distance computation
// using the angle weighted pseudonormal"): the face normal inside a face, the sum of the two face
// normals on an edge, the angle-weighted vertex normal at a vertex. For a closed, consistently
// wound (counter-clockwise seen from outside) mesh this sign is exact: negative exactly inside.
// Rejected: ray-parity inside tests (need a watertight mesh and break on rays through edges),
// the face normal of the closest triangle alone (wrong sign near convex edges and vertices).
//
// Open meshes (a ground sheet, a cloak's collar) have no inside; the sign then says which side
// of the surface the point lies on, at any distance, so a caller should only act on points near
// the surface. For the cloth–mesh broad phase, build a Bvh over worldVertices() and indices()
// and refit it every frame with the previous and current world vertices.
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/collision/Aabb.h>
#include <weft/collision/Bvh.h>
#include <weft/collision/RigidMotion.h>
#include <weft/collision/ShapeContact.h>

#include <memory>
#include <span>
#include <vector>

namespace weft {

/// A rigid triangle mesh collider (vertices in the body frame, moved by a kinematic pose).
class TriangleMeshShape {
 public:
  /// A mesh of `localVertices` (body frame, m) and `indices` (three per triangle, wound
  /// counter-clockwise seen from outside). Errors: no triangles, index count not a multiple of
  /// three, index out of range, repeated index in a triangle, non-finite vertex, zero-area
  /// triangle, invalid motion.
  static Result<TriangleMeshShape> create(std::span<const Vec3> localVertices,
                                          std::span<const Index> indices,
                                          const RigidMotion& motion = {});

  /// m, vertices in the body frame.
  const std::vector<Vec3>& localVertices() const { return m_geometry->vertices; }
  /// Three vertex indices per triangle.
  const std::vector<Index>& indices() const { return m_geometry->indices; }
  /// Number of triangles.
  Index triangleCount() const { return static_cast<Index>(m_geometry->indices.size() / 3); }
  /// The tree over the body-frame triangles (zero thickness).
  const Bvh& localBvh() const { return m_geometry->bvh; }
  /// Writes the vertices at the current pose into `vertices` (size localVertices().size()).
  void worldVertices(std::span<Vec3> vertices) const;

  /// Current pose and velocities.
  const RigidMotion& motion() const { return m_motion; }
  /// Moves the mesh (validated like create()); unchanged on error.
  Status setMotion(const RigidMotion& motion);
  /// Signed distance (pseudo-normal sign, see the design note), closest point, outward normal
  /// and surface velocity for a world point.
  ShapeContact queryPoint(const Vec3& point) const;
  /// World box (the rotated body-frame box: conservative).
  Aabb bounds() const;

 private:
  TriangleMeshShape() = default;  // create() builds every shape: none exists without geometry
  // The body-frame geometry, immutable once built and shared by every copy of the shape: a copy
  // (a collider posed for one substep, a saved world) costs a reference count, not the mesh.
  struct Geometry {
    std::vector<Vec3> vertices;
    std::vector<Index> indices;
    Bvh bvh;
    std::vector<Vec3> faceNormals;    // per triangle, unit
    std::vector<Vec3> edgeNormals;    // per triangle corner k: edge (k, k+1), unit
    std::vector<Vec3> vertexNormals;  // per vertex, angle-weighted, unit
  };
  std::shared_ptr<const Geometry> m_geometry;
  RigidMotion m_motion;
};

}  // namespace weft
