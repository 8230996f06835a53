// FilteredPcg: BW98 §5.3 modified PCG. See the design note in the header for the method, the
// stopping rule and the determinism scheme; the kernels below are the per-range sweeps it runs.
#include <solver/FilteredPcg.h>
#include <solver/MulticolorOrdering.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace weft {

namespace {

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

/// P̃_i⁻¹ for every vertex of the range.
void buildPreconditionerRange(Index begin, Index end, const BlockSparseMatrix& A,
                              const VertexFilter& filter, std::vector<Mat3>& inverseDiagonal) {
  for (Index vertex = begin; vertex < end; ++vertex) {
    const Mat3& diagonal = A.block(A.diagonalSlot(vertex));
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
    inverseDiagonal[vertex] = Real(0.5) * (inverse + inverse.transpose());
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

/// r = S b, s = P̃⁻¹ r over the range; returns Σ rᵀs (the residual of a zero start).
Real rightHandSideRange(Index begin, Index end, const Vec3Array& b, const VertexFilter& filter,
                        const std::vector<Mat3>& inverseDiagonal, Vec3Array& r, Vec3Array& s) {
  Real sum = 0;
  for (Index vertex = begin; vertex < end; ++vertex) {
    r[vertex] = filter.filter(vertex, b[vertex]);
    s[vertex].noalias() = inverseDiagonal[vertex] * r[vertex];
    sum += r[vertex].dot(s[vertex]);
  }
  return sum;
}

/// r = S(b − A x), s = P̃⁻¹ r over the range; returns Σ rᵀs.
Real residualRange(Index begin, Index end, const BlockSparseMatrix& A, const Vec3Array& b,
                   const VertexFilter& filter, const std::vector<Mat3>& inverseDiagonal,
                   const Vec3Array& x, Vec3Array& r, Vec3Array& s) {
  Real sum = 0;
  for (Index vertex = begin; vertex < end; ++vertex) {
    r[vertex] = filter.filter(vertex, b[vertex] - A.multiplyRow(vertex, x));
    s[vertex].noalias() = inverseDiagonal[vertex] * r[vertex];
    sum += r[vertex].dot(s[vertex]);
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

/// Δv += α c, r −= α q, s = P̃⁻¹ r over the range; returns Σ rᵀs.
Real updateRange(Index begin, Index end, Real alpha, const Vec3Array& c, const Vec3Array& q,
                 const std::vector<Mat3>& inverseDiagonal, Vec3Array& deltaV, Vec3Array& r,
                 Vec3Array& s) {
  Real sum = 0;
  for (Index vertex = begin; vertex < end; ++vertex) {
    deltaV[vertex] += alpha * c[vertex];
    r[vertex] -= alpha * q[vertex];
    s[vertex].noalias() = inverseDiagonal[vertex] * r[vertex];
    sum += r[vertex].dot(s[vertex]);
  }
  return sum;
}

// --- Multicolour symmetric Gauss–Seidel with Eisenstat's trick (header, "Gauss–Seidel"). With
// --- Ã = L̃ + D̃ + Ũ split by colour (L̃: blocks to earlier colours), P_L = D̃ + L̃, P_U = D̃ + Ũ = P_Lᵀ.
// --- A sweep over one colour's vertices order[begin … end) reads only other colours' entries,
// --- which earlier colours (forward) or later colours (backward) have finished; vertices of one
// --- colour share no block, so a colour's vertices can run in any order or at once. S_i on every
// --- output keeps the vectors exactly in the free subspace (exact zeros for fixed vertices).

/// The off-diagonal blocks of A in the ordering's sweep order (lower and upper entries), copied
/// once per solve so the sweeps read them front to back.
struct PackedBlocks {
  const std::vector<Mat3>& lower;
  const std::vector<Mat3>& upper;
};

/// Copies the blocks of the entries of sweep positions [begin, end) into packed order.
void packRange(Index begin, Index end, const BlockSparseMatrix& A,
               const MulticolorOrdering& ordering, std::vector<Mat3>& lower,
               std::vector<Mat3>& upper) {
  for (Index e = ordering.lowerBegin(begin), last = ordering.lowerBegin(end); e < last; ++e) {
    lower[e] = A.block(ordering.lowerSlots()[e]);
  }
  for (Index e = ordering.upperBegin(begin), last = ordering.upperBegin(end); e < last; ++e) {
    upper[e] = A.block(ordering.upperSlots()[e]);
  }
}

/// Backward sweep over sweep positions [begin, end) of one colour, t = P_U⁻¹ c:
/// t_i = D̃_i⁻¹(c_i − Σ_{later j} A_ij t_j), and u_i = S_i Σ_{later j} A_ij t_j = c_i − D̃_i t_i, the
/// input of the forward sweep (stored in w).
void backwardSweepRange(Index begin, Index end, const PackedBlocks& blocks,
                        const MulticolorOrdering& ordering, const VertexFilter& filter,
                        const std::vector<Mat3>& inverseDiagonal, const Vec3Array& c, Vec3Array& t,
                        Vec3Array& w) {
  const Index* columns = ordering.upperColumns().data();
  const Mat3* upper = blocks.upper.data();
  for (Index k = begin; k < end; ++k) {
    const Index vertex = ordering.order()[k];
    Vec3 sum = Vec3::Zero();
    for (Index e = ordering.upperBegin(k), last = ordering.upperBegin(k + 1); e < last; ++e) {
      sum.noalias() += upper[e] * t[columns[e]];
    }
    t[vertex] = filter.filter(vertex, inverseDiagonal[vertex] * (c[vertex] - sum));
    w[vertex] = filter.filter(vertex, sum);
  }
}

/// Forward sweep over sweep positions [begin, end) of one colour, in place, w = P_L⁻¹ w:
/// w_i = D̃_i⁻¹(w_i − Σ_{earlier j} A_ij w_j). With curvature, returns Σ c_iᵀ(t_i + w_i) over the
/// range (ĉᵀÂĉ, Â = P_L⁻¹ Ã P_U⁻¹).
template <bool curvature>
Real forwardSweepRange(Index begin, Index end, const PackedBlocks& blocks,
                       const MulticolorOrdering& ordering, const VertexFilter& filter,
                       const std::vector<Mat3>& inverseDiagonal, const Vec3Array& c,
                       const Vec3Array& t, Vec3Array& w) {
  const Index* columns = ordering.lowerColumns().data();
  const Mat3* lower = blocks.lower.data();
  Real sum = 0;
  for (Index k = begin; k < end; ++k) {
    const Index vertex = ordering.order()[k];
    Vec3 rest = w[vertex];
    for (Index e = ordering.lowerBegin(k), last = ordering.lowerBegin(k + 1); e < last; ++e) {
      rest.noalias() -= lower[e] * w[columns[e]];
    }
    w[vertex] = filter.filter(vertex, inverseDiagonal[vertex] * rest);
    if constexpr (curvature) sum += c[vertex].dot(t[vertex] + w[vertex]);
  }
  return sum;
}

/// ŝ = D̃ r̂ over the range (the transformed system's preconditioner); returns Σ r̂ᵀŝ.
Real diagonalRange(Index begin, Index end, const BlockSparseMatrix& A, const VertexFilter& filter,
                   const Vec3Array& r, Vec3Array& s) {
  Real sum = 0;
  for (Index vertex = begin; vertex < end; ++vertex) {
    s[vertex] = filter.filter(vertex, A.block(A.diagonalSlot(vertex)) * r[vertex]);
    sum += r[vertex].dot(s[vertex]);
  }
  return sum;
}

/// Δv += α t, r̂ −= α (t + w), ŝ = D̃ r̂ over the range; returns Σ r̂ᵀŝ.
Real transformedUpdateRange(Index begin, Index end, Real alpha, const BlockSparseMatrix& A,
                            const VertexFilter& filter, const Vec3Array& t, const Vec3Array& w,
                            Vec3Array& deltaV, Vec3Array& r, Vec3Array& s) {
  Real sum = 0;
  for (Index vertex = begin; vertex < end; ++vertex) {
    deltaV[vertex] += alpha * t[vertex];
    r[vertex] -= alpha * (t[vertex] + w[vertex]);
    s[vertex] = filter.filter(vertex, A.block(A.diagonalSlot(vertex)) * r[vertex]);
    sum += r[vertex].dot(s[vertex]);
  }
  return sum;
}

/// The true residual r = P_L r̂ = ŝ + S L̃ r̂ (ŝ = D̃ r̂) over sweep positions [begin, end); returns
/// Σ rᵀD̃⁻¹r, the stopping norm². Positions are independent: any split gives the same bits.
Real untransformedNormRange(Index begin, Index end, const PackedBlocks& blocks,
                            const MulticolorOrdering& ordering, const VertexFilter& filter,
                            const std::vector<Mat3>& inverseDiagonal, const Vec3Array& r,
                            const Vec3Array& s) {
  const Index* columns = ordering.lowerColumns().data();
  const Mat3* lower = blocks.lower.data();
  Real sum = 0;
  for (Index k = begin; k < end; ++k) {
    const Index vertex = ordering.order()[k];
    Vec3 product = Vec3::Zero();
    for (Index e = ordering.lowerBegin(k), last = ordering.lowerBegin(k + 1); e < last; ++e) {
      product.noalias() += lower[e] * r[columns[e]];
    }
    const Vec3 residual = s[vertex] + filter.filter(vertex, product);
    sum += residual.dot(inverseDiagonal[vertex] * residual);
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
  m_inverseDiagonal.assign(vertexCount, Mat3::Zero());
  m_blockPartials.assign((vertexCount + kReductionBlock - 1) / kReductionBlock, 0);
}

template <typename Kernel>
Real FilteredPcg::sumOverBlocks(Index vertexCount, Kernel&& kernel) {
  const Index blockCount = (vertexCount + kReductionBlock - 1) / kReductionBlock;
  if (m_tasks) {
    // Fixed blocks, partials combined in block order: the same bits as the loop below.
    return m_tasks->parallelReduce(
        vertexCount, kReductionBlock, Real(0),
        [&](Index begin, Index end) { return kernel(begin, end); },
        [](Real sum, Real partial) { return sum + partial; });
  }
  for (Index block = 0; block < blockCount; ++block) {
    const Index begin = block * kReductionBlock;
    m_blockPartials[block] = kernel(begin, std::min(begin + kReductionBlock, vertexCount));
  }
  // Combine in block order: the one summation order, whatever the thread count.
  Real sum = 0;
  for (Index block = 0; block < blockCount; ++block) sum += m_blockPartials[block];
  return sum;
}

template <typename Kernel>
void FilteredPcg::forEachInRange(Index count, Kernel&& kernel) {
  // parallelFor runs a single block inline (no fork): a colour smaller than a block costs nothing
  // in task overhead, which matters since a sweep visits every colour twice per iteration.
  if (m_tasks) {
    m_tasks->parallelFor(count, kReductionBlock,
                         [&](Index begin, Index end, int) { kernel(begin, end); });
    return;
  }
  for (Index begin = 0; begin < count; begin += kReductionBlock) {
    kernel(begin, std::min(begin + kReductionBlock, count));
  }
}

template <typename Kernel>
void FilteredPcg::forEachBlock(Index vertexCount, Kernel&& kernel) {
  if (m_tasks) {
    m_tasks->parallelFor(vertexCount, kReductionBlock,
                         [&](Index begin, Index end, int) { kernel(begin, end); });
    return;
  }
  for (Index begin = 0; begin < vertexCount; begin += kReductionBlock) {
    kernel(begin, std::min(begin + kReductionBlock, vertexCount));
  }
}

template <typename Kernel>
Real FilteredPcg::sumInRange(Index count, Kernel&& kernel) {
  if (m_tasks) {
    return m_tasks->parallelReduce(
        count, kReductionBlock, Real(0), [&](Index begin, Index end) { return kernel(begin, end); },
        [](Real sum, Real partial) { return sum + partial; });
  }
  Real sum = 0;
  for (Index begin = 0; begin < count; begin += kReductionBlock) {
    sum += kernel(begin, std::min(begin + kReductionBlock, count));
  }
  return sum;
}

void FilteredPcg::prepareGaussSeidel(const BlockSparseMatrix& A) {
  if (!m_ordering.matches(A, m_rowColors)) {
    // A new pattern or colouring (set-up, or a topology change): order it, size the packed
    // blocks. Allocates.
    m_ordering.build(A, m_rowColors);
    m_lowerBlocks.resize(m_ordering.lowerSlots().size());
    m_upperBlocks.resize(m_ordering.upperSlots().size());
  }
  forEachBlock(A.blockRows(), [&](Index begin, Index end) {
    packRange(begin, end, A, m_ordering, m_lowerBlocks, m_upperBlocks);
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
    sum += sumInRange(m_ordering.colorEnd(color) - first, [&](Index begin, Index end) {
      return forwardSweepRange<curvature>(first + begin, first + end, PackedBlocks{m_lowerBlocks, m_upperBlocks}, m_ordering,
                                          filter, m_inverseDiagonal, c, t, w);
    });
  }
  return sum;
}

void FilteredPcg::backwardSweep(const VertexFilter& filter,
                                const Vec3Array& c, Vec3Array& t, Vec3Array& w) {
  for (Index color = m_ordering.colorCount(); color-- > 0;) {
    const Index first = m_ordering.colorBegin(color);
    forEachInRange(m_ordering.colorEnd(color) - first, [&](Index begin, Index end) {
      backwardSweepRange(first + begin, first + end, PackedBlocks{m_lowerBlocks, m_upperBlocks}, m_ordering, filter,
                         m_inverseDiagonal, c, t, w);
    });
  }
}

void FilteredPcg::applyPreconditioner(const BlockSparseMatrix& A, const VertexFilter& filter,
                                      PreconditionerKind kind, const Vec3Array& r, Vec3Array& z,
                                      TaskSystem* tasks) {
  m_tasks = tasks;
  const Index vertexCount = A.blockRows();
  if (m_residual.size() != vertexCount) resize(vertexCount);
  z.resize(vertexCount);
  forEachBlock(vertexCount, [&](Index begin, Index end) {
    buildPreconditionerRange(begin, end, A, filter, m_inverseDiagonal);
  });
  if (kind != PreconditionerKind::MulticolorGaussSeidel) {
    for (Index vertex = 0; vertex < vertexCount; ++vertex) z[vertex] = m_inverseDiagonal[vertex] * r[vertex];
    return;
  }
  prepareGaussSeidel(A);
  Vec3Array& w = m_product;
  std::copy(r.begin(), r.end(), w.begin());
  forwardSweep<false>(filter, m_direction, m_backward, w);  // w = P_L⁻¹ r
  sumOverBlocks(vertexCount, [&](Index begin, Index end) {
    return diagonalRange(begin, end, A, filter, w, m_preconditioned);  // D̃ w
  });
  backwardSweep(filter, m_preconditioned, z, m_residual);  // z = P_U⁻¹ D̃ w
}

SolveReport FilteredPcg::solve(const BlockSparseMatrix& A, const Vec3Array& b,
                               const VertexFilter& filter, const PcgSettings& settings,
                               Vec3Array& deltaV, TaskSystem* tasks) {
  SolveReport report;
  m_tasks = tasks;
  const Index vertexCount = A.blockRows();
  // Validated rather than asserted: the contract says a mismatch is reported, not undefined.
  if (b.size() != vertexCount || filter.size() != vertexCount) {
    report.relativeResidual = std::numeric_limits<Real>::quiet_NaN();
    report.residualNorm = std::numeric_limits<Real>::quiet_NaN();
    return report;
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
    buildPreconditionerRange(begin, end, A, filter, m_inverseDiagonal);
  });
  const bool gaussSeidel = settings.preconditioner == PreconditionerKind::MulticolorGaussSeidel;
  // The colouring depends on the pattern only: rebuilt (allocating) when the topology changes.
  if (gaussSeidel) prepareGaussSeidel(A);

  // The reference r_ref = S(b − A(I − S)z). A cold start begins exactly there, so it is the initial
  // residual; a warm start needs it separately, and needs the SpMV only when some target is nonzero.
  Real referenceDelta = 0;
  if (warmStart) {
    const Real targetSquaredNorm = sumOverBlocks(vertexCount, [&](Index begin, Index end) {
      return targetRange(begin, end, filter, c);
    });
    referenceDelta =
        targetSquaredNorm == 0
            ? sumOverBlocks(vertexCount,
                            [&](Index begin, Index end) {
                              return rightHandSideRange(begin, end, b, filter, m_inverseDiagonal,
                                                        r, s);
                            })
            : sumOverBlocks(vertexCount, [&](Index begin, Index end) {
                return residualRange(begin, end, A, b, filter, m_inverseDiagonal, c, r, s);
              });
  }

  forEachBlock(vertexCount,
               [&](Index begin, Index end) { startRange(begin, end, filter, warmStart, deltaV); });
  // stopDelta = rᵀD̃⁻¹r drives the stopping rule; delta = rᵀs = rᵀP⁻¹r drives CG. They are one
  // number for block Jacobi (s = D̃⁻¹r).
  Real stopDelta = sumOverBlocks(vertexCount, [&](Index begin, Index end) {
    return residualRange(begin, end, A, b, filter, m_inverseDiagonal, deltaV, r, s);
  });
  if (!warmStart) referenceDelta = stopDelta;

  // rᵀP̃⁻¹r ≥ 0 in exact arithmetic; clamp rounding below zero before the square root.
  const Real referenceNorm = std::sqrt(std::max(referenceDelta, Real(0)));
  const Stopping stopping{std::max(settings.tolerance * referenceNorm, settings.absoluteTolerance),
                          std::max(referenceNorm, settings.absoluteTolerance),
                          std::isfinite(referenceDelta), settings.maxIterations};
  if (gaussSeidel) {
    iterateGaussSeidel(A, filter, stopping, stopDelta, deltaV, report);
  } else {
    iterateJacobi(A, filter, stopping, stopDelta, deltaV, report);
  }
  return report;
}

/// Fills the report's residual fields from the stopping norm² and says whether it converged.
bool FilteredPcg::Stopping::judge(Real stopDelta, SolveReport& report) const {
  // NaN compares false with everything, so test finiteness first: a NaN residual must end the
  // loop as a failure, never look converged and never spin until the cap.
  if (!referenceFinite || !std::isfinite(stopDelta)) {
    report.residualNorm = std::numeric_limits<Real>::quiet_NaN();
    report.relativeResidual = std::numeric_limits<Real>::quiet_NaN();
    report.converged = false;
    return false;
  }
  report.residualNorm = std::sqrt(std::max(stopDelta, Real(0)));
  // A zero denominator needs absoluteTolerance = 0 and a zero reference; avoid 0/0 there.
  report.relativeResidual = denominator > 0 ? report.residualNorm / denominator
                            : report.residualNorm == 0 ? Real(0)
                                                       : std::numeric_limits<Real>::infinity();
  report.converged = report.residualNorm <= threshold;
  return report.converged;
}

void FilteredPcg::iterateJacobi(const BlockSparseMatrix& A, const VertexFilter& filter,
                                const Stopping& stopping, Real delta, Vec3Array& deltaV,
                                SolveReport& report) {
  const Index vertexCount = A.blockRows();
  Vec3Array& r = m_residual;
  Vec3Array& s = m_preconditioned;
  Vec3Array& c = m_direction;
  Vec3Array& q = m_product;
  forEachBlock(vertexCount, [&](Index begin, Index end) { copyRange(begin, end, s, c); });

  Real previousDelta = delta;
  for (;;) {
    if (stopping.judge(delta, report) || !std::isfinite(report.residualNorm)) break;
    if (report.iterations >= stopping.maxIterations) break;

    if (report.iterations > 0) {
      const Real beta = delta / previousDelta;
      forEachBlock(vertexCount, [&](Index begin, Index end) {
        directionRange(begin, end, beta, filter, s, c);
      });
    }
    const Real curvature = sumOverBlocks(vertexCount, [&](Index begin, Index end) {
      return filteredProductRange(begin, end, A, filter, c, q);
    });
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
    delta = sumOverBlocks(vertexCount, [&](Index begin, Index end) {
      return updateRange(begin, end, alpha, c, q, m_inverseDiagonal, deltaV, r, s);
    });
    ++report.iterations;
  }
}

void FilteredPcg::iterateGaussSeidel(const BlockSparseMatrix& A, const VertexFilter& filter,
                                     const Stopping& stopping, Real startStopDelta,
                                     Vec3Array& deltaV, SolveReport& report) {
  const Index vertexCount = A.blockRows();
  Vec3Array& r = m_residual;        // r̂ = P_L⁻¹ r
  Vec3Array& s = m_preconditioned;  // ŝ = D̃ r̂
  Vec3Array& c = m_direction;       // ĉ
  Vec3Array& t = m_backward;        // t = P_U⁻¹ ĉ, the search direction in Δv's space
  Vec3Array& w = m_product;         // u, then w = P_L⁻¹ u; Â ĉ = t + w

  // The start's residual is exact (residualRange); a bad one ends the solve before any sweep.
  if (stopping.judge(startStopDelta, report) || !std::isfinite(report.residualNorm)) return;
  if (stopping.maxIterations <= 0) return;

  forwardSweep<false>(filter, c, t, r);  // r̂ = P_L⁻¹ r, in place
  Real delta = sumOverBlocks(vertexCount, [&](Index begin, Index end) {
    return diagonalRange(begin, end, A, filter, r, s);
  });
  forEachBlock(vertexCount, [&](Index begin, Index end) { copyRange(begin, end, s, c); });
  // ‖r‖²_{M⁻¹} = r̂ᵀD̃r̂ = delta (M the SGS preconditioner) falls with CG's iterations; its ratio to
  // the start scales the start's exact ‖r‖_{D̃⁻¹} into an estimate, and the exact norm (one
  // half-SpMV) is computed only once the estimate is below the threshold.
  const Real startDelta = delta;
  const Real startNorm = report.residualNorm;
  auto exactStopDelta = [&] {
    return sumOverBlocks(vertexCount, [&](Index begin, Index end) {
      return untransformedNormRange(begin, end, PackedBlocks{m_lowerBlocks, m_upperBlocks}, m_ordering, filter,
                                    m_inverseDiagonal, r, s);
    });
  };

  Real previousDelta = delta;
  for (;;) {
    if (!std::isfinite(delta)) {
      stopping.judge(std::numeric_limits<Real>::quiet_NaN(), report);
      break;
    }
    if (report.iterations > 0) {
      const Real estimate =
          startDelta > 0 ? startNorm * std::sqrt(std::max(delta, Real(0)) / startDelta) : Real(0);
      if (estimate <= stopping.threshold || report.iterations >= stopping.maxIterations) {
        if (stopping.judge(exactStopDelta(), report) || !std::isfinite(report.residualNorm)) break;
      }
      if (report.iterations >= stopping.maxIterations) break;
      const Real beta = delta / previousDelta;
      forEachBlock(vertexCount, [&](Index begin, Index end) {
        directionRange(begin, end, beta, filter, s, c);
      });
    }
    backwardSweep(filter, c, t, w);
    const Real curvature = forwardSweep<true>(filter, c, t, w);
    // ĉᵀÂĉ ≤ 0: breakdown (A not positive definite on the free subspace, or a NaN). Δv keeps the
    // last finite iterate; the report gets that iterate's exact residual.
    if (!(curvature > 0) || !std::isfinite(curvature)) {
      if (!std::isfinite(curvature)) stopping.judge(std::numeric_limits<Real>::quiet_NaN(), report);
      else if (report.iterations > 0) stopping.judge(exactStopDelta(), report);
      report.converged = false;
      break;
    }
    const Real alpha = delta / curvature;
    previousDelta = delta;
    delta = sumOverBlocks(vertexCount, [&](Index begin, Index end) {
      return transformedUpdateRange(begin, end, alpha, A, filter, t, w, deltaV, r, s);
    });
    ++report.iterations;
  }
}

}  // namespace weft
