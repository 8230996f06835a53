// How a cloth is advanced in time: the integrator, its substeps, and the linear solver.
//
// Design note. The default is Baraff & Witkin's linearised backward Euler: one sparse solve per
// substep, stable at any step, so one substep per 60 Hz frame suffices for cloth. The solve is a
// filtered PCG whose accuracy follows the contact state: loose (a mass-weighted velocity error of
// 10 %) where the step's own error dominates, tight (relative residual 1e-3) in substeps where the
// collision passes after the solve amplify its error: cloth jammed in self-contact or yanked by its
// pins. docs/tuning.md says when to change what; bench/results/ has the measurements behind the
// defaults.
#pragma once

#include <weft/Math.h>

namespace weft {

/// The time integrators every cloth can use.
enum class IntegratorKind {
  ExplicitEuler,    ///< x += h v, v += h a(x, v): first order, needs tiny steps on stiff cloth
  SymplecticEuler,  ///< v += h a(x, v), x += h v_new: first order, stable for h ω < 2
  Midpoint,         ///< explicit midpoint (RK2): second order
  RungeKutta4,      ///< classic RK4: fourth order, stable for h ω < 2.78
  ImplicitEuler,    ///< backward Euler, linearised as in Baraff & Witkin 1998 (the default)
  /// BDF2 (Choi & Ko 2002), linearised and solved as ImplicitEuler: second order, A-stable, far
  /// less numerical damping of the cloth's swing
  Bdf2,
};

/// True for the methods that solve a linear system each step (ImplicitEuler, Bdf2): stable at
/// any step, with the PCG settings below.
constexpr bool isImplicit(IntegratorKind kind) {
  return kind == IntegratorKind::ImplicitEuler || kind == IntegratorKind::Bdf2;
}

/// Readable name of an integrator ("implicit-euler", "bdf2", "rk4", ...).
const char* integratorName(IntegratorKind kind);

/// Preconditioner of the implicit step's PCG. All keep pinned and contact directions exactly
/// constrained, give the same bits on any thread count and stop at the same accuracy.
enum class PreconditionerKind {
  /// Inverse 3×3 diagonal block per vertex: cheapest per iteration, most iterations on stiff cloth.
  BlockJacobi,
  /// Symmetric block Gauss–Seidel (SSOR, ω = 1) in a multicolour order from the cloth's mesh: a
  /// forward and a backward sweep per iteration, about half the iterations of block Jacobi.
  MulticolorGaussSeidel,
  /// Gauss–Seidel plus a coarse correction over aggregates of about 4 × 4 vertices, each moving
  /// as one translation, solved exactly: iterations that stop growing with the mesh's refinement,
  /// each costing about two of Gauss–Seidel's, plus a factorisation per solve. Opt-in: on the
  /// ×16 and ×64 curtains it is faster while the cloth hangs free, slower over the ×16's script.
  TwoLevelGaussSeidel,
};

/// Which test ends the implicit step's PCG (SolverSettings::cgStopping).
enum class PcgStopping {
  /// The block-Jacobi-weighted residual against the cold start's falls below the tolerance.
  /// Blind to slow, soft-mode velocity errors on stiff or jammed cloth.
  RelativeResidual,
  /// The mass-weighted velocity error ‖e‖_M, bounded by ‖r‖_{M⁻¹} or estimated from the last
  /// iterations' progress, falls below tolerance · max(‖Δv‖_M, 1 mm/s · √Σm).
  VelocityError,
};

/// Integrator, substeps and solver settings of one cloth.
struct SolverSettings {
  IntegratorKind integrator = IntegratorKind::ImplicitEuler;  ///< which integrator
  /// Substeps per frame; 0 = automatic: implicit takes h ≤ maxImplicitStep, explicit methods what
  /// their stiffest mode needs, both enough for maxPinTravelPerSubstep, up to maxSubsteps.
  Index substeps = 0;
  /// Mean rest edge lengths a pin may travel in one automatic substep; more substeps when pins
  /// move faster. Raising it saves substeps at the cost of strain in those frames. 0 = no limit.
  Real maxPinTravelPerSubstep = 1;
  /// Automatic substeps: a frame that leaves a cloth past its strain limit + kStrainLimitSlack is
  /// redone with twice the substeps within this many (a squeeze through a ring at 60 Hz needs 4–8),
  /// except while redos already failed to bring the cloth back within its limit. 0 = never. Default 8.
  Index strainRetrySubsteps = 8;
  /// Cloth sizes (ClothModel::characteristicLength) every pin must move in one frame for the frame
  /// to be a teleport: the cloth is carried by the pins' best-fit rigid motion instead of dragged
  /// through the frame. Raise it for cloth on very fast vehicles. Default 1; 0 = never.
  Real pinTeleportDistance = 1;
  /// rad: pins turning as one rigid body by more than this in one frame make it a teleport too
  /// (a turn in place, which pinTeleportDistance cannot see). Default π/2; 0 = never.
  Real pinTeleportAngle = 1.5707963267948966;
  Real maxImplicitStep = 1.0 / 60.0;  ///< s, largest implicit substep in automatic mode
  /// Cap on automatic substeps per frame; an explicit method that would need more is stepped at
  /// the cap and reported (StepStatus::Unstable).
  Index maxSubsteps = 4000;
  /// Extra Newton iterations after Baraff–Witkin's single linearised solve (0 = BW98 exactly).
  int newtonIterations = 0;
  /// Relative-residual tolerance that hard substeps are solved to, whatever cgTolerance says: a
  /// cloth jammed in self-contact (tightSelfContactDensity) or yanked by its pins
  /// (tightPinTravel). Lower settles crumpled piles better. Default 1e-3; 0 = no tightening.
  Real tightCgTolerance = 1e-3;
  /// Self-contacts per vertex in a substep's first self-collision pass at or above which the next
  /// substep is hard (tightCgTolerance). A hanging cloth has none, a crumpled pile 0.5–6. Default 0.025.
  Real tightSelfContactDensity = 0.025;
  /// Mean rest edge lengths a pin moves in one substep at or above which the substep is hard
  /// (tightCgTolerance). Default 0.5.
  Real tightPinTravel = 0.5;
  /// Accuracy at which each implicit solve's PCG stops, in the sense of cgStopping. Tighter costs
  /// CG iterations and changes the motion little; hard substeps use tightCgTolerance. Default 0.1.
  Real cgTolerance = 1e-1;
  /// Which test ends the PCG. VelocityError (default) is sound on stiff and jammed cloth; hard
  /// substeps use RelativeResidual at tightCgTolerance whatever this says.
  PcgStopping cgStopping = PcgStopping::VelocityError;
  int cgMaxIterations = 200;  ///< PCG iteration cap per solve
  /// Preconditioner of the PCG; all meet the same tolerance, with answers that differ within it.
  /// Default multicolour Gauss–Seidel: the fastest on the curtain at every size measured.
  PreconditionerKind preconditioner = PreconditionerKind::MulticolorGaussSeidel;
  bool warmStart = true;      ///< start each PCG from the previous step's Δv
  /// Take pinned vertices out of the implicit system (their known velocity change moves to the
  /// right-hand side) instead of keeping them filtered in it; same motion. false is for checks.
  bool removePinnedVertices = true;
  /// Self-contacts inside the implicit solve (implicit Euler, BDF2), as a multiple of the stretch
  /// stiffness: settles crumpled piles, at about 2.5× the CG iterations in contact-heavy frames.
  /// ≥ 0; 0 = off (default): the contact projection alone keeps the layers apart.
  Real selfContactStiffness = 0;
};

}  // namespace weft
