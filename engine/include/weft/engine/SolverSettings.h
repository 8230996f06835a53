// How a cloth is advanced in time: the integrator, its substeps, and the linear solver.
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
};

/// Readable name of an integrator ("implicit-euler", "rk4", ...).
const char* integratorName(IntegratorKind kind);

/// Preconditioner of the implicit step's PCG. Both are filtered (pinned and contact directions
/// stay exactly constrained) and bitwise identical for any thread count; the stopping test
/// (SolverSettings::cgStopping) measures the same norm whichever is used, so they solve to the
/// same accuracy.
enum class PreconditionerKind {
  /// Inverse 3×3 diagonal block per vertex: one multiply per vertex per iteration, weakest on
  /// stiff cloth (many iterations when off-diagonal coupling dominates the mass).
  BlockJacobi,
  /// Symmetric block Gauss–Seidel (SSOR, ω = 1) in a multicolour order: a forward and a backward
  /// sweep per iteration (about one more SpMV of work), colours in sequence, the vertices of a
  /// colour in parallel. Fewer iterations, most so on stiff cloth.
  MulticolorGaussSeidel,
};

/// Which test ends the implicit step's PCG (SolverSettings::cgStopping; engine/src/solver/
/// FilteredPcg.h, "Stopping").
enum class PcgStopping {
  /// ‖r‖_{D̃⁻¹} ≤ tolerance · ‖r_ref‖_{D̃⁻¹}: the block-Jacobi residual against the cold start's.
  /// Matrix-only; blind to slow (soft-mode) velocity errors on stiff or jammed cloth.
  RelativeResidual,
  /// The mass-weighted velocity error ‖e‖_M, bounded by ‖r‖_{M⁻¹} or estimated from the last
  /// window's progress (while the relative residual agrees), ≤ tolerance · max(‖Δv‖_M,
  /// velocityFloor·√Σm). Needs the masses.
  VelocityError,
};

/// Integrator, substeps and solver settings of one cloth.
struct SolverSettings {
  IntegratorKind integrator = IntegratorKind::ImplicitEuler;  ///< which integrator
  /// Substeps per frame; 0 = automatic: implicit takes enough that h ≤ maxImplicitStep, explicit
  /// methods take enough that the stiffest mode of the rest state is stable, and either takes
  /// enough that no pin moves more than maxPinTravelPerSubstep mean rest edge lengths per
  /// substep (a pin moving 10 m in one frame on a 5 cm mesh, with pinTeleportDistance off or the
  /// other pins staying: 200), up to maxSubsteps. In a teleport frame (pinTeleportDistance) the
  /// rule measures each pin's travel relative to the carried cloth.
  Index substeps = 0;
  /// Mean rest edge lengths a pin may travel in one automatic substep; 0 = no limit. A pin is a
  /// kinematic driver, and neither the linearised implicit step nor the strain limiter nor the
  /// swept self-collision test can follow one that jumps far past its neighbours in one substep.
  /// 1 is the measured safe value (stress scene 10 with pinTeleportDistance off: pins moved 10 m
  /// in one frame end the frame at the strain limit with it; at 4 the frame ends at 0.14, and in
  /// one substep at 17.9). It costs substeps whenever pins move fast: a cape pinned to a
  /// character running at 6 m/s on a 3 cm mesh takes 4 substeps a frame at 60 Hz. A game that
  /// moves pins fast and can accept more strain in those frames raises it. Pins that all jump far are a teleport instead
  /// (pinTeleportDistance); a teleport of the whole cloth to a given state is World::setState.
  Real maxPinTravelPerSubstep = 1;
  /// Cloth sizes (ClothModel::characteristicLength, the rest shape's bounding-box diagonal) a pin
  /// may move in one frame before the frame is a teleport, when every pin of the cloth moves
  /// farther than that; 0 = never. A teleport frame carries the whole cloth at its start by the
  /// pins' best-fit rigid motion (old targets onto new: the centroids' translation and the
  /// least-squares rotation), turning velocities with it, and simulates only the pins' motion
  /// relative to it (none when they all move rigidly), under the substep rule above; one pin
  /// yanked far while the others stay is no teleport. So setPinTargets() moving a hanging
  /// cloth's pins 10 m, turned or not, puts it there hanging as before, the way game engines
  /// treat a character that jumps farther in a frame than it could move (a respawn facing another
  /// way, a cut). Pins that do not determine a rotation carry what they determine: one pin, its
  /// jump; pins on one line (a cape pinned along its top edge), the turn of that line, with the
  /// turn about the line chosen to keep the plane of the line and gravity (so a line turned end
  /// for end turns about the vertical). A turn in place, where the pins near the axis move less
  /// than this, is a teleport by pinTeleportAngle instead. Off, the pins drag the
  /// cloth at 600 m/s through that frame and stop dead at its end; the cloth crashes into them
  /// and can stay crushed in folds held by self-contact (stress scene 10 with it off: 6 of 24
  /// round-off-level perturbations do not settle within 2 s, bench weft-teleport-perturb).
  /// Pins that move their cloth's size in every frame (a 0.7 m flag on a vehicle at 42 m/s at
  /// 60 Hz) are carried every frame, so the cloth no longer feels that motion (nor the air it
  /// moves through): raise it or turn it off for such a cloth.
  Real pinTeleportDistance = 1;
  /// rad: a frame in which the pins turn as one rigid body (each pin within a mean rest edge of
  /// where their best-fit rigid motion puts it, and some pin moving farther than an edge) by more
  /// than this angle is a teleport too, carried by that motion as above; 0 = never. It catches the
  /// turns in place that pinTeleportDistance cannot (pins near the turn's axis hardly move: a
  /// character snapped round to face the other way). Dragged instead, each pin moves on a straight
  /// line through the frame, so the pins of a row turned end for end pass through their middle
  /// and crush the cloth there (a 0.4 m sheet: strain 5.0 at the frame's end, still 5.0 two seconds
  /// later, tests/engine/PinTeleportTest.cpp). A quarter-turn (the default) is 15 turns per second
  /// at 60 Hz, far beyond any animated attachment, and a dragged quarter-turn shortens a row's
  /// chord by at most 29 %, which the cloth takes as buckling (same file: strain ≤ the limit).
  /// Pins moved non-rigidly (one end swung round, a twist) are never carried by this rule.
  Real pinTeleportAngle = 1.5707963267948966;
  Real maxImplicitStep = 1.0 / 60.0;  ///< s, largest implicit substep in automatic mode
  /// Cap on automatic substeps per frame; an explicit method that would need more is stepped at
  /// the cap and reported unstable (StepStatus::Unstable), never silently.
  Index maxSubsteps = 4000;
  /// Extra Newton iterations after Baraff–Witkin's single linearised solve (0 = BW98 exactly).
  int newtonIterations = 0;
  /// Contact-aware accuracy (issue 7): the relative-residual tolerance (PcgStopping::
  /// RelativeResidual) that the hard substeps of a cloth are tightened to, whatever cgTolerance
  /// and cgStopping say for the others; never loosened (a hard substep solves to min(cgTolerance
  /// or the plan's, this)); 0 = no tightening. A substep is hard when the cloth is jammed in
  /// self-contact (the previous substep's self-collision pass found tightSelfContactDensity
  /// contacts per vertex) or yanked by its pins (one moves tightPinTravel mean edge lengths or
  /// more in the substep). Why (a reading of the measurements, not a proof): in both the step is
  /// followed by corrections that the solve's error feeds. In a jammed pile the self-collision
  /// pass moves positions after the solve, by as much as the solve left features overlapping,
  /// against the stiff stretch springs, and the next solves release that elastic energy as motion
  /// (tests/README.md, "why a crumpled pile can stir forever"; whether a pile jams is chaotic:
  /// the residual at 1e-4 stirs too, so this keeps the outcome the residual at 1e-3 has always
  /// had there rather than making it certain). Under a yank the velocity change is dominated by
  /// the pins' drive, so an error relative to it (the velocity-error test) is large against the
  /// cloth's own motion, the folds that the crash into the stopped pins then catches in
  /// self-contact. Elsewhere the error perturbs a smooth trajectory that the next steps damp, and
  /// on the curtain a loose solve is even closer to the fine-step reference (it damps less).
  /// Measured (bench/results/error-time-curtain.md, "contact-aware accuracy"): the loose default
  /// passes the crumple and dragged-pin scenes that it fails without the tightening.
  Real tightCgTolerance = 1e-3;
  /// Self-contacts per vertex (proximity pairs closer than the thickness plus swept impacts found
  /// by one substep's first self-collision pass, divided by the cloth's vertices) at or above
  /// which the next substep is hard (tightCgTolerance). Carried from frame to frame and saved with
  /// the world. Measured: a hanging or swinging cloth has none; a cloth crumpled in a pile, or
  /// dragged into its stopped pins, 0.5–6; the curtain folded against its sphere 0.2–1.2. At
  /// 0.025 and 0.05 the whole suite passes; at 0.1 the corner crumple fails.
  Real tightSelfContactDensity = 0.025;
  /// Mean rest edge lengths a pin moves in one substep at or above which the substep is hard
  /// (tightCgTolerance). Measured: the curtain's scripted pins move up to 0.31 per substep; pins
  /// dragged 10 m in one frame (maxPinTravelPerSubstep keeps them at ≤ 1) move 0.99, and those
  /// frames need the tight solve (at 1.0 they do not count as hard and the dragged-pin harness
  /// fails 22 of 24 runs; at 0.5 and 0.25, 6 of 24, as with every substep tight).
  Real tightPinTravel = 0.5;
  /// Relative accuracy at which each implicit solve's PCG stops, in the sense of cgStopping (hard
  /// substeps are tightened to tightCgTolerance). The default, the velocity error at 1e-1, is the
  /// contact-aware default of issue 7 (bench/results/error-time-curtain.md, "contact-aware
  /// accuracy"): on the curtain's quick sweep at h = 1/60 s it takes 9.3 CG iterations per frame
  /// for RMS error 0.0193 (the window test checked at every iteration, FilteredPcg.h), against
  /// 24.5 and 0.0217 for the residual at 1e-3, within ~4 % (idle wall clock, fastest of 3) of the
  /// front, whose nearest point is the residual at 5e-2 (9.0, 0.0175; that one fails
  /// 10 tests, among them two layers falling through a sphere, and the residual test at any loose
  /// tolerance loses the swing of a ×10⁴-stiff sheet: it weighs an error in a slow, soft mode by
  /// ~√(m/(m + h²k)), stress scenes 2 and 7). The curtain's error hardly moves with the tolerance
  /// (RMS 0.018–0.022 from 1e-1 to 1e-8 at h = 1/60 s): it is set by the step and the contacts.
  /// The loose velocity-error test alone fails the scenes of heavy self-contact (a cloth dropped
  /// on a corner keeps stirring on the floor, a drape, pins dragged 10 m in one frame: 22 of 24
  /// perturbed runs against 6 of 24 at 1e-3); with the tightening of hard substeps it passes them
  /// (tightCgTolerance explains why those need the accurate solve). A caller who wants every
  /// solve accurate sets this tighter (the hard substeps follow it down) or tightCgTolerance
  /// alone; the former default was RelativeResidual 1e-3 on every substep.
  Real cgTolerance = 1e-1;
  /// Which test ends the PCG (PcgStopping, engine/src/solver/FilteredPcg.h): VelocityError (the
  /// default), the mass-weighted velocity error (bounded by ‖r‖_{M⁻¹}, or estimated by what Δv
  /// moved over the last 4 iterations while the residual test also holds) against cgTolerance ×
  /// max(‖Δv‖_M, 1 mm/s·√Σm), sound on stiff and jammed cloth; or RelativeResidual, the
  /// block-Jacobi residual against the cold start's. Hard substeps use RelativeResidual at
  /// tightCgTolerance whatever this says.
  PcgStopping cgStopping = PcgStopping::VelocityError;
  int cgMaxIterations = 200;  ///< PCG iteration cap per solve
  /// Preconditioner of the PCG (see PreconditionerKind). Gauss–Seidel by default (runs on a
  /// shared machine, 1 thread, weft-solver-compare): curtain ×1 0.43x the iterations, 0.6x the
  /// solve time and 0.92–0.94x the CPU per frame of block Jacobi, ×4 0.42x and 0.78–0.80x with 0
  /// capped frames instead of 8; stress scene 2 ×10³ 0 capped frames instead of 12 of 90. Its order comes from the cloth's
  /// mesh, so skipped zero terms and removed pins give the same bits as assembling them or
  /// filtering the pins. Block Jacobi is cheaper per iteration; both meet the same tolerance, but
  /// the answers differ within it (contact scenes end with other max strains).
  PreconditionerKind preconditioner = PreconditionerKind::MulticolorGaussSeidel;
  bool warmStart = true;      ///< start each PCG from the previous step's Δv
  /// Take pinned vertices out of the implicit system (their known velocity change moves to the
  /// right-hand side) instead of keeping them in it filtered (S = 0). Same equations, so the same
  /// motion up to the solve tolerance; the solve shrinks by one row per pin. false is for checks.
  bool removePinnedVertices = true;
};

}  // namespace weft
