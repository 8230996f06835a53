// The pendulum: one 1 kg vertex hung from two pinned vertices by stiff springs (one triangle of
// mass–spring cloth), swinging about the line through the pins. Its small swings have the closed
// form θ(t) = θ₀ cos(ω t), ω = √(g / L), against which an integrator's numerical damping and
// period error are read (tests of the default dynamics, weft-error-time --scene pendulum).
//
//     pin (−½, 0, 0) ●───────● pin (½, 0, 0)
//                      \   /
//                       \ /   springs of rest length √(¼ + L²): the bob swings about the x axis
//                        ●    bob at (0, −L cos θ, L sin θ)
#pragma once

#include <weft/engine/World.h>

#include <complex>
#include <memory>

namespace weft {

/// Settings of a pendulum.
struct PendulumSettings {
  Real length = 1.0;             ///< m, L: the bob's distance from the axis through the pins
  Real amplitude = 0.0872664626; ///< rad, θ₀ (5°): small, so that the swing is linear to 0.05 %
  /// N/m per spring: stiff, so that the springs stretch by m g / (2k) ≈ 5 µm and their own mode
  /// (≈ 450 rad/s) is far above the swing's (≈ 3 rad/s).
  Real springStiffness = 1e5;
  SolverSettings solver;         ///< the engine's default solver
};

/// A World with the pendulum in it (no air drag, no spring damping: only the integrator damps).
class PendulumScene {
 public:
  static constexpr Real kFrameDt = 1.0 / 60.0;  ///< s, one frame
  static constexpr Real kGravity = 9.81;        ///< m/s²

  /// Builds the scene; fails on invalid settings, with the reason.
  static Result<PendulumScene> create(const PendulumSettings& settings = {});

  /// Advances one frame of 1/60 s (substeps as the solver plans them).
  StepStatus stepFrame() { return m_world->step(kFrameDt); }
  /// rad, the bob's angle from hanging straight down, about the pins' axis.
  Real angle() const;
  /// rad/s, √(g / L): the closed-form small-swing frequency.
  Real frequency() const;
  /// The factor by which an implicit method multiplies the complex amplitude of the linear swing
  /// each step of h at a constant step, from its characteristic equation on y' = λy, z = iωh:
  /// backward Euler 1/(1 − z), modulus (1 + ω²h²)^(−1/2); BDF2 (3/2 − z)ρ² − 2ρ + ½ = 0, the
  /// root that tends to 1 as h → 0: ρ = (2 + √(1 + 2z))/(3 − 2z). Its modulus is the amplitude
  /// kept per step, its argument the phase advanced (the period is 2π h / arg ρ). NaN for explicit methods.
  static std::complex<Real> growthFactor(IntegratorKind kind, Real omegaH);
  /// The world that holds the pendulum.
  World& world() { return *m_world; }

 private:
  PendulumScene() = default;
  std::unique_ptr<World> m_world;
  ClothId m_cloth;
  Real m_length = 1;
};

}  // namespace weft
