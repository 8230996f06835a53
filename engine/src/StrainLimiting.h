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
// Order (StrainLimitSettings::order). Gauss–Seidel, the default: the edges one after the other
// in edge order, then back, each seeing the corrections before it. It is serial, so the same
// bits on any thread count by construction; a sweep reads and writes what one Jacobi iteration
// does, without its fork/joins, and it converges several times faster (a pinned chain: 3.9
// times fewer iterations; the stress curtain at 1/30 s steps, with 32 iterations and 3 rounds
// in contact in Cloth: max strain 0.23 with Jacobi, 0.107 with Gauss–Seidel).
// The stopping count before every sweep still runs in parallel (TaskSystem's ordered
// reduction). Jacobi, kept for meshes so large that a serial sweep would dominate, is parallel
// and deterministic; one iteration is
//   1. per edge (one writer per edge slot): its impulse p_e and whether it is over the limit,
//      counting the edges still over limit + tolerance (TaskSystem's ordered reduction);
//   2. per vertex: n_i, how many over-limit edges move vertex i;
//   3. per vertex (one writer per vertex, incident edges gathered in increasing edge order):
//      Δx_i = w_i Σ_e ±p_e / max(n_a(e), n_b(e)); x_i += Δx_i, v_i += Δx_i / h.
// The division by the larger count is the same for both ends of an edge, so every edge still
// changes momentum by zero, and a vertex pulled by several edges at once takes at most the
// average of their corrections, which keeps the simultaneous updates from overshooting
// (Jacobi with every correction in full oscillates on a grid vertex pulled by six edges).
// Rejected: Gauss–Seidel in parallel without colouring (racy, thread-dependent); edge
// colouring (one fork/join per colour per iteration and a colouring to keep: a later step for
// large meshes); per-vertex averaging by the vertex's own count (conserves momentum only when
// both ends of every edge have the same count); a global projection (PCG on J W Jᵀ λ = excess
// over the edges over the limit, Goldenthal et al. 2007): tried, and on a hanging sheet its
// equality system over a triangle mesh with pinned rows became inconsistent (more active edges
// than free degrees of freedom), the multipliers grew without bound and the sheet blew up to
// strain 7 — with or without clamping λ ≥ 0 and a regularised diagonal.
//
// In contact (applyInContact). The collision passes run after the limiter and move vertices
// (out of a collider, apart, dragged by friction), which stretched the cloth again: 0.19 on the
// curtain at its 1/60 s step, 0.21 on a spinning sphere with friction. Cloth therefore runs the
// limiter again after them, with every vertex the collider response left on a surface held along
// that surface's normal n: its generalised inverse mass is w (I − n nᵀ), so an edge weighs it by
// w (1 − (n·d)²) and its correction loses the part along n. The limiter then slides it on the
// surface instead of pulling it back in (which the collisions would undo, stretching again).
// A vertex on two surfaces at an angle gets w = 0. The momentum the held part would have taken
// goes to the collider, like a contact force.
// A held end's step. The correction is linearised: it moves the ends so that the edge's length
// falls by the excess to first order. For a free edge the move is along the edge and exact; for a
// held end it runs across the normal, and when the edge lies nearly along that normal, the step
// excess / √(1 − (n·d)²) across it carries the end far past the point where the edge is
// shortest (at 1 − (n·d)² = 0.002, 22 times the excess), so the edge, and every other edge of
// the end, comes out longer than it went in. Each held step is therefore cut to the fraction
// that brings the edge exactly to the limit along its path (the first root of a quadratic), or,
// when the path never gets that short, to its shortest point. Measured on stress scene 7 at
// 16 × 16 vertices a layer: the largest strain right after a round's limiter went from 25.6
// (the limiter's own overshoot) to 3.1.
// Known limit: a free pair shares its correction in inverse proportion to mass, so a vertex
// much heavier than its neighbours (a 1 kg weight on 0.3 g cotton vertices) moves by a tiny
// fraction per iteration; within the iteration cap the light cloth around it is held but the
// weight keeps sinking (measured: strain 0.22 at 0.5 kg, 0.44 at 1 kg on a 9 × 9 sheet).
//
// Self-contacts (applyInContact's `separations`). A pair of features the self-collision pass
// found in contact (vertex–triangle or edge–edge, weights w_k summing to zero on each side,
// normal n) is held one-sided: n · Σ w_k x_k ≥ s, s the separation the pass left it at (at most
// the thickness). After every pass over the edges, each pair short of it is pushed apart in
// pair order (Gauss–Seidel), so the edges and the contacts are solved in one iteration
// (Bridson, Fedkiw & Anderson 2002 resolve contacts by the same projection with impulses).
// Inside a pair every movable vertex counts as heavy as the pair's heaviest: with true masses a
// 0.7 g sheet vertex under a 31 g weight takes 98 % of each separation, which the edges pull
// back on the next pass, and the weight rises by m_light / m_heavy of the overlap per iteration
// (stress scene 9: strain 8.1 with the cap hit every substep; 9.6 with true masses and the
// holds; 0.103 with the pair counting heavy). The momentum this gives the heavy side is the
// support the pins give through the taut sheet, the only case in which the limiter moves a light
// side into a heavy one. Cloth holds only pairs of very different masses (Cloth.cpp,
// kHeldContactMassRatio; holding every pair kept folds caught in stress scene 10). Holds with a
// collider normal n_j see w_j² W (1 − (n_j·n)²) as above.
//
// The iteration stops when no correctable edge is over limit + tolerance, or after
// maxIterations; the report says how many iterations ran and how many edges were left over.
// Cloth runs it after the solve, then the collisions, then (Cloth::limitStrainInContact) again
// in contact and the collisions again, a few rounds: collisions keep the last word (nothing
// inside a collider, no crossing) even where that costs a little strain. Between features of
// comparable masses the self-collision pass after the last round can still stretch the cloth
// (jammed layers, stress scene 7); ClothSettings::jointContactProjection then runs the limiter
// with every self-contact and the collider contacts as constraints (PositionConstraints,
// ColliderProjection.h), rounds until they settle.
#pragma once

#include <weft/Math.h>
#include <weft/engine/ClothModel.h>
#include <weft/threading/TaskSystem.h>

#include <algorithm>
#include <array>
#include <limits>
#include <span>
#include <vector>

namespace weft {

/// A pair of features in contact that the limiter keeps apart (applyInContact): vertex–triangle
/// (p; a, b, c) with weights (1, −b₀, −b₁, −b₂), or edge–edge with (1 − s, s, −(1 − u), −u), as in
/// ContactResolver. The limiter keeps normal · Σ weights[k] x[vertices[k]] ≥ separation: it may
/// move the pair apart or let it slide, never closer than that.
struct SeparationHold {
  std::array<Index, 4> vertices{};
  std::array<Real, 4> weights{};
  Vec3 normal = Vec3::Zero();  ///< unit, from the second side (triangle, second edge) to the first
  Real separation = 0;         ///< m, the smallest separation along the normal allowed
};

/// A contact is held inside the limiter (applyInContact's `separations`) when one of its movable
/// vertices is more than this many times heavier than another: Cloth for its self-contacts,
/// ClothClothCollision for contacts between cloths (the measurements are in Cloth.cpp).
constexpr Real kHeldContactMassRatio = 10;

/// True when `pair` joins movable vertices (non-zero weight and inverse mass) whose masses differ
/// by more than kHeldContactMassRatio.
inline bool spansHeldMassRatio(const SeparationHold& pair, std::span<const Real> inverseMasses) {
  Real lightest = 0, heaviest = std::numeric_limits<Real>::infinity();
  for (int k = 0; k < 4; ++k) {
    const Real w = inverseMasses[pair.vertices[k]];
    if (w == 0 || pair.weights[k] == 0) continue;
    lightest = std::max(lightest, w);
    heaviest = std::min(heaviest, w);
  }
  return lightest > kHeldContactMassRatio * heaviest;
}

/// Further one-sided constraints on positions that StrainLimiter::applyInContact satisfies together
/// with its edges and separations (Gauss–Seidel): Cloth's collider contacts (ColliderProjection).
class PositionConstraints {
 public:
  /// One pass over every constraint at the current x: each violated one is projected back onto
  /// its bound, each position change Δx made also as the velocity change Δx · inverseStep.
  /// Returns how many were violated by more than the implementation's tolerance.
  virtual Index project(std::span<Vec3> x, std::span<Vec3> v, Real inverseStep) = 0;

 protected:
  ~PositionConstraints() = default;
};

/// How the strain limiter orders its corrections within one iteration.
enum class StrainLimitOrder {
  /// One edge after the other, each seeing the corrections before it, in edge order and then
  /// back (serial; converges in several times fewer iterations than Jacobi on a grid).
  GaussSeidel,
  /// All edges at once from the same positions, averaged per vertex (parallel).
  Jacobi,
};

/// How far the strain limiter may let edges stretch and how hard it tries.
struct StrainLimitSettings {
  /// Strain l / l_rest − 1 that no edge may exceed at the end of a step; must be > 0 and finite
  /// (the cloth turns the limiter off for 0 or infinity).
  Real limit = 0.10;
  /// Strain an edge may stay above `limit` when the iteration stops: the corrections aim at the
  /// limit itself, and Jacobi approaches it geometrically, so a small band saves iterations.
  Real tolerance = 1e-3;
  /// Iterations per step at most (three parallel passes each); the report says what was left.
  int maxIterations = 64;
  /// Gauss–Seidel unless the mesh is so large that a serial sweep costs more than Jacobi's
  /// extra iterations (see the design note).
  StrainLimitOrder order = StrainLimitOrder::GaussSeidel;
};

/// What one StrainLimiter::apply() did.
struct StrainLimitReport {
  int iterations = 0;      ///< correction passes run (0: no edge was over limit + tolerance)
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
  /// within settings.maxIterations). `inverseMasses` is 1/m per vertex, 0 for vertices that must
  /// not move. Bitwise the same for any thread count of `tasks`.
  StrainLimitReport apply(const StrainLimitSettings& settings, std::span<const Real> inverseMasses,
                          Real h, std::span<Vec3> x, std::span<Vec3> v, TaskSystem& tasks);

  /// apply() for a cloth in contact: a vertex i with a non-zero `contactNormals[i]` (unit, one
  /// per vertex) is held along it — its corrections lose their part along the normal, and its
  /// edges weigh it by w_i (1 − (n_i·d)²) — so the limiter slides it on the surface it rests on
  /// but neither pushes it in nor pulls it off. A zero normal leaves the vertex free.
  ///
  /// `separations` are the cloth's self-contacts (SelfCollision::separationHolds()): after every
  /// pass over the edges, each pair closer than its separation along its normal is pushed back
  /// to it (Gauss–Seidel, in pair order, the same inverse masses and surface holds), so that the
  /// limiter and the contacts are solved together (see the design note).
  StrainLimitReport applyInContact(const StrainLimitSettings& settings,
                                   std::span<const Real> inverseMasses,
                                   std::span<const Vec3> contactNormals, Real h, std::span<Vec3> x,
                                   std::span<Vec3> v, TaskSystem& tasks,
                                   std::span<const SeparationHold> separations = {},
                                   PositionConstraints* constraints = nullptr);

 private:
  StrainLimitReport run(const StrainLimitSettings& settings, std::span<const Real> inverseMasses,
                        std::span<const Vec3> contactNormals,
                        std::span<const SeparationHold> separations,
                        PositionConstraints* constraints, Real h, std::span<Vec3> x,
                        std::span<Vec3> v, TaskSystem& tasks);

  // One Gauss–Seidel pass over every edge over the limit, forward or backward in edge order.
  void sweep(Real stretchFactor, std::span<const Real> inverseMasses,
             std::span<const Vec3> contactNormals, Real inverseStep, bool backward,
             std::span<Vec3> x, std::span<Vec3> v) const;
  // One Gauss–Seidel pass over the self-contacts, forward or backward in pair order: every pair
  // closer than its separation is moved apart to it.
  static void separate(std::span<const SeparationHold> separations,
                       std::span<const Real> inverseMasses, std::span<const Vec3> contactNormals,
                       Real inverseStep, bool backward, std::span<Vec3> x, std::span<Vec3> v);

  struct LimitedEdge {
    Index a = 0, b = 0;
    Real restLength = 0;
  };
  std::vector<LimitedEdge> m_edges;
  // Incident edges of every vertex, in increasing edge order: vertex i's are
  // m_incidentEdges[m_incidenceOffsets[i] .. m_incidenceOffsets[i + 1]).
  std::vector<Index> m_incidenceOffsets, m_incidentEdges;
  std::vector<Vec3> m_impulses;          // per edge: p_e (stale when not over the limit)
  std::vector<char> m_overLimit;         // per edge: 1 when corrected this iteration
  std::vector<Index> m_correctionCount;  // per vertex: n_i of this iteration
};

}  // namespace weft
