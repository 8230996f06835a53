// FilteredPcg: the modified preconditioned conjugate gradient of Baraff & Witkin 1998, §5.3,
// which solves the implicit step's A Δv = b with pins and contacts imposed through a filter.
//
// Design note.
// - The method. BW98 keep every iterate of the form Δv = S·y + (I − S)z (VertexFilter): the
//   constrained components are set to their targets at the start and every search direction is
//   filtered, so they never move; CG then runs on the free subspace, where S A S is SPD when A
//   is. Rejected: penalty springs for pins (stiff, and pins drift by force/stiffness), Lagrange
//   multipliers (an indefinite saddle-point system that CG cannot solve as is), and deleting the
//   rows and columns of pinned vertices (the pattern would change with every contact).
// - Start. Cold: Δv₀ = (I − S)z. Warm (default): Δv₀ = S·Δv_prev + (I − S)z, the previous step's
//   solution with this step's constraints; consecutive steps differ little, so this saves most
//   iterations in steady motion.
// - Block Jacobi (PreconditionerKind::BlockJacobi): per vertex, the inverse of the 3×3 diagonal
//   block. It captures the anisotropy a vertex's own stretch and bend stiffness gives it, which
//   BW98's scalar diagonal misses, for 9 instead of 3 multiplies per vertex. For a vertex
//   constrained along p (and q) the block used is S_i A_ii S_i + (I − S_i), inverted and filtered
//   on both sides: D̃_i⁻¹ = S_i (S_i A_ii S_i + I − S_i)⁻¹ S_i, the exact inverse of A_ii on the
//   vertex's free subspace and zero on the constrained one (zero for fixed vertices). Filtering
//   keeps s = D̃⁻¹r in the free subspace, so the residual norm below sees free directions only.
// - Gauss–Seidel (PreconditionerKind::MulticolorGaussSeidel, the engine default). Block Jacobi ignores
//   the coupling between vertices, which dominates the mass on stiff cloth (iterations grow with
//   stiffness until the cap). Symmetric Gauss–Seidel (SSOR, ω = 1) on the filtered matrix
//   Ã = S A S + (I − S) keeps it: with Ã = L̃ + D̃ + L̃ᵀ, M = (D̃ + L̃) D̃⁻¹ (D̃ + L̃)ᵀ, SPD, and on the
//   free subspace exactly because Ã does not mix it with the constrained one. Order: multicolour
//   (MulticolorOrdering), so each sweep runs colour after colour and a colour's vertices in
//   parallel, bitwise the same for any thread count. The colours come from the system's owner
//   (setRowColors(): a cloth colours its mesh once, so zero terms that are skipped and pins that
//   are removed do not change the order, nor the answer), else from A's pattern; the ordering is
//   built once per pattern (BlockSparseMatrix::patternId()) and colours, and rebuilt if either
//   changes. Cost: Eisenstat's trick (1981) — CG runs on Â = P_L⁻¹ Ã P_L⁻ᵀ
//   (P_L = D̃ + L̃) with D̃ as its preconditioner, which is the same Krylov method as PCG on Ã with
//   M, and Â ĉ = t + P_L⁻¹(ĉ − D̃ t), t = P_L⁻ᵀ ĉ, costs one backward and one forward half-sweep,
//   i.e. one SpMV of work, instead of an SpMV plus two triangular solves. Δv is updated with t
//   directly (Δv += α t), so nothing is transformed back at the end. The off-diagonal blocks are
//   copied once per solve into sweep order so the sweeps stream, an isotropic block
//   (BlockSparseMatrix::isotropic(), isometric bending's 2-ring) as its one scalar: on a cloth
//   grid that is 12 of a row's 18 off-diagonal blocks, so the sweeps read under half the bytes
//   of full blocks. On the curtain it takes about half the iterations of block Jacobi
//   (weft-solver-compare, bench/results/solver-defaults.md).
//   Rejected: natural-order Gauss–Seidel and block IC(0) (sequential sweeps: no parallel version
//   with the same bits); over-relaxation (SSOR, ω > 1): with a multicolour order it saves no
//   iterations on the curtain (bench/results/two-level-pcg-2026-11-27.md).
// - Two-level (PreconditionerKind::TwoLevelGaussSeidel, opt-in).
//   Gauss–Seidel's iterations grow with the mesh's refinement (h²k/m grows with it): the smooth
//   error, whole regions moving wrongly, falls slowly. The additive two-level preconditioner
//   P⁻¹ = M_SGS⁻¹ + S P₀ A_c⁻¹ P₀ᵀ S adds an exact solve over aggregates of about 4 × 4 vertices,
//   each moving as one translation (AggregateCoarseSpace, which has the design of the coarse
//   level), which removes that error, so the iterations stop growing. It cannot use Eisenstat's
//   form: an iteration runs both half-sweeps (M_SGS⁻¹ r), the coarse correction and its own SpMV
//   (from the packed blocks), about twice a Gauss–Seidel iteration, and each solve assembles and
//   factorises A_c. It pays only where it saves well over half the iterations: on the curtain
//   ×16 and ×64 while the cloth hangs free, not once contacts make the solves short, where it
//   saves a third (the whole ×16 script: 1.5× Gauss–Seidel's solve time); not on the ×4 at all
//   (bench/results/two-level-pcg-2026-11-27.md has the figures). The forward sweep also forms
//   D̃ P_L⁻¹ r, and the prolongation sums rᵀz, to spare two passes. CG runs on the block-Jacobi
//   loop (iterateJacobi), whose update pass still computes rᵀD̃⁻¹r for the stopping test; s is
//   then overwritten with P⁻¹r. Contact couplings
//   enter the Gauss–Seidel part as above (E_ii in D̃') and stay out of A_c: a preconditioner need
//   only be SPD. Rejected: the multiplicative (V-cycle) form (fewer iterations, one more SpMV
//   each), block Jacobi as the smoother (more iterations, no faster), a second level of
//   aggregation (the coarse solve is not the cost; the iterations grow).
// - Stopping, two tests (PcgStopping).
//   VelocityError (the engine's). What a loose solve must not get wrong is the velocity, so the test
//   measures the error e = Δv − Δv* in the mass norm ‖e‖_M = √(Σ m_i‖e_i‖²) (√kg·m/s) against
//   tolerance · max(‖Δv‖_M, velocityFloor·√Σm), Σ over vertices with a free direction: the velocity
//   change to tolerance relative, Galilean invariant, and a cloth at rest still solved to
//   tolerance × velocityFloor. Two measures of ‖e‖_M:
//   (1) a bound, ‖r‖_{M⁻¹} ≥ ‖e‖_A ≥ ‖e‖_M, since A = M − h∂f/∂v − h²∂f/∂x ≥ M on the free subspace
//   (damping and the definiteness-fixed stiffness are negative semidefinite): exact in soft modes
//   (A e ≈ M e), pessimistic in stiff ones by their h²k/m; one more fused dot product per
//   iteration. It alone may end the solve.
//   (2) an estimate, ‖Δv_k − Δv_{k−w}‖_M, what the last window of w = progressWindow iterations
//   still moved, which is ‖e_{k−w}‖_M minus what is left: close when CG converges steadily (the
//   reasoning of Hestenes–Stiefel's delayed estimate of the energy-norm error), fair to stiff
//   modes, which block Jacobi resolves in a few iterations, but an underestimate where CG crawls
//   (static scenes with 10 s steps). So it ends the solve only while the relative-residual test
//   below (same tolerance) holds too: the residual sees stiff and slowly converging errors, the
//   window sees the soft ones the residual is blind to. Measured at every iteration k ≥ w, fused
//   into the update pass: a ring of the last w iterates (slot k mod w holds Δv_{k−w} until
//   iteration k reads it and writes Δv_k there), so a solve ends at the first iteration that
//   meets the test, not at the next multiple of w (checked only every w-th iteration, solves pile
//   up at multiples of w). One more read and write of a vector per iteration; w vectors of memory.
//   On a stiff sheet (×10⁴ cotton) the bound alone is too pessimistic and hits the iteration cap;
//   this test does not (bench/results/error-time-curtain.md has the figures). The window alone,
//   without the residual's agreement, stops static scenes early, where CG crawls. Rejected:
//   the residual relative to b in the M⁻¹ norm (b's elastic part sets the scale: on a jammed stack
//   it allowed 20–60 % velocity errors) and the energy norm relative to anything holding b's
//   elastic part, for the same reason.
//   RelativeResidual (matrix-only: tests, solves without masses). ‖r‖_{D̃⁻¹} = √(rᵀ D̃⁻¹ r), the
//   block-Jacobi norm of r = S(b − AΔv) for either preconditioner, compared with the same norm of
//   the reference r_ref = S(b − A(I − S)z), the residual of the cold start, which does not depend
//   on the initial guess (BW98 use filter(b), which also ignores the pull of moving pins). It stops
//   when ‖r‖_{D̃⁻¹} ≤ max(tolerance · ‖r_ref‖_{D̃⁻¹}, absoluteTolerance). Its flaw, and why it is
//   not the default: D̃ ≈ m + h²k, so an error in a soft mode (where A e ≈ M e) shows in the
//   residual only as (m/(m + h²k))^{1/2} of its size; on stiff or jammed cloth a "1 %" residual can
//   hide velocity errors of tens of per cent (bench/results/error-time-curtain.md).
//   Both: the absolute floor handles a vanishing right-hand side (cloth at rest on its pins), where
//   no relative goal is reachable. Gauss–Seidel's CG only carries r̂ = P_L⁻¹ r and rᵀM_SGS⁻¹r; it
//   scales the start's exact stopping norm by the fall of √(rᵀM_SGS⁻¹r) into an estimate, and
//   computes the exact one (r = P_L r̂, half an SpMV) only once that estimate meets the threshold,
//   at the end of a velocity-test window whose progress meets it, and at the cap.
// - Determinism. Every vector operation is a small kernel over a vertex range [begin, end).
//   Reductions (dot products) are accumulated in fixed blocks of kReductionBlock vertices, in
//   vertex order within a block, and the per-block partial sums are combined in block order. A
//   parallel version hands blocks to threads and keeps the same combine, so its results are
//   bitwise identical to this serial one for any thread count. Kernels are fused per pass (e.g.
//   x += αc, r −= αq, s = D̃⁻¹r and rᵀs in one sweep) because CG on a sparse matrix is bound by
//   memory bandwidth; three sweeps per iteration, one of them the SpMV (Gauss–Seidel: four, two
//   of them the half-sweeps; a half-sweep splits each colour, whose rows are independent, into
//   one chunk per thread, and its curvature sum is taken from per-row terms afterwards, colour by
//   colour, fixed blocks within a colour, colours in order).
// - Contact couplings (ContactCoupling.h). solve() may take a list of rank-one terms
//   E = Σ coefficient · JᵀJ outside A's block pattern (self-contacts) and then solves (A + E)Δv = b,
//   matrix-free: E = E_diag + E_off, its diagonal blocks E_ii and its coupling blocks.
//   Block Jacobi: D̃' = blocks of A + E_ii (the touched rows' inverses rebuilt), and the SpMV adds
//   S E c, computed serially in list order over the touched rows after the parallel pass.
//   Gauss–Seidel: the sweeps run on Ã' = L̃ + D̃' + L̃ᵀ + S E_off S, with P_L = D̃' + L̃ (L̃ from A
//   only). With t = P_L⁻ᵀ ĉ, Ã' t = P_L t + (ĉ − D̃' t) + S E_off S t, so
//   Â ĉ = t + P_L⁻¹(ĉ − D̃' t + S E_off t): the backward sweep leaves u = ĉ − D̃' t as before (its
//   identity uses D̃' itself), and S E_off t is added to u before the forward sweep; ŝ = D̃' r̂ gets
//   S E_ii r̂ added on the touched rows. M = P_L D̃'⁻¹ P_Lᵀ stays SPD, so this is PCG on Ã' with an
//   SGS preconditioner that holds E's diagonal blocks but not its couplings. The residuals
//   r = S(b − (A + E)Δv) take E Δv the same way. Every coupling operation is serial over the
//   terms or the touched rows in a fixed order: the same bits on any thread count. A ⪰ M still
//   holds (E ⪰ 0), so the velocity test's bound is unchanged.
// - No allocation in solve(): all scratch is sized by resize() (the Gauss–Seidel colouring and
//   packed blocks on the first solve of a pattern). Non-finite input (NaN or inf in
//   b or in A where it reaches the free subspace) ends the solve with converged = false; deltaV
//   then holds the last finite iterate.
#pragma once

#include <solver/AggregateCoarseSpace.h>
#include <solver/BlockSparseMatrix.h>
#include <solver/ContactCoupling.h>
#include <solver/MulticolorOrdering.h>
#include <solver/VertexFilter.h>

#include <weft/Math.h>
#include <weft/engine/SolverSettings.h>
#include <weft/threading/TaskSystem.h>

#include <span>
#include <vector>

namespace weft {

/// How accurately FilteredPcg solves, and from where it starts.
struct PcgSettings {
  /// Relative accuracy. RelativeResidual: of ‖r‖_{D̃⁻¹} against the cold-start residual;
  /// VelocityError: of the velocity change, in the mass norm. Lower is more accurate and costs
  /// more iterations (about linearly in −log(tolerance)).
  Real tolerance = 1e-3;
  /// Iteration cap (one SpMV each); reaching it before the tolerance reports converged = false.
  int maxIterations = 200;
  /// Start from the filtered previous solution (deltaV on input) instead of (I − S)z.
  bool warmStart = true;
  /// √kg·m/s: absolute floor of the stopping threshold, in the stopping norm, for a right-hand
  /// side that (nearly) vanishes. 1e-12 is a velocity error of ~1.5e-12 m/s spread over the
  /// 0.45 kg curtain: far below anything visible, far above double rounding of a typical step's
  /// ‖b‖ (~0.1 √kg·m/s for gravity alone). Raising it ends near-static solves sooner.
  Real absoluteTolerance = 1e-12;
  /// The stopping test (enum in SolverSettings.h); ImplicitEuler passes SolverSettings::cgStopping.
  PcgStopping stopping = PcgStopping::RelativeResidual;
  /// m/s, VelocityError only: the smallest velocity change the tolerance is taken relative to,
  /// so a cloth at rest (Δv → 0) is solved to tolerance × this instead of to the absolute floor.
  /// 1e-3 m/s is half the speed below which a cloth may sleep (SleepSettings::speed).
  Real velocityFloor = 1e-3;
  /// VelocityError only: iterations per progress window; the velocity change over a window is
  /// the estimate of the error left at its start (header, "Stopping"). Longer is safer and stops
  /// later; 4 is enough on the stress scenes (bench/results/error-time-curtain.md).
  int progressWindow = 4;
  /// Which preconditioner (SolverSettings::preconditioner). The stopping norm does not depend on
  /// it, so the tolerance means the same accuracy whichever is used.
  PreconditionerKind preconditioner = PreconditionerKind::BlockJacobi;
};

/// What one FilteredPcg::solve did.
struct SolveReport {
  int iterations = 0;         ///< CG iterations run (one SpMV of work each); 0 when the start was good enough
  /// The error measure at exit over its scale. RelativeResidual: ‖r‖_{D̃⁻¹} / max(‖r_ref‖_{D̃⁻¹},
  /// absoluteTolerance); VelocityError: the smaller of ‖r‖_{M⁻¹} and the last window's progress
  /// over max(‖Δv‖_M, velocityFloor·√Σm). NaN when the input was not finite.
  Real relativeResidual = 0;
  bool converged = false;     ///< the stopping threshold was met (false: cap, breakdown or NaN)
  /// √kg·m/s, the stopping norm of r at exit (‖r‖_{D̃⁻¹} or ‖r‖_{M⁻¹}), from the recurrence (an
  /// estimate with Gauss–Seidel when the progress test ended the solve).
  Real residualNorm = 0;
};

/// Partial sums of one FilteredPcg pass over the vertices (summed in block order): rᵀP⁻¹r for
/// CG, the stopping norm², and the solution's mass norm².
struct FilteredPcgPassSums {
  Real cg = 0;
  Real stop = 0;
  Real scale = 0;
  Real progress = 0;
  FilteredPcgPassSums operator+(const FilteredPcgPassSums& o) const {
    return {cg + o.cg, stop + o.stop, scale + o.scale, progress + o.progress};
  }
};

/// The mass weights of the velocity test (PcgStopping::VelocityError) per vertex: m_i and 1/m_i,
/// both zero on a fixed vertex (no free velocity to be wrong). Null: the relative-residual test,
/// whose norm is D̃⁻¹.
struct FilteredPcgMassWeights {
  const Real* mass = nullptr;
  const Real* inverseMass = nullptr;
  bool active() const { return inverseMass != nullptr; }
};

/// One triangle of A's off-diagonal blocks (MulticolorOrdering's lower or upper entries) packed in
/// sweep order: general blocks whole, isotropic ones as the scalar of their multiple of I₃.
struct PackedTriangle {
  std::vector<Mat3> general;
  std::vector<Real> isotropic;
};

/// BW98 modified PCG with a filtered block-Jacobi, multicolour Gauss–Seidel or two-level
/// preconditioner; owns its scratch.
class FilteredPcg {
 public:
  /// Number of vertices whose sums form one partial sum of a reduction. Fixed (not a function of
  /// the thread count) so the summation order, and hence every bit of the result, is too; 256
  /// vertices of the four solver vectors (~24 KB) fit in L1/L2 and amortise a task's overhead.
  static constexpr Index kReductionBlock = 256;
  /// A system of fewer rows (2 blocks) is solved on the calling thread: its vector passes would
  /// be one block and its colours a few dozen rows, whose fork and join cost more than a second
  /// thread saves. The blocks and their order are the same, so are the bits.
  static constexpr Index kMinParallelRows = 2 * kReductionBlock;
  /// Fewest rows of one colour a sweep hands to a task. A colour's rows are independent, so a
  /// sweep splits each colour into one chunk per thread (not into reduction blocks: the
  /// curtain's colours are ~140 rows, under one block) and any split gives the same bits; 32
  /// rows are ~1.5 µs of work, about twice a fork and join on two threads.
  static constexpr Index kMinSweepChunk = 32;

  /// Allocates scratch for vertexCount vertices; solve() then never allocates for that size.
  void resize(Index vertexCount);

  /// Solves A Δv = b on the free subspace of filter, with the constrained part of Δv equal to
  /// filter's targets (fixed vertices come out bitwise at their targets). A must be symmetric
  /// positive definite (on the free subspace at least) with blockRows() equal to b.size() and
  /// filter.size(); otherwise the solve returns converged = false with deltaV untouched.
  /// masses (kg per row) are required by PcgStopping::VelocityError (a size mismatch is reported
  /// like the others) and ignored otherwise.
  /// deltaV in: the previous solution when settings.warmStart (if its size differs from the
  /// vertex count it is resized to zeros and the start is cold), anything otherwise; out: the
  /// solution. Allocates only if resize() was not called with this vertex count.
  /// `tasks` runs the sweeps over the reduction blocks (null: serial); the blocks and the order
  /// their partial sums are combined in do not depend on it, so neither do the bits.
  /// couplings: rank-one terms added to A (rows of A, kInvalidIndex entries skipped; the rows of
  /// one term distinct); the solve is then of (A + Σ coefficient·JᵀJ) Δv = b (header, "Contact
  /// couplings"). A row out of range is reported like a size mismatch. The touched-row list grows
  /// (allocates) only when more rows are coupled than in any earlier solve.
  SolveReport solve(const BlockSparseMatrix& A, const Vec3Array& b, const VertexFilter& filter,
                    const PcgSettings& settings, Vec3Array& deltaV, TaskSystem* tasks = nullptr,
                    std::span<const Real> masses = {},
                    std::span<const ContactCoupling> couplings = {});

  /// Colours of A's rows for the Gauss–Seidel order (MulticolorOrdering::build), used by every
  /// later solve while they separate every coupled pair of A's pattern (else the pattern is
  /// coloured); empty: colour the pattern. The span must stay valid until the next call.
  void setRowColors(std::span<const Index> rowColors) { m_rowColors = rowColors; }

  /// z = P̃⁻¹ r: the preconditioner `kind` built from A (no couplings) and filter exactly as solve() builds it
  /// (block Jacobi: D̃⁻¹ r; Gauss–Seidel: P_U⁻¹ D̃ P_L⁻¹ r; two-level: that plus S P₀ A_c⁻¹ P₀ᵀ r).
  /// r should lie in the free subspace
  /// (S r = r); z does, exactly zero at fixed vertices. For tests and diagnostics; sizes as solve().
  void applyPreconditioner(const BlockSparseMatrix& A, const VertexFilter& filter,
                           PreconditionerKind kind, const Vec3Array& r, Vec3Array& z,
                           TaskSystem* tasks = nullptr);

 private:
  // The task system a system of `rows` rows runs on: none below kMinParallelRows, nor one of a
  // single thread (whose parallel calls would only add their overhead).
  static TaskSystem* tasksFor(Index rows, TaskSystem* tasks) {
    return rows >= kMinParallelRows && tasks && !tasks->isSerial() ? tasks : nullptr;
  }

  /// Runs kernel(begin, end) over the fixed reduction blocks of [0, count) (all vertices, or a
  /// colour's vertex list) and returns the sum of the returned partials, combined in block order
  /// (the deterministic reduction).
  template <typename Kernel>
  auto sumOverBlocks(Index count, Kernel&& kernel);

  /// Runs kernel(begin, end) over the fixed reduction blocks of [0, count) (no reduction).
  template <typename Kernel>
  void forEachBlock(Index count, Kernel&& kernel);

  /// Runs kernel(begin, end) over [0, count) (one colour's sweep positions) in one chunk per
  /// thread of at least kMinSweepChunk rows; the rows are independent, so the split is free.
  template <typename Kernel>
  void forEachColourChunk(Index count, Kernel&& kernel);

  /// w = P_L⁻¹ w in place, colour by colour; with curvature, returns Σ cᵀ(t + w).
  template <bool curvature>
  Real forwardSweep(const VertexFilter& filter, const Vec3Array& c, const Vec3Array& t,
                    Vec3Array& w);

  /// t = P_U⁻¹ c and w = c − D̃ t, colours in reverse.
  void backwardSweep(const VertexFilter& filter, const Vec3Array& c, Vec3Array& t, Vec3Array& w);

  /// Orders A's rows (m_rowColors, else A's pattern) if the pattern or colours are new (allocates
  /// then) and packs its off-diagonal blocks in sweep order (every solve: the values change).
  void prepareGaussSeidel(const BlockSparseMatrix& A);

  /// Collects the rows the couplings touch and their diagonal blocks E_ii, and rebuilds those
  /// rows' preconditioner blocks from A_ii + E_ii (header, "Contact couplings").
  void prepareCouplings(const BlockSparseMatrix& A, const VertexFilter& filter);
  /// y = E x (E_off x when offDiagonalOnly) on the touched rows (zero elsewhere), serially;
  /// null when there are no couplings.
  const Vec3Array* couplingProduct(const Vec3Array& x, bool offDiagonalOnly = false);
  /// s += S E_ii r on the touched rows; returns Σ rᵀ S E_ii r over them, in row-list order.
  Real addCouplingDiagonal(const VertexFilter& filter, const Vec3Array& r, Vec3Array& s);

  /// The stopping rule of one solve (header, "Stopping").
  struct Stopping {
    bool velocityTest = false;     ///< PcgStopping::VelocityError
    Real tolerance = 0;            ///< relative tolerance
    Real referenceNorm = 0;        ///< √kg·m/s, ‖r_ref‖_{D̃⁻¹} (both tests)
    Real scaleFloor = 0;           ///< √kg·m/s, velocityFloor·√Σm (velocity test)
    Real absoluteTolerance = 0;    ///< √kg·m/s, floor of the threshold
    bool referenceFinite = true;   ///< the reference (or the masses) were finite
    int maxIterations = 0;         ///< iteration cap
    int window = 1;                ///< iterations per progress window (velocity test)
    /// √kg·m/s, what the tolerance is relative to, given ‖Δv‖²_M.
    Real scale(Real solutionSquaredNorm) const;
    /// √kg·m/s, the error measure at which the solve stops.
    Real threshold(Real solutionSquaredNorm) const;
    /// Sets report's residual fields from the stopping norm², the block-Jacobi residual norm²
    /// rᵀD̃⁻¹r, ‖Δv‖²_M and the window progress² (negative: no window ended); true when converged.
    bool judge(Real stopDelta, Real residualDelta, Real solutionSquaredNorm, Real progressSquared,
               SolveReport& report) const;
  };

  /// CG iterations from the start residual in r (s = D̃⁻¹r) with the block-Jacobi preconditioner,
  /// or with the two-level one.
  void iterateJacobi(const BlockSparseMatrix& A, const VertexFilter& filter,
                     const FilteredPcgMassWeights& weights, const Stopping& stopping,
                     const FilteredPcgPassSums& start, bool twoLevel, Vec3Array& deltaV,
                     SolveReport& report);

  /// z = M_SGS⁻¹ r = P_U⁻¹ D̃' P_L⁻¹ r, the symmetric Gauss–Seidel preconditioner applied as such
  /// (not in Eisenstat's form). Uses m_product and m_backward as scratch.
  void applySymmetricGaussSeidel(const VertexFilter& filter, const Vec3Array& r, Vec3Array& z);
  /// z = P⁻¹r for the two-level preconditioner (header, "Two-level"): symmetric Gauss–Seidel plus
  /// the coarse correction; returns rᵀz. Uses m_product and m_backward as scratch.
  Real applyTwoLevel(const VertexFilter& filter, const Vec3Array& r, Vec3Array& z);

  /// CG iterations with multicolour symmetric Gauss–Seidel (Eisenstat form) from r.
  void iterateGaussSeidel(const BlockSparseMatrix& A, const VertexFilter& filter,
                          const FilteredPcgMassWeights& weights, const Stopping& stopping,
                          const FilteredPcgPassSums& start, Vec3Array& deltaV,
                          SolveReport& report);

  Vec3Array m_residual;          ///< r = S(b − AΔv) (Gauss–Seidel: r̂ = P_L⁻¹ r)
  Vec3Array m_preconditioned;    ///< s = D̃⁻¹ r (Gauss–Seidel: ŝ = D̃ r̂)
  Vec3Array m_direction;         ///< c, the filtered search direction
  Vec3Array m_product;           ///< q = S A c (Gauss–Seidel: u, then w = P_L⁻¹ u)
  Vec3Array m_backward;          ///< t = P_U⁻¹ ĉ (Gauss–Seidel only)
  std::vector<Mat3> m_diagonal;         ///< D̃_i per vertex: A's diagonal blocks, dense
  std::vector<Mat3> m_inverseDiagonal;  ///< D̃_i⁻¹ per vertex (filtered block-Jacobi)
  std::vector<Real> m_blockPartials;    ///< one partial sum per reduction block
  std::vector<Real> m_sweepTerms;       ///< per sweep position, the forward sweep's curvature term
  std::span<const Index> m_rowColors;   ///< setRowColors(); empty: colour A's pattern
  MulticolorOrdering m_ordering;        ///< order of A's rows (Gauss–Seidel only)
  AggregateCoarseSpace m_coarseSpace;   ///< the two-level preconditioner's coarse level
  PackedTriangle m_lowerBlocks;         ///< A's lower-colour blocks in sweep order (Gauss–Seidel)
  PackedTriangle m_upperBlocks;         ///< A's upper-colour blocks in sweep order (Gauss–Seidel)
  /// The velocity test's last w iterates, slot k mod w holding Δv_k (w · vertex count entries).
  Vec3Array m_progressRing;
  std::vector<Real> m_stopMass;         ///< kg, m_i of the velocity test (0 on fixed vertices)
  std::vector<Real> m_inverseMass;      ///< 1/kg, 1/m_i of the velocity test (0 on fixed vertices)
  TaskSystem* m_tasks = nullptr;        ///< the current solve's task system, or null (serial)
  std::span<const ContactCoupling> m_couplings;  ///< the current solve's couplings
  std::vector<Index> m_couplingRows;    ///< rows the couplings touch, in first-seen order
  std::vector<char> m_couplingMark;     ///< 1 on the rows of m_couplingRows
  std::vector<Mat3> m_couplingDiagonal; ///< E_ii on the touched rows, zero elsewhere
  Vec3Array m_couplingProduct;          ///< E x (or E_off x) on the touched rows, zero elsewhere
};

}  // namespace weft
