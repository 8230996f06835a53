// TriangleMeshShape: a static or kinematic collider made of triangles (a character, furniture).
//
// Design note
// -----------
// The mesh is stored in its body frame with an AABB tree over it (built once with small leaves:
// the mesh is rigid, so the tree never needs a refit). queryPoint() moves the query point into
// the body frame and finds the closest triangle by a best-first descent of the tree (nearer
// child first, subtrees and triangles farther than the best distance so far pruned: a triangle
// by the distance to its plane, a lower bound, before the exact point–triangle walk).
//
// Closed meshes (every edge shared by exactly two triangles) sign the distance with the
// angle-weighted pseudo-normal of the closest feature (Bærentzen & Aanæs 2005, "Signed distance
// computation using the angle weighted pseudonormal"): the face normal inside a face, the sum of
// the two face normals on an edge, the angle-weighted vertex normal at a vertex. For a closed,
// consistently wound (counter-clockwise seen from outside) mesh this sign is exact: negative
// exactly inside. Rejected: ray-parity inside tests (need a watertight mesh and break on rays
// through edges), the face normal of the closest triangle alone (wrong sign near convex edges
// and vertices).
//
// Open meshes (a table top of one quad, a flag, a leaf) have no inside: the pseudo-normal's side
// reaches to infinity, and a point anywhere below a one-quad table top would be "inside" and be
// pushed through to the top. An open mesh is therefore a two-sided shell: the distance is
// unsigned and the normal points from the closest surface point to the query point, so a cloth
// is kept at its thickness on whichever side it is. A path that crosses the shell within a step
// is caught by the continuous tests of the caller (sphere tracing on the unsigned distance meets
// the surface before it can pass it).
//
// Edges (edges()) carry how far the surface round them can bulge into a flat face that spans
// them, from the turn of the surface there and the width of the triangles beside it: a face whose
// corners keep a distance d from the surface keeps d − bulge(span) from the edge. A ridge turning
// by φ rises (span / 2)·tan(φ / 2) into a face over it; turns spread over narrow triangles add up
// as a curved surface's sag, span² · curvature / 4 (span²/(8R) for radius R). Vertices count
// apart: a cone's tip, whose edges each turn little, rises (span / 2)·vertexSlope(v) into a face
// over it. Cloth face contacts use both to skip the edges and vertices of smooth regions, which a
// face cannot reach between its corners.
//
// For the cloth–mesh broad phase, build a Bvh over worldVertices() and indices() and refit it
// every frame with the previous and current world vertices.
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/collision/Aabb.h>
#include <weft/collision/Bvh.h>
#include <weft/collision/RigidMotion.h>
#include <weft/collision/ShapeContact.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace weft {

/// An edge of a TriangleMeshShape (vertices a < b) and the shape of the surface at it.
struct MeshEdge {
  Index a = 0;  ///< the lower vertex index
  Index b = 0;  ///< the higher vertex index
  /// tan of half the surface's turn at the edge (the angle between its face normals; convex
  /// turns only on a closed mesh). Infinite on a border or a fin (not two triangles).
  Real ridgeSlope = 0;
  /// 1/m, ridgeSlope per width of the triangles beside the edge: the curvature it stands for.
  Real curvature = 0;

  /// m, the most a flat face of extent `span` (m) over the edge comes nearer the edge than its
  /// corners keep from the surface (see the design note).
  Real bulge(Real span) const {
    return std::max(ridgeSlope * span / 2, curvature * span * span / 4);
  }
};

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
  /// Every edge once, sorted by (a, b).
  const std::vector<MeshEdge>& edges() const { return m_geometry->edges; }
  /// The steepest of vertex v's faces against its normal, as a slope (tan of the angle; infinite
  /// from a right angle): how sharply the surface peaks at v (see the design note).
  Real vertexSlope(Index v) const { return m_geometry->vertexSlopes[v]; }
  /// m, the most any edge or vertex of the mesh bulges into a flat face of extent `span` (m): at
  /// least every MeshEdge::bulge(span) and (span / 2)·vertexSlope(v). A face that nothing bulges
  /// into by more than a clearance needs no edge of the mesh tested (a smooth mesh's faces).
  Real maxBulge(Real span) const {
    const Geometry& g = *m_geometry;
    return std::max({g.maxRidgeSlope * span / 2, g.maxCurvature * span * span / 4,
                     g.maxVertexSlope * span / 2});
  }
  /// Indices into edges() of triangle t's edges: corner k's edge runs from corner k to k + 1.
  std::span<const Index, 3> triangleEdges(Index t) const {
    return std::span<const Index, 3>(m_geometry->triangleEdges.data() + 3 * std::size_t(t), 3);
  }
  /// The tree over the body-frame triangles (zero thickness).
  const Bvh& localBvh() const { return m_geometry->bvh; }
  /// Writes the vertices at the current pose into `vertices` (size localVertices().size()).
  void worldVertices(std::span<Vec3> vertices) const;

  /// Current pose and velocities.
  const RigidMotion& motion() const { return m_motion; }
  /// Moves the mesh (validated like create()); unchanged on error.
  Status setMotion(const RigidMotion& motion);
  /// True when every edge belongs to exactly two triangles (decided at create()): the mesh
  /// bounds a volume and queryPoint() signs its distance. False: an open, two-sided shell whose
  /// distance is unsigned (see the design note).
  bool isClosed() const { return m_geometry->closed; }
  /// Distance, closest point, normal and surface velocity for a world point. Closed mesh: signed
  /// distance (pseudo-normal sign, negative inside) and outward normal. Open mesh: unsigned
  /// distance and the normal from the closest point towards `point` (the face normal for a point
  /// on the surface).
  ShapeContact queryPoint(const Vec3& point) const;
  /// queryPoint() for a point nearer the surface than `maxDistance` (m, on either side); none
  /// for a point at least that far from it. The search prunes everything beyond maxDistance, so
  /// a point far from the mesh costs a few box tests.
  std::optional<ShapeContact> queryPointWithin(const Vec3& point, Real maxDistance) const;
  /// queryPoint() for a point whose signed distance is below `maxDistance` (m): inside a closed
  /// mesh or nearer than that; none for a point at least that far outside. The search prunes
  /// beyond maxDistance and goes further only for a point inside a closed mesh's box.
  std::optional<ShapeContact> queryPointBelow(const Vec3& point, Real maxDistance) const;
  /// The parameter s ∈ [0, 1] of the first point where the world segment start → end meets a
  /// triangle (the mesh at its current pose); none when it misses them all. For an open mesh,
  /// whose unsigned distance cannot show that a path went through it.
  std::optional<Real> firstCrossing(const Vec3& start, const Vec3& end) const;
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
    std::vector<Vec3> corners;        // per triangle, its three vertices
    std::vector<MeshEdge> edges;      // each edge once, sorted
    std::vector<Index> triangleEdges; // per triangle corner k: its edge (k, k+1) in edges
    std::vector<Real> vertexSlopes;   // per vertex, vertexSlope()
    Real maxRidgeSlope = 0;           // the largest of the edges' ridgeSlope, curvature and the
    Real maxCurvature = 0;            // vertices' slopes: maxBulge()
    Real maxVertexSlope = 0;
    bool closed = false;              // every edge has exactly two triangles
  };
  std::shared_ptr<const Geometry> m_geometry;
  RigidMotion m_motion;

  // The turn of the surface at `edge` (positive convex; infinite unless two triangles share it)
  // and the smaller height of its triangles over it; `slots` are its (key, triangle corner) slots.
  static std::pair<Real, Real> edgeTurnAndWidth(
      const Geometry& geometry, const MeshEdge& edge,
      std::span<const std::pair<std::uint64_t, Index>> slots);
  // Sets every edge's ridgeSlope and curvature (MeshEdge) from the edges' turns and widths.
  static void setEdgeShapes(Geometry& geometry, std::span<const std::pair<Real, Real>> turnAndWidth);
  // The triangle closest to a body-frame point (the first found among equally close ones), or
  // kInvalidIndex when none is nearer than sqrt(maxSquared).
  Index closestTriangle(const Vec3& local, Real maxSquared) const;
  // The contact of a body-frame point whose closest triangle is `triangle`.
  ShapeContact contactWith(const Vec3& local, Index triangle) const;
};

}  // namespace weft
