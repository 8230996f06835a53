// FilteredPcg: BW98 §5.3 modified PCG. See the design note in the header for the method, the
// stopping rule and the determinism scheme; the kernels below are the per-range sweeps it runs.
#include <solver/FilteredPcg.h>
#include <solver/MulticolorOrdering.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace weft {

namespace {

using PassSums = FilteredPcgPassSums;

using MassWeights = FilteredPcgMassWeights;

/// One vertex's term of the stopping norm²: rᵀM⁻¹r for the velocity test, rᵀs = rᵀD̃⁻¹r otherwise.
inline Real stopTerm(const MassWeights& weights, Index vertex, const Vec3& r, const Vec3& s) {
  return weights.active() ? weights.inverseMass[vertex] * r.squaredNorm() : r.dot(s);
}

/// One vertex's term of ‖Δv‖²_M (zero for the relative-residual test).
inline Real massTerm(const MassWeights& weights, Index vertex, const Vec3& deltaV) {
  return weights.active() ? weights.mass[vertex] * deltaV.squaredNorm() : Real(0);
}

// --- Kernels over a vertex range [begin, end). Each touches only its own vertices' entries of the
// --- output arrays (reading neighbours only through the SpMV gather), and each dot product is
// --- summed in vertex order, so a range gives the same bits whichever thread runs it.

/// P̃_i⁻¹ of one vertex before the safety checks: the inverse of its diagonal block on the
/// vertex's free subspace, zero on the constrained one (header, "Preconditioner").
Mat3 filteredInverse(const Mat3& diagonal, const VertexFilter& filter, Index vertex) {
  switch (filter.kind(vertex)) {
    case ConstraintKind::Free:
      return diagonal.inverse();
    case ConstraintKind::OneDirection:
    case ConstraintKind::TwoDirections: {
      // S A S + (I − S) is A_ii on the free subspace and the identity on the constrained one, so
      // it is invertible whenever A_ii is SPD; the outer S's zero the constrained part again.
      const Mat3 projection = filter.projection(vertex);
      const Mat3 restricted = projection * diagonal * projection + (Mat3::Identity() - projection);
      return projection * restricted.inverse() * projection;
    }
    case ConstraintKind::Fixed:
      break;
  }
  return Mat3::Zero();
}

/// P̃_i⁻¹ of one vertex whose diagonal block is `diagonal`.
Mat3 preconditionerBlock(const Mat3& diagonal, const VertexFilter& filter, Index vertex) {
  Mat3 inverse = filteredInverse(diagonal, filter, vertex);
  // A singular diagonal block (impossible for SPD A, possible for a broken assembly) gives an
  // infinite inverse; fall back to scalar Jacobi so the preconditioner itself stays finite. A NaN
  // block fails the test too, but its NaN still reaches the residual through the SpMV.
  if (!inverse.allFinite()) {
    const Real meanDiagonal = diagonal.trace() / 3;
    inverse = (meanDiagonal > 0 && std::isfinite(meanDiagonal) ? 1 / meanDiagonal : Real(1)) *
              filter.projection(vertex);
  }
  // Cofactor inverses of a symmetric block can differ from symmetric in the last bit; CG wants a
  // symmetric preconditioner, so average the two triangles.
  return Real(0.5) * (inverse + inverse.transpose());
}

/// D̃_i and P̃_i⁻¹ for every vertex of the range. The iterations read D̃ from this dense copy: a
/// diagonal block inside A lies one row (about 1.4 kB) from the next, a cache line and often a
/// page apart, where the copy streams.
void buildPreconditionerRange(Index begin, Index end, const BlockSparseMatrix& A,
                              const VertexFilter& filter, std::vector<Mat3>& diagonal,
                              std::vector<Mat3>& inverseDiagonal) {
  for (Index vertex = begin; vertex < end; ++vertex) {
    diagonal[vertex] = A.block(A.diagonalSlot(vertex));
    inverseDiagonal[vertex] = preconditionerBlock(diagonal[vertex], filter, vertex);
  }
}

/// Δv = S·Δv + (I − S)z (warm) or Δv = (I − S)z (cold) over the range.
void startRange(Index begin, Index end, const VertexFilter& filter, bool warmStart,
                Vec3Array& deltaV) {
  for (Index vertex = begin; vertex < end; ++vertex) {
    deltaV[vertex] = warmStart ? Vec3(filter.filter(vertex, deltaV[vertex]) + filter.target(vertex))
                               : filter.target(vertex);
  }
}

/// out = (I − S)z over the range; returns Σ ‖(I − S)z‖² (zero when no target moves anything).
Real targetRange(Index begin, Index end, const VertexFilter& filter, Vec3Array& out) {
  Real sum = 0;
  for (Index vertex = begin; vertex < end; ++vertex) {
    out[vertex] = filter.target(vertex);
    sum += out[vertex].squaredNorm();
  }
  return sum;
}

/// r = S b, s = P̃⁻¹ r over the range; returns Σ rᵀs and the stopping norm² (of a zero start).
PassSums rightHandSideRange(Index begin, Index end, const Vec3Array& b, const VertexFilter& filter,
                            const std::vector<Mat3>& inverseDiagonal, const MassWeights& weights,
                            Vec3Array& r, Vec3Array& s) {
  PassSums sum;
  for (Index vertex = begin; vertex < end; ++vertex) {
    r[vertex] = filter.filter(vertex, b[vertex]);
    s[vertex].noalias() = inverseDiagonal[vertex] * r[vertex];
    sum.cg += r[vertex].dot(s[vertex]);
    sum.stop += stopTerm(weights, vertex, r[vertex], s[vertex]);
  }
  return sum;
}

/// r = S(b − A x − y), s = P̃⁻¹ r over the range, y = E x the contact couplings' product (null:
/// none); returns Σ rᵀs, the stopping norm² and ‖x‖²_M.
PassSums residualRange(Index begin, Index end, const BlockSparseMatrix& A, const Vec3Array& b,
                       const VertexFilter& filter, const std::vector<Mat3>& inverseDiagonal,
                       const MassWeights& weights, const Vec3Array& x, Vec3Array& r, Vec3Array& s,
                       const Vec3Array* coupled) {
  PassSums sum;
  for (Index vertex = begin; vertex < end; ++vertex) {
    Vec3 rest = b[vertex] - A.multiplyRow(vertex, x);
    if (coupled) rest -= (*coupled)[vertex];
    r[vertex] = filter.filter(vertex, rest);
    s[vertex].noalias() = inverseDiagonal[vertex] * r[vertex];
    sum.cg += r[vertex].dot(s[vertex]);
    sum.stop += stopTerm(weights, vertex, r[vertex], s[vertex]);
    sum.scale += massTerm(weights, vertex, x[vertex]);
  }
  return sum;
}

/// c = s over the range (the first search direction; s is already filtered).
void copyRange(Index begin, Index end, const Vec3Array& in, Vec3Array& out) {
  std::copy(in.begin() + begin, in.begin() + end, out.begin() + begin);
}

/// q = S A c over the range (the SpMV); returns Σ cᵀq.
Real filteredProductRange(Index begin, Index end, const BlockSparseMatrix& A,
                          const VertexFilter& filter, const Vec3Array& c, Vec3Array& q) {
  Real sum = 0;
  for (Index vertex = begin; vertex < end; ++vertex) {
    q[vertex] = filter.filter(vertex, A.multiplyRow(vertex, c));
    sum += c[vertex].dot(q[vertex]);
  }
  return sum;
}

/// The velocity test's progress ring slot an update pass reads and rewrites (header, "Stopping"):
/// it holds Δv_{k−w} on entry, Δv_k on exit. Null values: no velocity test; measure false: the
/// slot is only filled (k < w, no iterate w back yet).
struct ProgressSlot {
  Vec3* values = nullptr;
  bool measure = false;
};

/// m_i‖Δv_k − Δv_{k−w}‖² for one vertex (when measured), then the slot takes Δv_k.
inline Real progressTerm(const MassWeights& weights, Index vertex, const Vec3& deltaV,
                         const ProgressSlot& slot) {
  if (!slot.values) return 0;
  const Real term = slot.measure ? massTerm(weights, vertex, deltaV - slot.values[vertex]) : Real(0);
  slot.values[vertex] = deltaV;
  return term;
}

/// The ring slot of the update that makes iterate k (k ≥ 1): slot k mod w, which holds Δv_{k−w}
/// once k ≥ w (slot 0 holds the start Δv_0). Empty when the velocity test is off.
ProgressSlot ringSlot(Vec3Array& ring, Index vertexCount, bool velocityTest, int window,
                      int iteration) {
  if (!velocityTest) return {};
  return {ring.data() + std::size_t(iteration % window) * std::size_t(vertexCount),
          iteration >= window};
}

/// Δv += α c, r −= α q, s = P̃⁻¹ r over the range; returns Σ rᵀs, the stopping norm², ‖Δv‖²_M and
/// the progress over the last window (when the slot measures).
PassSums updateRange(Index begin, Index end, Real alpha, const Vec3Array& c, const Vec3Array& q,
                     const std::vector<Mat3>& inverseDiagonal, const MassWeights& weights,
                     Vec3Array& deltaV, Vec3Array& r, Vec3Array& s, const ProgressSlot& slot) {
  PassSums sum;
  for (Index vertex = begin; vertex < end; ++vertex) {
    deltaV[vertex] += alpha * c[vertex];
    r[vertex] -= alpha * q[vertex];
    s[vertex].noalias() = inverseDiagonal[vertex] * r[vertex];
    sum.cg += r[vertex].dot(s[vertex]);
    sum.stop += stopTerm(weights, vertex, r[vertex], s[vertex]);
    sum.scale += massTerm(weights, vertex, deltaV[vertex]);
    sum.progress += progressTerm(weights, vertex, deltaV[vertex], slot);
  }
  return sum;
}

// --- Multicolour symmetric Gauss–Seidel with Eisenstat's trick (header, "Gauss–Seidel"). With
// --- Ã = L̃ + D̃ + Ũ split by colour (L̃: blocks to earlier colours), P_L = D̃ + L̃, P_U = D̃ + Ũ = P_Lᵀ.
// --- A sweep over one colour's vertices order[begin … end) reads only other colours' entries,
// --- which earlier colours (forward) or later colours (backward) have finished; vertices of one
// --- colour share no block, so a colour's vertices can run in any order or at once. S_i on every
// --- output keeps the vectors exactly in the free subspace (exact zeros for fixed vertices).

/// Copies the blocks of the entries of sweep positions [begin, end) of one triangle into packed
/// order: general blocks whole, isotropic ones as their scalar.
void packTriangleRange(Index begin, Index end, const BlockSparseMatrix& A,
                       const SweepTriangle& entries, PackedTriangle& packed) {
  const SweepEntries& general = entries.general;
  for (Index e = general.begin(begin), last = general.begin(end); e < last; ++e) {
    packed.general[e] = A.block(general.slots[e]);
  }
  const SweepEntries& isotropic = entries.isotropic;
  for (Index e = isotropic.begin(begin), last = isotropic.begin(end); e < last; ++e) {
    const Mat3& block = A.block(isotropic.slots[e]);
    assert(block == block(0, 0) * Mat3::Identity() && "an isotropic slot holds a general block");
    packed.isotropic[e] = block(0, 0);
  }
}

/// Σ_j A_ij x_j over one triangle's entries of sweep position k: general blocks, then isotropic.
/// Always inlined: it is the inner loop of every sweep, and a call per row costs a tenth of it.
[[gnu::always_inline]] inline Vec3 triangleProduct(Index k, const SweepTriangle& entries,
                                                   const PackedTriangle& packed,
                                                   const Vec3Array& x) {
  Vec3 sum = Vec3::Zero();
  const SweepEntries& general = entries.general;
  const Index* columns = general.columns.data();
  const Mat3* blocks = packed.general.data();
  for (Index e = general.begin(k), last = general.begin(k + 1); e < last; ++e) {
    sum.noalias() += blocks[e] * x[columns[e]];
  }
  const SweepEntries& isotropic = entries.isotropic;
  columns = isotropic.columns.data();
  const Real* scalars = packed.isotropic.data();
  for (Index e = isotropic.begin(k), last = isotropic.begin(k + 1); e < last; ++e) {
    sum += scalars[e] * x[columns[e]];
  }
  return sum;
}

/// Backward sweep over sweep positions [begin, end) of one colour, t = P_U⁻¹ c:
/// t_i = D̃_i⁻¹(c_i − Σ_{later j} A_ij t_j), and u_i = S_i Σ_{later j} A_ij t_j = c_i − D̃_i t_i, the
/// input of the forward sweep (stored in w).
void backwardSweepRange(Index begin, Index end, const PackedTriangle& upper,
                        const MulticolorOrdering& ordering, const VertexFilter& filter,
                        const std::vector<Mat3>& inverseDiagonal, const Vec3Array& c, Vec3Array& t,
                        Vec3Array& w) {
  for (Index k = begin; k < end; ++k) {
    const Index vertex = ordering.order()[k];
    const Vec3 sum = triangleProduct(k, ordering.upper(), upper, t);
    t[vertex] = filter.filter(vertex, inverseDiagonal[vertex] * (c[vertex] - sum));
    w[vertex] = filter.filter(vertex, sum);
  }
}

/// Forward sweep over sweep positions [begin, end) of one colour, in place, w = P_L⁻¹ w:
/// w_i = D̃_i⁻¹(w_i − Σ_{earlier j} A_ij w_j). With curvature, terms[k] = c_iᵀ(t_i + w_i) for each
/// position k of the range (summed to ĉᵀÂĉ, Â = P_L⁻¹ Ã P_U⁻¹, in a fixed order after the sweep).
template <bool curvature>
void forwardSweepRange(Index begin, Index end, const PackedTriangle& lower,
                       const MulticolorOrdering& ordering, const VertexFilter& filter,
                       const std::vector<Mat3>& inverseDiagonal, const Vec3Array& c,
                       const Vec3Array& t, Vec3Array& w, Real* terms) {
  for (Index k = begin; k < end; ++k) {
    const Index vertex = ordering.order()[k];
    const Vec3 rest = w[vertex] - triangleProduct(k, ordering.lower(), lower, w);
    const Vec3 result = filter.filter(vertex, inverseDiagonal[vertex] * rest);
    w[vertex] = result;
    if constexpr (curvature) terms[k] = c[vertex].dot(t[vertex] + result);
  }
}

/// The forward sweep of M_SGS⁻¹ r over sweep positions [begin, end) of one colour:
/// w = P_L⁻¹ r (w_i = D̃_i⁻¹(r_i − Σ_{earlier j} A_ij w_j)) and y_i = S_i D̃_i w_i, the input of the
/// backward sweep, in the same pass.
void forwardSweepWithDiagonalRange(Index begin, Index end, const PackedTriangle& lower,
                          const MulticolorOrdering& ordering, const VertexFilter& filter,
                          const std::vector<Mat3>& inverseDiagonal,
                          const std::vector<Mat3>& diagonal, const Vec3Array& r, Vec3Array& w,
                          Vec3Array& y) {
  for (Index k = begin; k < end; ++k) {
    const Index vertex = ordering.order()[k];
    const Vec3 rest = r[vertex] - triangleProduct(k, ordering.lower(), lower, w);
    w[vertex] = filter.filter(vertex, inverseDiagonal[vertex] * rest);
    y[vertex] = filter.filter(vertex, diagonal[vertex] * w[vertex]);
  }
}

/// q = S Ã c = S(D̃ c + L̃ c + Ũ c) over sweep positions [begin, end), from the packed blocks (half
/// the bytes of A's own); returns Σ cᵀq over the positions in order.
Real packedProductRange(Index begin, Index end, const PackedTriangle& lower,
                        const PackedTriangle& upper, const MulticolorOrdering& ordering,
                        const std::vector<Mat3>& diagonal, const VertexFilter& filter,
                        const Vec3Array& c, Vec3Array& q) {
  Real sum = 0;
  for (Index k = begin; k < end; ++k) {
    const Index vertex = ordering.order()[k];
    Vec3 product = diagonal[vertex] * c[vertex];
    product += triangleProduct(k, ordering.lower(), lower, c);
    product += triangleProduct(k, ordering.upper(), upper, c);
    q[vertex] = filter.filter(vertex, product);
    sum += c[vertex].dot(q[vertex]);
  }
  return sum;
}

/// ŝ = D̃ r̂ over the range (the transformed system's preconditioner); returns Σ r̂ᵀŝ.
Real diagonalRange(Index begin, Index end, const std::vector<Mat3>& diagonal,
                   const VertexFilter& filter, const Vec3Array& r, Vec3Array& s) {
  Real sum = 0;
  for (Index vertex = begin; vertex < end; ++vertex) {
    s[vertex] = filter.filter(vertex, diagonal[vertex] * r[vertex]);
    sum += r[vertex].dot(s[vertex]);
  }
  return sum;
}

/// Δv += α t, r̂ −= α (t + w), ŝ = D̃ r̂ over the range; returns Σ r̂ᵀŝ, ‖Δv‖²_M and the progress
/// over the last window (when the slot measures).
PassSums transformedUpdateRange(Index begin, Index end, Real alpha,
                                const std::vector<Mat3>& diagonal,
                                const VertexFilter& filter, const MassWeights& weights,
                                const Vec3Array& t, const Vec3Array& w, Vec3Array& deltaV,
                                Vec3Array& r, Vec3Array& s, const ProgressSlot& slot) {
  PassSums sum;
  for (Index vertex = begin; vertex < end; ++vertex) {
    deltaV[vertex] += alpha * t[vertex];
    r[vertex] -= alpha * (t[vertex] + w[vertex]);
    s[vertex] = filter.filter(vertex, diagonal[vertex] * r[vertex]);
    sum.cg += r[vertex].dot(s[vertex]);
    sum.scale += massTerm(weights, vertex, deltaV[vertex]);
    sum.progress += progressTerm(weights, vertex, deltaV[vertex], slot);
  }
  return sum;
}

/// The true residual r = P_L r̂ = ŝ + S L̃ r̂ (ŝ = D̃ r̂) over sweep positions [begin, end); returns
/// Σ rᵀD̃⁻¹r (cg) and the stopping norm² (stop: the same, or Σ rᵀM⁻¹r for the velocity test).
/// Positions are independent: any split gives the same bits.
PassSums untransformedNormRange(Index begin, Index end, const PackedTriangle& lower,
                                const MulticolorOrdering& ordering, const VertexFilter& filter,
                                const std::vector<Mat3>& inverseDiagonal,
                                const MassWeights& weights, const Vec3Array& r,
                                const Vec3Array& s) {
  PassSums sum;
  for (Index k = begin; k < end; ++k) {
    const Index vertex = ordering.order()[k];
    const Vec3 product = triangleProduct(k, ordering.lower(), lower, r);
    const Vec3 residual = s[vertex] + filter.filter(vertex, product);
    sum.cg += residual.dot(inverseDiagonal[vertex] * residual);
    sum.stop += weights.active() ? weights.inverseMass[vertex] * residual.squaredNorm()
                                 : residual.dot(inverseDiagonal[vertex] * residual);
  }
  return sum;
}

/// c = S(s + β c) over the range. s and c are in the free subspace already; filtering again
/// removes the rounding that would otherwise let constrained components creep.
void directionRange(Index begin, Index end, Real beta, const VertexFilter& filter,
                    const Vec3Array& s, Vec3Array& c) {
  for (Index vertex = begin; vertex < end; ++vertex) {
    c[vertex] = filter.filter(vertex, s[vertex] + beta * c[vertex]);
  }
}

}  // namespace

void FilteredPcg::resize(Index vertexCount) {
  m_residual.assign(vertexCount, Vec3::Zero());
  m_preconditioned.assign(vertexCount, Vec3::Zero());
  m_direction.assign(vertexCount, Vec3::Zero());
  m_product.assign(vertexCount, Vec3::Zero());
  m_backward.assign(vertexCount, Vec3::Zero());
  m_diagonal.assign(vertexCount, Mat3::Zero());
  m_inverseDiagonal.assign(vertexCount, Mat3::Zero());
  m_inverseMass.assign(vertexCount, 0);
  m_stopMass.assign(vertexCount, 0);
  // The velocity test's ring for the default window; a longer window grows it in solve().
  m_progressRing.assign(std::size_t(PcgSettings{}.progressWindow) * std::size_t(vertexCount),
                        Vec3::Zero());
  m_blockPartials.assign((vertexCount + kReductionBlock - 1) / kReductionBlock, 0);
  m_sweepTerms.assign(vertexCount, 0);
  m_couplingDiagonal.assign(vertexCount, Mat3::Zero());
  m_couplingProduct.assign(vertexCount, Vec3::Zero());
  m_couplingMark.assign(vertexCount, 0);
  m_couplingRows.clear();
}

template <typename Kernel>
auto FilteredPcg::sumOverBlocks(Index count, Kernel&& kernel) {
  using Sum = decltype(kernel(Index(0), Index(0)));
  if (m_tasks) {
    // Fixed blocks, partials combined in block order: the same bits as the loop below.
    return m_tasks->parallelReduce(
        count, kReductionBlock, Sum{},
        [&](Index begin, Index end) { return kernel(begin, end); },
        [](const Sum& sum, const Sum& partial) { return sum + partial; });
  }
  // Combine in block order, starting from zero: the one summation order, whatever the thread count.
  Sum sum{};
  for (Index begin = 0; begin < count; begin += kReductionBlock) {
    sum = sum + kernel(begin, std::min(begin + kReductionBlock, count));
  }
  return sum;
}

template <typename Kernel>
void FilteredPcg::forEachColourChunk(Index count, Kernel&& kernel) {
  const Index threads = m_tasks ? Index(m_tasks->threadCount()) : 1;
  if (threads <= 1 || count < 2 * kMinSweepChunk) {
    kernel(Index(0), count);
    return;
  }
  const Index chunk = std::max(kMinSweepChunk, (count + threads - 1) / threads);
  m_tasks->parallelFor(count, chunk, [&](Index begin, Index end, int) { kernel(begin, end); });
}

template <typename Kernel>
void FilteredPcg::forEachBlock(Index count, Kernel&& kernel) {
  // parallelFor runs a single block inline (no fork).
  if (m_tasks) {
    m_tasks->parallelFor(count, kReductionBlock,
                         [&](Index begin, Index end, int) { kernel(begin, end); });
    return;
  }
  for (Index begin = 0; begin < count; begin += kReductionBlock) {
    kernel(begin, std::min(begin + kReductionBlock, count));
  }
}

void FilteredPcg::prepareGaussSeidel(const BlockSparseMatrix& A) {
  if (!m_ordering.matches(A, m_rowColors)) {
    // A new pattern or colouring (set-up, or a topology change): order it, size the packed
    // blocks. Allocates.
    m_ordering.build(A, m_rowColors);
    for (auto [entries, packed] : {std::pair{&m_ordering.lower(), &m_lowerBlocks},
                                   std::pair{&m_ordering.upper(), &m_upperBlocks}}) {
      packed->general.resize(entries->general.size());
      packed->isotropic.resize(entries->isotropic.size());
    }
  }
  forEachBlock(A.blockRows(), [&](Index begin, Index end) {
    packTriangleRange(begin, end, A, m_ordering.lower(), m_lowerBlocks);
    packTriangleRange(begin, end, A, m_ordering.upper(), m_upperBlocks);
  });
}

template <bool curvature>
Real FilteredPcg::forwardSweep(const VertexFilter& filter,
                               const Vec3Array& c, const Vec3Array& t, Vec3Array& w) {
  // Colour by colour; a colour's partial sums in block order, the colours' sums in colour order:
  // one summation order whatever the thread count.
  Real sum = 0;
  for (Index color = 0; color < m_ordering.colorCount(); ++color) {
    const Index first = m_ordering.colorBegin(color);
    const Index count = m_ordering.colorEnd(color) - first;
    forEachColourChunk(count, [&](Index begin, Index end) {
      forwardSweepRange<curvature>(first + begin, first + end, m_lowerBlocks, m_ordering, filter,
                                   m_inverseDiagonal, c, t, w, m_sweepTerms.data());
    });
    if constexpr (curvature) {
      // The terms in the colour's reduction blocks, as the sweep itself summed them.
      sum += sumOverBlocks(count, [&](Index begin, Index end) {
        Real partial = 0;
        for (Index k = first + begin; k < first + end; ++k) partial += m_sweepTerms[k];
        return partial;
      });
    }
  }
  return sum;
}

void FilteredPcg::backwardSweep(const VertexFilter& filter,
                                const Vec3Array& c, Vec3Array& t, Vec3Array& w) {
  for (Index color = m_ordering.colorCount(); color-- > 0;) {
    const Index first = m_ordering.colorBegin(color);
    forEachColourChunk(m_ordering.colorEnd(color) - first, [&](Index begin, Index end) {
      backwardSweepRange(first + begin, first + end, m_upperBlocks, m_ordering, filter,
                         m_inverseDiagonal, c, t, w);
    });
  }
}

void FilteredPcg::applyPreconditioner(const BlockSparseMatrix& A, const VertexFilter& filter,
                                      PreconditionerKind kind, const Vec3Array& r, Vec3Array& z,
                                      TaskSystem* tasks) {
  m_couplings = {};
  const Index vertexCount = A.blockRows();
  m_tasks = tasksFor(vertexCount, tasks);
  if (m_residual.size() != vertexCount) resize(vertexCount);
  z.resize(vertexCount);
  forEachBlock(vertexCount, [&](Index begin, Index end) {
    buildPreconditionerRange(begin, end, A, filter, m_diagonal, m_inverseDiagonal);
  });
  if (kind == PreconditionerKind::BlockJacobi) {
    for (Index vertex = 0; vertex < vertexCount; ++vertex) z[vertex] = m_inverseDiagonal[vertex] * r[vertex];
    return;
  }
  prepareGaussSeidel(A);
  if (kind == PreconditionerKind::TwoLevelGaussSeidel) {
    m_coarseSpace.assemble(A, filter, m_tasks);
    applyTwoLevel(filter, r, z);
  } else {
    applySymmetricGaussSeidel(filter, r, z);
  }
}

void FilteredPcg::prepareCouplings(const BlockSparseMatrix& A, const VertexFilter& filter) {
  for (Index row : m_couplingRows) {
    m_couplingDiagonal[row].setZero();
    m_couplingProduct[row].setZero();
    m_couplingMark[row] = 0;
  }
  m_couplingRows.clear();  // keeps its capacity: grows only with the most contacts seen
  for (const ContactCoupling& term : m_couplings) {
    for (int k = 0; k < 4; ++k) {
      const Index row = term.rows[k];
      if (row == kInvalidIndex) continue;
      if (!m_couplingMark[row]) {
        m_couplingMark[row] = 1;
        m_couplingRows.push_back(row);
      }
      m_couplingDiagonal[row] += couplingDiagonalBlock(term, k);
    }
  }
  // D̃' = blocks of A + E: the rows a coupling touches get the inverse of their summed block.
  for (Index row : m_couplingRows) {
    m_inverseDiagonal[row] =
        preconditionerBlock(A.block(A.diagonalSlot(row)) + m_couplingDiagonal[row], filter, row);
  }
}

const Vec3Array* FilteredPcg::couplingProduct(const Vec3Array& x, bool offDiagonalOnly) {
  if (m_couplings.empty()) return nullptr;
  for (Index row : m_couplingRows) m_couplingProduct[row].setZero();
  addCouplingProduct(m_couplings, x, m_couplingProduct, offDiagonalOnly);
  return &m_couplingProduct;
}

Real FilteredPcg::addCouplingDiagonal(const VertexFilter& filter, const Vec3Array& r, Vec3Array& s) {
  // The touched rows are the last solve's: without couplings now (applyPreconditioner) they are
  // stale, and E adds nothing.
  if (m_couplings.empty()) return 0;
  Real sum = 0;
  for (Index row : m_couplingRows) {
    const Vec3 extra = filter.filter(row, m_couplingDiagonal[row] * r[row]);
    s[row] += extra;
    sum += r[row].dot(extra);
  }
  return sum;
}

SolveReport FilteredPcg::solve(const BlockSparseMatrix& A, const Vec3Array& b,
                               const VertexFilter& filter, const PcgSettings& settings,
                               Vec3Array& deltaV, TaskSystem* tasks,
                               std::span<const Real> masses,
                               std::span<const ContactCoupling> couplings) {
  SolveReport report;
  m_couplings = {};
  const Index vertexCount = A.blockRows();
  m_tasks = tasksFor(vertexCount, tasks);
  const bool velocityTest = settings.stopping == PcgStopping::VelocityError;
  // Validated rather than asserted: the contract says a mismatch is reported, not undefined.
  if (b.size() != vertexCount || filter.size() != vertexCount ||
      (velocityTest && masses.size() != std::size_t(vertexCount))) {
    report.relativeResidual = std::numeric_limits<Real>::quiet_NaN();
    report.residualNorm = std::numeric_limits<Real>::quiet_NaN();
    return report;
  }
  for (const ContactCoupling& term : couplings) {
    for (Index row : term.rows) {
      if (row != kInvalidIndex && row >= vertexCount) {
        report.relativeResidual = std::numeric_limits<Real>::quiet_NaN();
        report.residualNorm = std::numeric_limits<Real>::quiet_NaN();
        return report;
      }
    }
  }
  if (m_residual.size() != vertexCount) resize(vertexCount);  // allocates only on a size change
  bool warmStart = settings.warmStart;
  if (deltaV.size() != vertexCount) {
    deltaV.assign(vertexCount, Vec3::Zero());
    warmStart = false;
  }

  Vec3Array& r = m_residual;
  Vec3Array& s = m_preconditioned;
  Vec3Array& c = m_direction;

  forEachBlock(vertexCount, [&](Index begin, Index end) {
    buildPreconditionerRange(begin, end, A, filter, m_diagonal, m_inverseDiagonal);
  });
  m_couplings = couplings;
  prepareCouplings(A, filter);
  const bool gaussSeidel = settings.preconditioner == PreconditionerKind::MulticolorGaussSeidel;
  const bool twoLevel = settings.preconditioner == PreconditionerKind::TwoLevelGaussSeidel;
  // The colouring and the aggregates depend on the pattern only: rebuilt (allocating) when the
  // topology changes. The coarse matrix is assembled and factorised every solve.
  if (gaussSeidel || twoLevel) prepareGaussSeidel(A);
  if (twoLevel) m_coarseSpace.assemble(A, filter, m_tasks);

  // The velocity test's weights: m_i and 1/m_i on vertices with a free direction, zero on fixed
  // ones (and on a massless row, which a valid system does not have). Σm is the mass that moves.
  MassWeights weights;
  Real movingMass = 0;
  if (velocityTest) {
    for (Index vertex = 0; vertex < vertexCount; ++vertex) {
      const Real mass = masses[vertex];
      const bool counts = filter.kind(vertex) != ConstraintKind::Fixed && mass > 0 && std::isfinite(mass);
      m_stopMass[vertex] = counts ? mass : Real(0);
      m_inverseMass[vertex] = counts ? 1 / mass : Real(0);
      movingMass += m_stopMass[vertex];
    }
    weights = MassWeights{m_stopMass.data(), m_inverseMass.data()};
  }

  // The relative-residual test's reference r_ref = S(b − A(I − S)z). A cold start begins exactly
  // there, so it is the initial residual; a warm start needs it separately, and needs the SpMV only
  // when some target is nonzero. The velocity test needs no reference.
  Real referenceDelta = 0;
  if (warmStart) {
    const Real targetSquaredNorm = sumOverBlocks(vertexCount, [&](Index begin, Index end) {
      return targetRange(begin, end, filter, c);
    });
    referenceDelta =
        (targetSquaredNorm == 0
             ? sumOverBlocks(vertexCount,
                             [&](Index begin, Index end) {
                               return rightHandSideRange(begin, end, b, filter, m_inverseDiagonal,
                                                         weights, r, s);
                             })
             : [&] {
                 const Vec3Array* coupled = couplingProduct(c);
                 return sumOverBlocks(vertexCount, [&](Index begin, Index end) {
                   return residualRange(begin, end, A, b, filter, m_inverseDiagonal, weights, c, r,
                                        s, coupled);
                 });
               }())
            .cg;
  }

  forEachBlock(vertexCount,
               [&](Index begin, Index end) { startRange(begin, end, filter, warmStart, deltaV); });
  // start.stop drives the stopping rule; start.cg = rᵀs = rᵀP⁻¹r drives CG. They are one number
  // for the relative-residual test with block Jacobi (s = D̃⁻¹r).
  const Vec3Array* coupled = couplingProduct(deltaV);
  const PassSums start = sumOverBlocks(vertexCount, [&](Index begin, Index end) {
    return residualRange(begin, end, A, b, filter, m_inverseDiagonal, weights, deltaV, r, s,
                         coupled);
  });
  if (!warmStart) referenceDelta = start.cg;

  Stopping stopping;
  stopping.velocityTest = velocityTest;
  stopping.tolerance = settings.tolerance;
  stopping.absoluteTolerance = settings.absoluteTolerance;
  stopping.maxIterations = settings.maxIterations;
  // rᵀP̃⁻¹r ≥ 0 in exact arithmetic; clamp rounding below zero before the square root.
  stopping.referenceNorm = std::sqrt(std::max(referenceDelta, Real(0)));
  stopping.referenceFinite = std::isfinite(referenceDelta) && std::isfinite(movingMass);
  if (velocityTest) {
    stopping.scaleFloor = std::max(settings.velocityFloor, Real(0)) * std::sqrt(movingMass);
    stopping.window = std::clamp(settings.progressWindow, 1, 1 << 20);
    // Iterate k writes slot k mod w, k ≤ maxIterations: a window beyond the cap needs only
    // maxIterations + 1 slots (and never measures). Grows (allocates) only for a window longer
    // than the default one resize() made room for.
    const std::size_t slots =
        std::size_t(std::min(stopping.window, std::max(settings.maxIterations, 0) + 1));
    if (m_progressRing.size() < slots * std::size_t(vertexCount)) {
      m_progressRing.resize(slots * std::size_t(vertexCount));
    }
  }
  if (gaussSeidel) {
    iterateGaussSeidel(A, filter, weights, stopping, start, deltaV, report);
  } else {
    iterateJacobi(A, filter, weights, stopping, start, twoLevel, deltaV, report);
  }
  return report;
}

Real FilteredPcg::Stopping::scale(Real solutionSquaredNorm) const {
  if (!velocityTest) return referenceNorm;
  return std::max(std::sqrt(std::max(solutionSquaredNorm, Real(0))), scaleFloor);
}

Real FilteredPcg::Stopping::threshold(Real solutionSquaredNorm) const {
  return std::max(tolerance * scale(solutionSquaredNorm), absoluteTolerance);
}

/// Fills the report's residual fields and says whether the solve has converged.
bool FilteredPcg::Stopping::judge(Real stopDelta, Real residualDelta, Real solutionSquaredNorm,
                                  Real progressSquared, SolveReport& report) const {
  // NaN compares false with everything, so test finiteness first: a NaN residual must end the
  // loop as a failure, never look converged and never spin until the cap.
  if (!referenceFinite || !std::isfinite(stopDelta) || !std::isfinite(residualDelta) ||
      !std::isfinite(solutionSquaredNorm) || std::isnan(progressSquared)) {
    report.residualNorm = std::numeric_limits<Real>::quiet_NaN();
    report.relativeResidual = std::numeric_limits<Real>::quiet_NaN();
    report.converged = false;
    return false;
  }
  report.residualNorm = std::sqrt(std::max(stopDelta, Real(0)));
  const Real goal = threshold(solutionSquaredNorm);
  Real error = report.residualNorm;
  bool converged = error <= goal;
  if (velocityTest && progressSquared >= 0) {
    // The window's progress counts only where the block-Jacobi residual agrees (header,
    // "Stopping"): each covers the other's blind spot.
    const Real progress = std::sqrt(progressSquared);
    const bool residualAgrees = std::sqrt(std::max(residualDelta, Real(0))) <=
                                std::max(tolerance * referenceNorm, absoluteTolerance);
    if (residualAgrees) {
      error = std::min(error, progress);
      converged = converged || progress <= goal;
    }
  }
  const Real denominator = std::max(scale(solutionSquaredNorm), absoluteTolerance);
  // A zero denominator needs absoluteTolerance = 0 and a zero scale; avoid 0/0 there.
  report.relativeResidual = denominator > 0 ? error / denominator
                            : error == 0   ? Real(0)
                                           : std::numeric_limits<Real>::infinity();
  report.converged = converged;
  return converged;
}

void FilteredPcg::applySymmetricGaussSeidel(const VertexFilter& filter, const Vec3Array& r,
                                            Vec3Array& z) {
  Vec3Array& w = m_product;
  Vec3Array& y = m_backward;
  // w = P_L⁻¹ r and y = D̃ w in one pass, colour by colour.
  for (Index color = 0; color < m_ordering.colorCount(); ++color) {
    const Index first = m_ordering.colorBegin(color);
    forEachColourChunk(m_ordering.colorEnd(color) - first, [&](Index begin, Index end) {
      forwardSweepWithDiagonalRange(first + begin, first + end, m_lowerBlocks, m_ordering, filter,
                                    m_inverseDiagonal, m_diagonal, r, w, y);
    });
  }
  addCouplingDiagonal(filter, w, y);  // y = D̃' w
  backwardSweep(filter, y, z, w);     // z = P_U⁻¹ y; w is scratch
}

Real FilteredPcg::applyTwoLevel(const VertexFilter& filter, const Vec3Array& r, Vec3Array& z) {
  const Index vertexCount = Index(r.size());
  applySymmetricGaussSeidel(filter, r, z);
  // The coarse correction's pass also sums rᵀz; without a factorised A_c, a pass of its own.
  if (m_coarseSpace.factorised()) return m_coarseSpace.addCorrection(filter, r, z, m_tasks);
  return sumOverBlocks(vertexCount, [&](Index begin, Index end) {
    Real sum = 0;
    for (Index vertex = begin; vertex < end; ++vertex) sum += r[vertex].dot(z[vertex]);
    return sum;
  });
}

void FilteredPcg::iterateJacobi(const BlockSparseMatrix& A, const VertexFilter& filter,
                                const FilteredPcgMassWeights& weights, const Stopping& stopping,
                                const FilteredPcgPassSums& start, bool twoLevel,
                                Vec3Array& deltaV, SolveReport& report) {
  const Index vertexCount = A.blockRows();
  Vec3Array& r = m_residual;
  Vec3Array& s = m_preconditioned;
  Vec3Array& c = m_direction;
  Vec3Array& q = m_product;
  // rᵀP⁻¹r, CG's own measure: the block-Jacobi sum of the pass, or the two-level one, for which
  // s is overwritten with P⁻¹r once the pass has summed rᵀD̃⁻¹r for the stopping test.
  Real delta = twoLevel && start.cg > 0 ? applyTwoLevel(filter, r, s) : start.cg;
  forEachBlock(vertexCount, [&](Index begin, Index end) { copyRange(begin, end, s, c); });
  // The velocity test's progress window starts at the initial guess.
  if (stopping.velocityTest) {
    forEachBlock(vertexCount,
                 [&](Index begin, Index end) { copyRange(begin, end, deltaV, m_progressRing); });
  }

  PassSums sums = start;
  Real previousDelta = delta;
  for (;;) {
    // The progress over the last window, once w iterations have run (header, "Stopping").
    const bool windowFull = stopping.velocityTest && report.iterations >= stopping.window;
    if (stopping.judge(sums.stop, sums.cg, sums.scale, windowFull ? sums.progress : Real(-1),
                       report) ||
        !std::isfinite(report.residualNorm)) {
      break;
    }
    if (report.iterations >= stopping.maxIterations) break;

    if (report.iterations > 0) {
      const Real beta = delta / previousDelta;
      forEachBlock(vertexCount, [&](Index begin, Index end) {
        directionRange(begin, end, beta, filter, s, c);
      });
    }
    Real curvature = sumOverBlocks(vertexCount, [&](Index begin, Index end) {
      return twoLevel ? packedProductRange(begin, end, m_lowerBlocks, m_upperBlocks, m_ordering,
                                           m_diagonal, filter, c, q)
                      : filteredProductRange(begin, end, A, filter, c, q);
    });
    // q += S E c over the rows the contact couplings touch (serially, in a fixed order).
    if (const Vec3Array* coupled = couplingProduct(c)) {
      for (Index row : m_couplingRows) {
        const Vec3 extra = filter.filter(row, (*coupled)[row]);
        q[row] += extra;
        curvature += c[row].dot(extra);
      }
    }
    // cᵀAc ≤ 0 means A is not positive definite on the free subspace (or q holds a NaN): CG has
    // broken down. Stop before touching Δv, so it keeps the last finite iterate.
    if (!(curvature > 0) || !std::isfinite(curvature)) {
      if (!std::isfinite(curvature)) {
        report.residualNorm = std::numeric_limits<Real>::quiet_NaN();
        report.relativeResidual = std::numeric_limits<Real>::quiet_NaN();
      }
      break;
    }
    const Real alpha = delta / curvature;
    previousDelta = delta;
    const ProgressSlot slot = ringSlot(m_progressRing, vertexCount, stopping.velocityTest,
                                       stopping.window, report.iterations + 1);
    sums = sumOverBlocks(vertexCount, [&](Index begin, Index end) {
      return updateRange(begin, end, alpha, c, q, m_inverseDiagonal, weights, deltaV, r, s,
                         slot);
    });
    delta = twoLevel && sums.cg > 0 ? applyTwoLevel(filter, r, s) : sums.cg;
    ++report.iterations;
  }
}

void FilteredPcg::iterateGaussSeidel(const BlockSparseMatrix& A, const VertexFilter& filter,
                                     const FilteredPcgMassWeights& weights, const Stopping& stopping,
                                     const FilteredPcgPassSums& start, Vec3Array& deltaV,
                                     SolveReport& report) {
  const Index vertexCount = A.blockRows();
  Vec3Array& r = m_residual;        // r̂ = P_L⁻¹ r
  Vec3Array& s = m_preconditioned;  // ŝ = D̃ r̂
  Vec3Array& c = m_direction;       // ĉ
  Vec3Array& t = m_backward;        // t = P_U⁻¹ ĉ, the search direction in Δv's space
  Vec3Array& w = m_product;         // u, then w = P_L⁻¹ u; Â ĉ = t + w

  // The start's residual is exact (residualRange); a bad one ends the solve before any sweep.
  Real solutionSquaredNorm = start.scale;
  if (stopping.judge(start.stop, start.cg, solutionSquaredNorm, -1, report) ||
      !std::isfinite(report.residualNorm)) {
    return;
  }
  if (stopping.maxIterations <= 0) return;
  if (stopping.velocityTest) {
    forEachBlock(vertexCount,
                 [&](Index begin, Index end) { copyRange(begin, end, deltaV, m_progressRing); });
  }

  forwardSweep<false>(filter, c, t, r);  // r̂ = P_L⁻¹ r, in place
  Real delta = sumOverBlocks(vertexCount, [&](Index begin, Index end) {
    return diagonalRange(begin, end, m_diagonal, filter, r, s);
  });
  delta += addCouplingDiagonal(filter, r, s);  // ŝ = D̃' r̂ with the couplings' diagonal blocks
  forEachBlock(vertexCount, [&](Index begin, Index end) { copyRange(begin, end, s, c); });
  // ‖r‖²_{M⁻¹} = r̂ᵀD̃r̂ = delta (M the SGS preconditioner) falls with CG's iterations; its ratio to
  // the start scales the start's exact stopping norm into an estimate, and the exact norm (one
  // half-SpMV) is computed only once the estimate is below the threshold.
  const Real startDelta = delta;
  const Real startNorm = report.residualNorm;
  auto exactNorms = [&] {
    return sumOverBlocks(vertexCount, [&](Index begin, Index end) {
      return untransformedNormRange(begin, end, m_lowerBlocks, m_ordering, filter,
                                    m_inverseDiagonal, weights, r, s);
    });
  };

  Real previousDelta = delta;
  Real progress = -1;  // the velocity test's window progress², when a window has just ended
  for (;;) {
    if (!std::isfinite(delta)) {
      stopping.judge(std::numeric_limits<Real>::quiet_NaN(), std::numeric_limits<Real>::quiet_NaN(),
                     solutionSquaredNorm, -1, report);
      break;
    }
    if (report.iterations > 0) {
      // The velocity test's window progress is free (fused into the update); when it meets the
      // threshold, the exact residual (half an SpMV) says whether the residual test agrees.
      const Real estimate =
          startDelta > 0 ? startNorm * std::sqrt(std::max(delta, Real(0)) / startDelta) : Real(0);
      const bool windowMet =
          progress >= 0 && std::sqrt(progress) <= stopping.threshold(solutionSquaredNorm);
      if (windowMet || estimate <= stopping.threshold(solutionSquaredNorm) ||
          report.iterations >= stopping.maxIterations) {
        const PassSums exact = exactNorms();
        if (stopping.judge(exact.stop, exact.cg, solutionSquaredNorm, progress, report) ||
            !std::isfinite(report.residualNorm)) {
          break;
        }
      }
      if (report.iterations >= stopping.maxIterations) break;
      const Real beta = delta / previousDelta;
      forEachBlock(vertexCount, [&](Index begin, Index end) {
        directionRange(begin, end, beta, filter, s, c);
      });
    }
    backwardSweep(filter, c, t, w);
    // u = ĉ − D̃' t + S E_off t: the couplings' off-diagonal blocks, which the sweeps do not hold.
    if (const Vec3Array* coupled = couplingProduct(t, /*offDiagonalOnly=*/true)) {
      for (Index row : m_couplingRows) w[row] += filter.filter(row, (*coupled)[row]);
    }
    const Real curvature = forwardSweep<true>(filter, c, t, w);
    // ĉᵀÂĉ ≤ 0: breakdown (A not positive definite on the free subspace, or a NaN). Δv keeps the
    // last finite iterate; the report gets that iterate's exact residual.
    if (!(curvature > 0) || !std::isfinite(curvature)) {
      if (!std::isfinite(curvature)) {
        stopping.judge(std::numeric_limits<Real>::quiet_NaN(), std::numeric_limits<Real>::quiet_NaN(),
                     solutionSquaredNorm, -1, report);
      } else if (report.iterations > 0) {
        const PassSums exact = exactNorms();
        stopping.judge(exact.stop, exact.cg, solutionSquaredNorm, -1, report);
      }
      report.converged = false;
      break;
    }
    const Real alpha = delta / curvature;
    previousDelta = delta;
    const ProgressSlot slot = ringSlot(m_progressRing, vertexCount, stopping.velocityTest,
                                       stopping.window, report.iterations + 1);
    const PassSums sums = sumOverBlocks(vertexCount, [&](Index begin, Index end) {
      return transformedUpdateRange(begin, end, alpha, m_diagonal, filter, weights, t, w, deltaV,
                                    r, s, slot);
    });
    delta = sums.cg + addCouplingDiagonal(filter, r, s);
    solutionSquaredNorm = sums.scale;
    progress = slot.measure ? sums.progress : Real(-1);
    ++report.iterations;
  }
}

}  // namespace weft
