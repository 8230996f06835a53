// Integrator: advances a DynamicSystem by one step h.
//
// Six methods behind one interface (SolverSettings::integrator). The explicit ones only
// evaluate forces; ImplicitEuler linearises once per step as in Baraff & Witkin 1998 (eq. 16),
// optionally followed by Newton iterations on the full backward-Euler equations, and solves with
// the filtered PCG; Bdf2 takes the same step with a two-step history (Bdf2.h). Prescribed (pinned) vertices follow DynamicSystem::applyPrescribedMotion()
// at every stage, so every method can run every scene.
#pragma once

#include "RigidFit.h"
#include "integrators/DynamicSystem.h"

#include <weft/engine/SolverSettings.h>

#include <memory>

namespace weft {

/// What one step did, for statistics and health.
struct IntegratorReport {
  int linearSolves = 0;       ///< PCG solves in this step (implicit only)
  int cgIterations = 0;       ///< PCG iterations summed over the solves
  Real cgResidual = 0;        ///< relative residual of the last solve
  bool cgConverged = true;    ///< false when any solve hit its iteration cap
  Real potentialEnergy = 0;   ///< J, at the start of the step (as evaluated by the method)
  Real assemblyMs = 0;        ///< ms spent evaluating forces and assembling the system
  Real solveMs = 0;           ///< ms spent in PCG solves
  /// Scalar unknowns of the last linear solve: 3 per row of the system (free vertices when
  /// pinned vertices are removed from the solve); 0 without a solve.
  Index solvedUnknowns = 0;
};

class Integrator {
 public:
  virtual ~Integrator() = default;

  /// An integrator of the given kind; solver settings matter to ImplicitEuler only.
  static std::unique_ptr<Integrator> create(IntegratorKind kind, const SolverSettings& settings);

  virtual IntegratorKind kind() const = 0;
  /// Order of accuracy in h (1, 2 or 4).
  virtual int order() const = 0;
  /// Advances (x, v) from time t to t + h. Allocates scratch on the first call for a size only.
  virtual void step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
                    IntegratorReport& report) = 0;
  /// Sets the linear solver's relative tolerance and iteration cap for the following steps (a
  /// frame budget's plan); methods without a linear solve ignore it.
  virtual void setSolveLimits(Real tolerance, int maxIterations) { (void)tolerance, (void)maxIterations; }
  /// Sets the tolerance and the stopping test of the following steps' solves, keeping the
  /// iteration cap (the contact-aware accuracy, SolverSettings::tightCgTolerance, per substep).
  virtual void setSolveAccuracy(Real tolerance, PcgStopping stopping) { (void)tolerance, (void)stopping; }
  /// Forgets warm-start data (after a teleport or a restore).
  virtual void reset() {}
  /// State carried from one step to the next that changes results (the implicit method's Δv
  /// warm start): saved and restored with the world so a restored world continues bit for bit.
  /// Empty when the method carries none.
  virtual void saveCarriedState(Vec3Array& out) const { out.clear(); }
  /// The most entries saveCarriedState() writes for `vertexCount` vertices, so that a caller
  /// saving it every frame sizes its buffer once.
  virtual std::size_t carriedStateCapacity(std::size_t vertexCount) const {
    (void)vertexCount;
    return 0;
  }
  /// Restores what saveCarriedState() wrote (an empty array = no carried state).
  virtual void restoreCarriedState(const Vec3Array& in) { (void)in; reset(); }
  /// Moves the carried state with a rigid motion of the whole system (a pin teleport): positions
  /// as motion.apply() moves them, world-axis vectors turned by motion.rotation.
  virtual void carryCarriedState(const RigidFit& motion) { (void)motion; }
};

/// Largest step h (s) at which `kind` keeps a damped linear mode ẍ = −ω² x − c ẋ from growing by
/// more than a factor (1 + growthPerStep) per step. ω in rad/s, c in 1/s. Infinity for the
/// implicit methods. Found from the method's own amplification matrix (it steps a one-vertex
/// oscillator through the same code), so it is exact for every method without a formula each.
Real stableStepLimit(IntegratorKind kind, Real omega, Real dampingRate, Real growthPerStep);

}  // namespace weft
