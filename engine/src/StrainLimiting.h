// StrainLimiting: keeps every mesh edge of a cloth within (1 + limit) times its rest length at
// the end of a step, by correcting the step's velocities (and so its end positions).
//
// Design note
// -----------
// Why: the implicit solve treats stretch as an elastic spring of the material's low-strain
// stiffness (cotton: 260 N/m). Woven fabric does not behave like that past ≈ 10 % strain — its
// yarns straighten and it becomes nearly inextensible — so a heavy load, a large step, friction
// dragging it round a spinning body or a pin yanked far away stretched the cloth without bound
// (strains of 0.35 in the curtain, 45 under heavy objects). Making the stiffness nonlinear would
// stiffen the linear systems and slow every solve; Provot (1995) instead corrects the positions
// of over-stretched springs after the step, and Bridson, Fedkiw & Anderson (2002, §5) do the
// same on velocities, so that the next step starts from a consistent state: the correction Δx
// of an end position is made as the velocity change Δx / h over the step.
//
// Per edge e = (a, b) with direction n = (x_b − x_a) / l, length l and rest length L, an excess
// l − (1 + s) L > 0 is removed by moving a by +w_a p and b by −w_b p, with the edge's position
// impulse p = excess / (w_a + w_b) · n and w = 1/m (0 for pinned and collider-attached
// vertices, which never move). The momentum change m_a w_a p − m_b w_b p is zero: a free pair
// keeps its momentum, and only pins and attachments take force from the cloth. An edge whose
// two ends are both immovable cannot be corrected and is left alone.
//
// The edges over the limit are corrected together, as one linear system (the "fast projection"
// of Goldenthal et al. 2007 on the active edges): with per-edge multipliers λ, vertex a moves by
// w_a Σ λ_e n_e and b by −w_b Σ λ_e n_e, and the linearised shortening of every active edge is
// (J W Jᵀ λ)_e, which must equal its excess c_e. J W Jᵀ is symmetric positive (semi)definite,
// with diagonal w_a + w_b: it is solved by PCG with that diagonal as preconditioner, and the
// projection is repeated (a few passes) from the corrected positions for the nonlinearity and for
// edges the correction itself pushed over; an edge once active stays active (held at the limit)
// for the rest of the call, so the passes converge like Newton's method instead of trading
// edges back and forth. λ < 0 is kept: it holds an over-stretched edge at the
// limit where the others would have shortened it further, which costs nothing, while clamping
// it to 0 unbalances the large opposite multipliers of redundant edges (measured: a randomly
// displaced grid went from strain 0.7 to 42).
// Rejected: Jacobi or Gauss–Seidel sweeps over single edges (Provot's own method). Measured
// here with a 1 kg weight on a 9 × 9 cotton sheet (vertices of 0.3 g): a sweep moves the weight
// by w_weight / (w_weight + w_sheet) ≈ 1/3000 of an edge's excess, so after 3,700 Jacobi
// iterations the sheet was still at strain 0.44. PCG on J W Jᵀ converges at the rate of the
// light sheet's own graph, whatever the weight.
//
// Parallel and deterministic: every pass is either per edge (one writer per edge slot) or per
// vertex (one writer per vertex, incident edges gathered in increasing edge order), and every
// dot product is TaskSystem's ordered reduction over fixed blocks. So 1, 2 or 8 threads give the
// same bits. No Gauss–Seidel, no atomics, no colouring.
//
// It runs after the solve and before collision response, so collisions keep the last word
// (nothing inside a collider, no crossing) even where that costs a little strain.
#pragma once

#include <weft/Math.h>
#include <weft/engine/ClothModel.h>
#include <weft/threading/TaskSystem.h>

#include <span>
#include <vector>

namespace weft {

/// How far the strain limiter may let edges stretch and how hard it tries.
struct StrainLimitSettings {
  /// Strain l / l_rest − 1 that no edge may exceed at the end of a step; must be > 0 and finite
  /// (the cloth turns the limiter off for 0 or infinity).
  Real limit = 0.10;
  /// Strain an edge may stay above `limit` when the iteration stops: the corrections aim at the
  /// limit itself, and Jacobi approaches it geometrically, so a small band saves iterations.
  Real tolerance = 1e-3;
  /// Projections per step at most (each finds the edges over the limit and solves for them).
  int maxPasses = 4;
  /// PCG iterations per projection at most (three parallel passes each).
  int maxIterations = 50;
};

/// What one StrainLimiter::apply() did.
struct StrainLimitReport {
  int passes = 0;          ///< projections run (0: no edge was over limit + tolerance)
  int iterations = 0;      ///< PCG iterations summed over the projections
  Index edgesOverLimit = 0;  ///< correctable edges still over limit + tolerance at the end
};

/// The strain limiter of one mesh: edge tables built once, scratch reused (no allocation in
/// apply()).
class StrainLimiter {
 public:
  /// `edges` with their rest lengths (ClothModel::edges()); vertex indices < vertexCount.
  StrainLimiter(std::span<const Edge> edges, Index vertexCount);

  /// Corrects x and v (one entry per vertex) after a step of length h > 0 so that no edge with
  /// a movable end is longer than (1 + settings.limit) times its rest length (to the tolerance,
  /// within settings.maxPasses and maxIterations). `inverseMasses` is 1/m per vertex, 0 for vertices that must
  /// not move. Bitwise the same for any thread count of `tasks`.
  StrainLimitReport apply(const StrainLimitSettings& settings, std::span<const Real> inverseMasses,
                          Real h, std::span<Vec3> x, std::span<Vec3> v, TaskSystem& tasks);

 private:
  struct LimitedEdge {
    Index a = 0, b = 0;
    Real restLength = 0;
  };
  // y = J W Jᵀ s on the active edges (the product of one PCG iteration), via m_shift.
  template <class Scalars>
  void gatherShifts(const Scalars& s, std::span<const Real> inverseMasses, TaskSystem& tasks);

  std::vector<LimitedEdge> m_edges;
  // Incident edges of every vertex, in increasing edge order: vertex i's are
  // m_incidentEdges[m_incidenceOffsets[i] .. m_incidenceOffsets[i + 1]).
  std::vector<Index> m_incidenceOffsets, m_incidentEdges;
  // Per edge: active in this projection, its direction, and the PCG vectors (0 when inactive).
  std::vector<char> m_active;
  std::vector<Vec3> m_direction;
  std::vector<Real> m_diagonal, m_multiplier, m_residual, m_preconditioned, m_search, m_product;
  std::vector<Vec3> m_shift;  // per vertex: W Jᵀ s for the current s
};

}  // namespace weft
