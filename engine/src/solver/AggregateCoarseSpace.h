// AggregateCoarseSpace: the coarse level of the two-level preconditioner
// (PreconditionerKind::TwoLevelGaussSeidel): rows of the implicit system grouped into aggregates,
// each moving as one rigid translation, and the system's Galerkin restriction to those motions,
// factorised exactly.
//
// Design note.
// - Why. Gauss–Seidel removes the error that varies from vertex to vertex within a few sweeps,
//   but the smooth error, a whole region of the cloth moving wrongly, falls slowly: on a finer
//   mesh the ratio of stiffness to mass, h²k/m, grows with the square of the refinement, and the
//   CG iterations grow with it (on the curtain they double from ×1 to ×4 and again to ×16). A
//   coarse space that holds the smooth motions removes that error in one solve, so the iteration
//   count stops growing with the mesh: the two-level methods of domain decomposition and
//   aggregation multigrid (Vaněk, Mandel & Brezina 1996; Toselli & Widlund 2005, ch. 3).
// - Aggregates. Greedy, in row order, on A's block pattern (Vaněk et al.'s first two passes): a
//   row whose pattern neighbours are all still free founds an aggregate of itself and them; each
//   row left over joins the aggregate of its first aggregated neighbour. On a cloth grid with
//   isometric bending (a 2-ring pattern) an aggregate is about 4 × 4 to 5 × 5 vertices. Built
//   once per pattern: pins and contacts change the filter, not the pattern.
// - Coarse matrix. With P₀ the piecewise-constant prolongation (aggregate I's translation moves
//   each of its rows alike) and S the filter, the coarse basis is S P₀, and A_c = P₀ᵀ S A S P₀:
//   block (I, J) sums S_i A_ij S_j over the rows i ∈ I, j ∈ J. A translation that every row of an
//   aggregate has constrained is in the null space of S P₀; A_c gets a shift of 10⁻¹⁰ of its
//   diagonal block's mean diagonal (1 where that is zero) so the factorisation stays definite, and
//   the prolongation's S removes that direction again. Rejected: smoothed aggregation (a Jacobi
//   step applied to P₀): on the curtain it saved an iteration at most while giving A_c about 2.5
//   times the entries, and its factorisation the time; the six rigid motions per aggregate
//   instead of three translations: A_c would double in size for motions the mass term already
//   keeps well conditioned at the implicit step's h.
// - Solve. Sparse LDLᵀ (Eigen's SimplicialLDLT), its fill-reducing order (AMD) computed once per
//   pattern and the coarse unknowns numbered in it, the upper triangle stored, so a factorisation
//   allocates nothing (its scratch is on the stack up to 16,384 coarse unknowns, Eigen's limit of
//   128 kB). The factorisation is numeric only, once per solve, serial, as are the triangular
//   solves: the parts of a two-level solve that do not scale with threads.
// - Determinism. The restriction sums rows in row order and the coarse solve is serial; the
//   prolongation is per row: the same bits on any thread count.
#pragma once

#include <solver/BlockSparseMatrix.h>
#include <solver/VertexFilter.h>

#include <weft/Math.h>
#include <weft/threading/TaskSystem.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <cstdint>
#include <span>
#include <vector>

namespace weft {

/// Aggregates of a block-sparse system's rows and the system restricted to their translations.
class AggregateCoarseSpace {
 public:
  /// Groups A's rows into aggregates and prepares the coarse pattern and its ordering (allocates).
  /// Call again when A's pattern changes (built() is false for it).
  void build(const BlockSparseMatrix& A);
  /// Whether build() was last called for A's pattern.
  bool built(const BlockSparseMatrix& A) const {
    return m_patternId == A.patternId() && m_aggregateOf.size() == A.blockRows();
  }

  /// A_c = P₀ᵀ S A S P₀ from A's values and the filter, then its LDLᵀ factorisation; build()s
  /// first when A's pattern is new (allocating then). False when the factorisation fails (a
  /// non-finite or indefinite A); addCorrection() then adds nothing.
  /// `tasks` runs it over the aggregates (null: serial); the result does not depend on it.
  bool assemble(const BlockSparseMatrix& A, const VertexFilter& filter, TaskSystem* tasks);

  /// z += S P₀ A_c⁻¹ P₀ᵀ r, for r in the free subspace (S r = r); returns rᵀz, z as updated (the
  /// preconditioner's rᵀP⁻¹r when z held the smoother's part). Adds nothing and returns 0 when
  /// A_c is not factorised.
  /// `tasks` runs the prolongation (null: serial); the result does not depend on it.
  Real addCorrection(const VertexFilter& filter, const Vec3Array& r, Vec3Array& z,
                     TaskSystem* tasks);

  /// Number of aggregates (three coarse unknowns each).
  Index aggregateCount() const { return m_aggregateCount; }
  /// The aggregate of each row.
  std::span<const Index> aggregateOf() const { return m_aggregateOf; }
  /// Whether the last assemble() factorised A_c.
  bool factorised() const { return m_factorised; }

 private:
  using CoarseMatrix = Eigen::SparseMatrix<Real, Eigen::ColMajor, int>;
  /// LDLᵀ of a matrix already in its fill-reducing order: factorises the stored upper triangle in
  /// place, without the copy (and allocation) Eigen's factorize() makes of its input.
  class CoarseSolver
      : public Eigen::SimplicialLDLT<CoarseMatrix, Eigen::Upper, Eigen::NaturalOrdering<int>> {
   public:
    void factorizeInPlace(const CoarseMatrix& upper) { factorize_preordered<true>(upper); }
    /// Every pivot of D positive (vectorD() would copy D).
    bool definite() const { return (m_diag.array() > 0).all(); }
  };

  std::uint64_t m_patternId = 0;
  Index m_aggregateCount = 0;
  std::vector<Index> m_aggregateOf;        ///< aggregate per row
  std::vector<Index> m_memberOffsets;      ///< per aggregate, where its rows start in m_members
  std::vector<Index> m_members;            ///< rows by aggregate, in row order within one
  std::vector<Index> m_blockRowOffsets;    ///< per aggregate I, where its blocks (I, J) start
  std::vector<Index> m_slotBlock;          ///< per slot of A: its coarse block (I, J)
  std::vector<Mat3> m_blocks;              ///< coarse blocks (I, J), summed by assemble()
  std::vector<Index> m_diagonalBlock;      ///< per aggregate: its block (I, I)
  /// Per coarse block, per entry (a, b) in row-major order: its index in A_c's values, or −1 for
  /// an entry below the diagonal (the upper triangle holds it).
  std::vector<std::array<int, 9>> m_blockValues;
  std::vector<int> m_coarseIndex;          ///< per coarse unknown 3I + a: its index in AMD order
  CoarseMatrix m_matrix;                   ///< A_c in AMD order, upper triangle
  CoarseSolver m_solver;
  Eigen::Matrix<Real, Eigen::Dynamic, 1> m_restricted;  ///< P₀ᵀ r in AMD order
  Eigen::Matrix<Real, Eigen::Dynamic, 1> m_coarse;      ///< A_c⁻¹ P₀ᵀ r in AMD order
  bool m_factorised = false;
};

}  // namespace weft
