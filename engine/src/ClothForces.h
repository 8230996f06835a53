// ClothForces: the internal and external forces of one cloth, and their Jacobians assembled into
// the implicit system.
//
// The loop is deliberately trivial: every element (triangle, hinge or spring) asks its pure
// kernel for its contribution and scatters it through slots precomputed at set-up into the
// block-sparse matrix. There is no search and no allocation in a step.
// - Triangles use stretchShear() (forces/BaraffWitkin.h) for forces and for assemblies in
//   StiffnessMode::Definite (the implicit solver's): stretch, shear and their damping fused in
//   closed form, from constants (√a-scaled weights, rest lengths) stored in the element itself, so
//   the loop streams through one array. Assemblies in Exact mode (checks, Newton), hinges and
//   springs go through conditions (forces/Condition.h) and ElementForces.
// - One pass per vertex starts every row: gravity, drag and external forces; the isometric
//   bending force gathered from its stencils; and the row's blocks set to M + h·drag on the
//   diagonal plus bending's constant Hessian, (h k_d + h² D) K̂ ⊗ I₃, K̂ = Σ_s c_s w_s w_sᵀ summed
//   once at set-up (in stencil order) into one scalar per block. Every other block of the row is
//   zeroed in the same pass, so the matrix is written row by row once before the elements add to
//   it, with no separate zeroing sweep; bending needs no colouring (one writer per row).
//
// Parallel and deterministic: elements of each kind are cut into chunks of consecutive elements
// and the chunks coloured once (forces/ChunkColouring.h), so that no two chunks of a colour share
// a vertex. A colour is then a parallelFor with one chunk per block: blocks write disjoint vertices
// and matrix blocks with no locks or atomics, each chunk writes rows near each other, and every
// force entry and block receives its contributions in an order fixed by the model, whatever the
// thread count. Energies are summed per fixed block and combined in block order (TaskSystem's
// ordered reduction). So 1, 2 or 8 threads give the same bits. In Definite mode the matrix is also
// symmetric to the bit: a triangle writes block (j, i) as the transpose of the (i, j) it computed,
// K̂ is symmetric, and blocks (i, j) and (j, i) receive their contributions in the same order.
// Rejected: per-element buffers gathered per row (about 5 MB of extra traffic per assembly on the
// curtain), and per-thread copies of the matrix merged in a fixed order (memory × threads, and a
// merge as costly as the SpMV). Colouring costs one fork/join per colour.
#pragma once

#include "forces/BaraffWitkin.h"
#include "forces/Condition.h"
#include "solver/BlockSparseMatrix.h"
#include "solver/FreeVertexMap.h"
#include "solver/PinnedCoupling.h"

#include <weft/threading/TaskSystem.h>

#include <weft/engine/ClothModel.h>
#include <weft/engine/Material.h>

#include <array>
#include <memory>
#include <span>
#include <vector>

namespace weft {

/// Everything that decides the forces on one cloth.
struct ClothForceSettings {
  ForceModel model = ForceModel::BaraffWitkin;  ///< continuum or springs
  ClothMaterial material;                       ///< continuum material (and density, drag)
  MassSpringMaterial springs;                   ///< spring stiffnesses for ForceModel::MassSpring
  Vec3 gravity{0.0, -9.81, 0.0};                ///< m/s²
  Vec3 wind{0.0, 0.0, 0.0};                     ///< m/s, air velocity for the drag force
  StiffnessMode stiffnessMode = StiffnessMode::Definite;  ///< Jacobian treatment (keep Definite)
  /// Leave out terms whose coefficients are all zero: bending hinges without bending stiffness
  /// or damping, damping Jacobians without damping. Exact; false evaluates them anyway (checks).
  bool skipZeroTerms = true;
};

class ClothForces {
 public:
  /// Precomputes element tables from the model. `masses` in kg, one per vertex. `tasks` runs the
  /// loops (null: serial); the results are bitwise the same either way.
  ClothForces(const ClothModel& model, const ClothForceSettings& settings, std::vector<Real> masses,
              TaskSystem* tasks = nullptr);
  /// Runs later evaluations on `tasks` (null: serial).
  void setTaskSystem(TaskSystem* tasks) { m_tasks = tasks; }

  /// Vertex pairs that some element couples: the sparsity pattern of the system matrix.
  std::vector<std::array<Index, 2>> coupledPairs() const;
  /// The pairs of coupledPairs() that only isometric bending couples: their blocks are
  /// (h k_d + h² D) K̂_ij I₃, multiples of the identity (BlockSparseMatrix::isotropic()).
  std::vector<std::array<Index, 2>> isotropicPairs() const;
  /// Builds the system of `map`'s rows: `matrix` with the pattern of coupledPairs() between rows
  /// (isotropicPairs() marked), `coupling` with the blocks towards removed vertices, and binds
  /// them (bindMatrix). Allocates; call at set-up and when the map changes.
  void buildSystem(const FreeVertexMap& map, BlockSparseMatrix& matrix, PinnedCoupling& coupling);
  /// Vertex pairs that some force term of this model could couple whatever its coefficients
  /// (also terms left out because they are zero, ClothForceSettings::skipZeroTerms): a superset
  /// of coupledPairs() fixed by the mesh and the force and bending models, for the solver's
  /// colouring (MulticolorOrdering), which then does not depend on which terms are zero.
  std::vector<std::array<Index, 2>> potentialCoupledPairs() const;
  /// Looks up, once, the matrix slot of every block every element writes (row i = vertex i).
  void bindMatrix(const BlockSparseMatrix& matrix);
  /// The same with vertices removed from the system (FreeVertexMap.h): `matrix` has
  /// map.rowCount() rows, blocks between a free row and a removed vertex go to `coupling`, and
  /// the rows of removed vertices are not assembled at all. Call again when the map changes.
  void bindMatrix(const BlockSparseMatrix& matrix, const FreeVertexMap& map,
                  const PinnedCoupling& coupling);

  /// f(x, v) in N on every vertex; returns the potential energy in J (elastic + gravity).
  Real computeForces(const Vec3Array& x, const Vec3Array& v, Vec3Array& f) const;
  /// A = M − h ∂f/∂v − h² ∂f/∂x, f(x, v) and (∂f/∂x)·velocityForProduct; returns the energy.
  /// f and the product cover every vertex; the matrix (and `coupling`, when bindMatrix() was
  /// given one) the rows it was bound with.
  Real assemble(const Vec3Array& x, const Vec3Array& v, Real h, BlockSparseMatrix& matrix,
                Vec3Array& f, const Vec3Array& velocityForProduct,
                Vec3Array& stiffnessTimesVelocity, PinnedCoupling* coupling = nullptr) const;

  const std::vector<Real>& masses() const { return m_masses; }
  /// Colours of each element kind (triangles, hinges, springs): fork/joins per assembly.
  std::array<std::size_t, 3> colourCounts() const {
    return {m_triangleColours.size() - 1, m_hingeColours.size() - 1, m_springColours.size() - 1};
  }
  const ClothForceSettings& settings() const { return m_settings; }
  /// N, a force on every vertex added to each evaluation (constant in x and v, so no Jacobian);
  /// empty: none. Sizes and finiteness are checked by the caller.
  void setExternalForces(std::span<const Vec3> forces) {
    m_externalForces.assign(forces.begin(), forces.end());
  }
  const Vec3Array& externalForces() const { return m_externalForces; }
  /// Changes gravity (m/s²) and air velocity (m/s) for later evaluations.
  void setExternalFields(const Vec3& gravity, const Vec3& wind) {
    m_settings.gravity = gravity;
    m_settings.wind = wind;
  }
  /// True when evaluations include bending (isometric stencils or dihedral hinges).
  bool evaluatesBending() const { return m_isometricBending || !m_hinges.empty(); }
  /// True when assemblies form damping Jacobians (∂f/∂v of the element dampers).
  bool formsDampingJacobians() const { return m_damping; }

 private:
  /// The pairs of coupledPairs() that triangles, hinges or springs hold (every pair of each
  /// element, in element order): their blocks are general 3×3 blocks.
  std::vector<std::array<Index, 2>> elementPairs() const;
  struct Pass;  // one evaluation: what to compute and where to put it
  Real evaluate(const Pass& pass) const;
  void buildIsometricBending();

  template <int N>
  struct Element {
    std::array<Index, N> vertices;
    std::array<Index, N * N> slots;  // slot of block (vertices[a], vertices[b]) at a·N + b
    Index modelIndex;                // position in the model's list (rest data)
  };
  struct TriangleElement : Element<3> {
    StretchShearRest membrane;  // the stretchShear() constants, next to the indices they go with
  };
  struct SpringElement : Element<2> {
    Real restLength;
    Real stiffness;  // N/m
    Real damping;    // N·s/m
  };

  const ClothModel* m_model;
  ClothForceSettings m_settings;
  std::vector<Real> m_masses;
  std::vector<TriangleElement> m_triangles;
  std::vector<Element<4>> m_hinges;
  std::vector<SpringElement> m_springs;
  // Elements are stored sorted by colour; colour k holds [colours[k], colours[k + 1]).
  std::vector<Index> m_triangleColours, m_hingeColours, m_springColours;
  std::vector<Index> m_diagonalSlots;
  // Per vertex, the matrix slots of its row [rowSlots[i][0], rowSlots[i][1]) (empty for a vertex
  // without a row): the per-vertex pass initialises them, so the matrix needs no separate zeroing.
  std::vector<std::array<Index, 2>> m_rowSlots;
  // Per matrix slot, the entry of K̂ it holds (1/m², zero where bending couples nothing): the
  // per-vertex pass writes each block once as (h k_d + h² D) K̂_ij I.
  std::vector<Real> m_slotBending;
  // Slots below this are matrix slots; from it on, PinnedCoupling slots offset by it;
  // kInvalidIndex is a block of a removed vertex's row, which is not assembled.
  Index m_couplingBase = kInvalidIndex;
  Vec3Array m_externalForces;  // N per vertex, or empty
  // Isometric bending: K̂ by rows (column, value, matrix slot), the stencils that hold each vertex
  // (for the force gather), and per-stencil scratch c_s (D r_s + k_d S_s v).
  struct BendingEntry {
    Index column;
    Real value;  // 1/m², entry of K̂
    Index slot;
  };
  struct StencilUse {
    Index stencil;
    Real weight;
  };
  std::vector<Index> m_bendingRowOffsets;
  std::vector<BendingEntry> m_bendingEntries;
  std::vector<Index> m_stencilUseOffsets;
  std::vector<StencilUse> m_stencilUses;
  mutable Vec3Array m_stencilResiduals;  // written by evaluate(), sized at set-up: no allocation
  bool m_isometricBending = false;
  TaskSystem* m_tasks = nullptr;
  std::unique_ptr<TaskSystem> m_serialTasks;  // used when m_tasks is null; reused, so no allocation
  bool m_bending = false;  // bending stiffness or damping non-zero
  bool m_damping = true;   // some element damping non-zero (or skipZeroTerms off)
};

}  // namespace weft
