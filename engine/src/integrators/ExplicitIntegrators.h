// Explicit integrators (see Integrator.h). Each keeps its own scratch arrays.
#pragma once

#include "integrators/Integrator.h"

namespace weft {

/// x_{n+1} = x_n + h v_n, v_{n+1} = v_n + h a(x_n, v_n). First order.
class ExplicitEuler final : public Integrator {
 public:
  IntegratorKind kind() const override { return IntegratorKind::ExplicitEuler; }
  int order() const override { return 1; }
  void step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
            IntegratorReport& report) override;

 private:
  Vec3Array m_force, m_acceleration;
};

/// v_{n+1} = v_n + h a(x_n, v_n), x_{n+1} = x_n + h v_{n+1}. First order, symplectic.
class SymplecticEuler final : public Integrator {
 public:
  IntegratorKind kind() const override { return IntegratorKind::SymplecticEuler; }
  int order() const override { return 1; }
  void step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
            IntegratorReport& report) override;

 private:
  Vec3Array m_force, m_acceleration;
};

/// Explicit midpoint (second-order Runge–Kutta).
class Midpoint final : public Integrator {
 public:
  IntegratorKind kind() const override { return IntegratorKind::Midpoint; }
  int order() const override { return 2; }
  void step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
            IntegratorReport& report) override;

 private:
  Vec3Array m_force, m_acceleration, m_midPosition, m_midVelocity;
};

/// Classic fourth-order Runge–Kutta.
class RungeKutta4 final : public Integrator {
 public:
  IntegratorKind kind() const override { return IntegratorKind::RungeKutta4; }
  int order() const override { return 4; }
  void step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
            IntegratorReport& report) override;

 private:
  Vec3Array m_force, m_stagePosition, m_stageVelocity, m_positionSum, m_velocitySum,
      m_acceleration;
};

}  // namespace weft
