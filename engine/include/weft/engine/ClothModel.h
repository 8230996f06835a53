// ClothModel: the immutable topology and rest state of one piece of cloth.
//
// Built once (from a rectangular grid, a triangle mesh or an OBJ file) and shared by every cloth
// instance made from it, in the manner of Jolt's SoftBodySharedSettings. It holds only what does
// not depend on the material: rest parameterisation per triangle, bending hinges, springs for the
// mass-spring model and lumped vertex areas. Materials (stiffness, density, damping) are applied
// per instance, so one model serves cotton and denim alike.
//
// Rest parameterisation (Baraff & Witkin 1998, §4.1): every triangle carries material
// coordinates (u, v) for its vertices, in metres; u runs along the warp, v along the weft. The
// deformation map w(u, v) has the constant gradient per triangle
//
//     [w_u  w_v] = [x1 - x0   x2 - x0] · [u1 - u0   u2 - u0]^-1
//                                         [v1 - v0   v2 - v0]
//
// so w_u and w_v are fixed linear combinations of the three positions. TriangleRest stores the
// weights of those combinations; the force kernels never see (u, v) again.
//
// Bending data for both bending models: BendingStencils per vertex for the isometric (quadratic)
// energy, the default, and Hinges per interior edge for the dihedral one.
//
// Hinge convention (one per interior edge, for dihedral bending):
//
//            x2
//           /  \          triangle A = (x0, x1, x2), with the edge x0 -> x1 in its winding
//          /  A \         triangle B holds the same edge and the vertex x3
//        x0 ---- x1       the dihedral angle is measured about e = x1 - x0, 0 when flat
//          \  B /
//           \  /
//            x3
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/engine/InputLimits.h>

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace weft {

/// Rest state of one triangle for the Baraff–Witkin stretch and shear conditions.
struct TriangleRest {
  std::array<Index, 3> vertices{};  ///< x0, x1, x2 in the mesh's winding
  Real area = 0;                    ///< m², rest area in material space
  std::array<Real, 3> warpWeights{};  ///< 1/m; w_u = Σ warpWeights[i] · x_i
  std::array<Real, 3> weftWeights{};  ///< 1/m; w_v = Σ weftWeights[i] · x_i
};

/// Rest state of one interior edge for the dihedral bending condition (see the drawing above).
struct Hinge {
  std::array<Index, 4> vertices{};  ///< x0, x1 (the edge), x2 (in triangle A), x3 (in triangle B)
  std::array<Index, 2> triangles{}; ///< A and B, indices into ClothModel::triangles()
  Real restAngle = 0;               ///< rad, dihedral angle of the rest shape (0 for flat cloth)
  Real restLength = 0;              ///< m, rest length of the edge
  /// 1/m⁰ (dimensionless): 3 l² / (A_A + A_B). Bending energy = D/2 · scale · (θ − θ_rest)², so a
  /// bending stiffness D in N·m gives the same curvature energy on any mesh resolution.
  Real stiffnessScale = 0;
};

/// One weight of an isometric-bending stencil (forces/IsometricBending.h).
struct StencilWeight {
  Index vertex = 0;  ///< the vertex the weight multiplies
  Real weight = 0;   ///< dimensionless; a stencil's weights sum to zero
};

/// One term of the isometric bending energy D/2 · energyWeight · |S(x) − α n_v(x)|², where
/// S(x) = Σ weight · x over its StencilWeights is A_v times one entry of the surface Hessian of
/// the deformation at vertex v (forces/IsometricBending.h explains the choice). Three per vertex.
struct BendingStencil {
  Index vertex = 0;         ///< the centre vertex v
  Index firstWeight = 0;    ///< its weights: ClothModel::bendingWeights()[firstWeight, + weightCount)
  Index weightCount = 0;    ///< the centre first, then the neighbours in ascending index
  Real energyWeight = 0;    ///< 1/m², 1/A_v for H_uu and H_vv, 2/A_v for H_uv (A_v: vertex area)
  /// m, α_v: the rest value of S_v along the rest vertex normal; 0 for a flat rest shape.
  Real restCurvature = 0;
  Index firstTriangle = 0;  ///< incident triangles (curved rest only): bendingTriangles()[first, +count)
  Index triangleCount = 0;  ///< 0 when restCurvature is 0 (the normal is not needed)
};

/// The three spring families of the classic mass-spring cloth (Provot 1995).
enum class SpringKind : std::uint8_t {
  Structural,  ///< along warp and weft (grid) or along mesh edges
  Shear,       ///< grid diagonals, or the quad diagonal across an interior edge
  Flexion,     ///< skip-one neighbours along straight lines: resist bending
};

/// One spring of the mass-spring network.
struct Spring {
  std::array<Index, 2> vertices{};  ///< the two vertices it joins
  Real restLength = 0;  ///< m
  SpringKind kind = SpringKind::Structural;  ///< which family (and so which stiffness) it has
};

/// An undirected mesh edge and the triangles on either side.
struct Edge {
  std::array<Index, 2> vertices{};     ///< smaller index first
  std::array<Index, 2> triangles{kInvalidIndex, kInvalidIndex};  ///< second is invalid on a border
  Real restLength = 0;                 ///< m
};

/// A rectangular grid of vertices, each quad split in two along its (r, c)–(r+1, c+1) diagonal.
/// Vertex index = row · columns + column; row 0 lies at `origin`, rows grow along `heightAxis`.
struct GridSettings {
  Index columns = 41;               ///< vertices along the width (warp); at least 2
  Index rows = 31;                  ///< vertices along the height (weft); at least 2
  Real width = 2.0;                 ///< m, extent along widthAxis
  Real height = 1.5;                ///< m, extent along heightAxis
  Vec3 origin{-1.0, 0.5, 0.0};      ///< m, position of vertex (row 0, column 0)
  Vec3 widthAxis{1.0, 0.0, 0.0};    ///< unit direction of growing columns (the warp)
  Vec3 heightAxis{0.0, 1.0, 0.0};   ///< unit direction of growing rows (the weft)
};

/// A triangle mesh as read from a file or handed over by a game.
struct TriangleMesh {
  Vec3Array positions;           ///< m, rest positions
  std::vector<Index> indices;    ///< three per triangle
  /// Optional per-vertex material coordinates (u = warp, v = weft) in metres. Empty: each
  /// triangle is flattened isometrically, with u along `warpDirection` projected into its plane.
  std::vector<Vec2> materialCoordinates;
};

/// How a mesh becomes a cloth model.
struct MeshSettings {
  Vec3 warpDirection{1.0, 0.0, 0.0};  ///< direction of the warp (u) when no material coordinates
  /// Reject edges shared by more than two triangles and bowtie vertices (two fans of triangles
  /// meeting at one vertex): bending needs a manifold. False: such edges get no hinge and such
  /// vertices no isometric bending stencil.
  bool requireManifold = true;
  /// A triangle whose area is below this fraction of its longest edge squared is degenerate.
  Real degenerateAreaRatio = 1e-8;
  /// Merge vertices closer than weldTolerance (exporters write a vertex once per UV island).
  /// False keeps the copies: a cut along each seam, its two borders in contact. Default true.
  bool weldVertices = true;
  /// Fraction of the mesh's bounding-box diagonal within which vertices are welded; default
  /// 1e-6 (1 µm on a 1 m cloth, above the rounding of six written decimals).
  Real weldTolerance = 1e-6;
  /// Flip triangles so each connected piece winds like its lowest-numbered triangle (bending and
  /// normals need one orientation). False: inconsistent winding is an error. Default true.
  bool fixWinding = true;
};

/// What fromMesh() did to the mesh it was given (ClothModel::meshImport()).
struct MeshImport {
  Index weldedVertices = 0;    ///< input vertices merged into an earlier coincident one
  Index flippedTriangles = 0;  ///< triangles reversed to agree with their connected piece
  Index components = 0;        ///< connected pieces (triangles joined through shared edges)
  /// The model vertex of each input vertex; empty when the numbering is unchanged (no weld).
  std::vector<Index> modelVertexOfInput;
  /// The model vertex of input vertex `input` (of the mesh given to fromMesh()).
  Index modelVertex(Index input) const {
    return modelVertexOfInput.empty() ? input : modelVertexOfInput[input];
  }
};

/// Immutable cloth topology and rest state. Build with grid(), fromMesh() or loadObj().
class ClothModel {
 public:
  /// A rectangular grid with the classic structural/shear/flexion spring network.
  static Result<ClothModel> grid(const GridSettings& settings);
  /// A general triangle mesh: validated (indices, finite positions within kMaxCoordinate,
  /// degeneracy, manifoldness, memory), its coincident vertices welded and its winding made
  /// consistent (MeshSettings); meshImport() reports what changed. Errors name input vertices
  /// and triangles by their index in `mesh`.
  static Result<ClothModel> fromMesh(const TriangleMesh& mesh, const MeshSettings& settings = {});
  /// bytes, the largest OBJ file readObj() reads (a 4-million-vertex cloth with texture
  /// coordinates takes about 600 MB).
  static constexpr std::uint64_t kMaxObjFileBytes = 1ull << 30;
  /// Reads positions and triangles from a Wavefront OBJ file (see parseObj()). Refuses anything
  /// but a regular file of at most kMaxObjFileBytes, without reading it.
  static Result<TriangleMesh> readObj(const std::string& path);
  /// Parses Wavefront OBJ text held in memory: "v" and "f" statements (quads split along the
  /// shorter inside diagonal, larger polygons ear-clipped); errors name the line. `source` names
  /// the text in messages, e.g. "OBJ file 'cape.obj'".
  static Result<TriangleMesh> parseObj(std::string_view text, std::string_view source = "OBJ text");
  /// readObj() followed by fromMesh().
  static Result<ClothModel> loadObj(const std::string& path, const MeshSettings& settings = {});

  /// Number of vertices.
  Index vertexCount() const { return static_cast<Index>(m_restPositions.size()); }
  /// Number of triangles.
  Index triangleCount() const { return static_cast<Index>(m_triangles.size()); }

  /// m, the rest shape, one position per vertex.
  const Vec3Array& restPositions() const { return m_restPositions; }
  /// Three vertex indices per triangle, in the mesh's winding (for rendering and collision).
  const std::vector<Index>& indices() const { return m_indices; }
  /// Per triangle: vertices and rest quantities of the Baraff–Witkin stretch and shear terms.
  const std::vector<TriangleRest>& triangles() const { return m_triangles; }
  /// Interior edges with their two triangles: the dihedral bending hinges.
  const std::vector<Hinge>& hinges() const { return m_hinges; }
  /// Isometric bending terms, three per vertex (vertices next to non-manifold edges have none),
  /// in vertex order.
  const std::vector<BendingStencil>& bendingStencils() const { return m_bendingStencils; }
  /// The weights of all bending stencils (BendingStencil::firstWeight indexes them).
  const std::vector<StencilWeight>& bendingWeights() const { return m_bendingWeights; }
  /// Triangles whose normals the curved-rest stencils need (BendingStencil::firstTriangle).
  const std::vector<Index>& bendingTriangles() const { return m_bendingTriangles; }
  /// Every undirected mesh edge (strain, strain limiting, collision).
  const std::vector<Edge>& edges() const { return m_edges; }
  /// The mass-spring network (ForceModel::MassSpring).
  const std::vector<Spring>& springs() const { return m_springs; }
  /// m², a third of the rest area of every triangle around each vertex (lumped mass = ρ_A · area).
  const std::vector<Real>& vertexAreas() const { return m_vertexAreas; }
  /// m², total rest area.
  Real totalArea() const { return m_totalArea; }
  /// kg, total mass at an areal density in kg/m².
  Real totalMass(Real arealDensity) const { return arealDensity * m_totalArea; }
  /// kg per vertex at an areal density in kg/m² (lumped: a third of each adjacent triangle).
  std::vector<Real> vertexMasses(Real arealDensity) const;
  /// m, the diagonal of the rest bounding box: the length errors are divided by.
  Real characteristicLength() const { return m_characteristicLength; }
  /// Grid dimensions when built by grid(), {0, 0} otherwise.
  std::array<Index, 2> gridSize() const { return m_gridSize; }
  /// What fromMesh() welded and flipped (all zero for grid()).
  const MeshImport& meshImport() const { return m_meshImport; }

  /// bytes, an upper bound on the heap a model of this size needs while fromMesh() or grid()
  /// builds it (about 1.3 times the measured peak; the model keeps about half of it).
  static std::uint64_t estimatedBuildBytes(std::uint64_t vertices, std::uint64_t triangles);

 private:
  ClothModel() = default;
  // Rest state and derived topology of a checked, welded and oriented mesh. `inputOfModel` maps
  // model vertices to the caller's numbering for messages (empty: the same); `bowtieVertices`
  // (ascending) get no bending stencil. `meshSprings`: derive the spring network from the mesh
  // (grid() builds its own).
  static Result<ClothModel> build(const TriangleMesh& mesh, const MeshSettings& settings,
                                  const std::vector<Vec2>& perCornerMaterialCoordinates,
                                  const std::vector<Index>& inputOfModel,
                                  const std::vector<Index>& bowtieVertices, bool meshSprings);
  void buildMeshSprings();

  Vec3Array m_restPositions;
  std::vector<Index> m_indices;
  std::vector<TriangleRest> m_triangles;
  std::vector<Hinge> m_hinges;
  std::vector<BendingStencil> m_bendingStencils;
  std::vector<StencilWeight> m_bendingWeights;
  std::vector<Index> m_bendingTriangles;
  std::vector<Edge> m_edges;
  std::vector<Spring> m_springs;
  std::vector<Real> m_vertexAreas;
  Real m_totalArea = 0;
  Real m_characteristicLength = 0;
  std::array<Index, 2> m_gridSize{0, 0};
  MeshImport m_meshImport;
};

}  // namespace weft
