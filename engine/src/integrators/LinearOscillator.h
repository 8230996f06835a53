// LinearOscillator: one vertex of mass m on an isotropic linear spring to the origin with linear
// damping, f = −k x − c_d v. The smallest DynamicSystem there is: stableStepLimit() reads each
// integrator's amplification matrix off it, and the tests compare integrators with its exact
// solutions through the same code paths the cloth uses.
#pragma once

#include "integrators/DynamicSystem.h"

namespace weft {

class LinearOscillator final : public DynamicSystem {
 public:
  /// mass in kg, stiffness in N/m, dampingRate c in 1/s (force −m c v).
  LinearOscillator(Real mass, Real stiffness, Real dampingRate)
      : m_masses{mass}, m_stiffness(stiffness), m_damping(mass * dampingRate),
        m_matrix(1, std::span<const std::array<Index, 2>>()) {}

  Index vertexCount() const override { return 1; }
  const std::vector<Real>& masses() const override { return m_masses; }

  Real computeForces(const Vec3Array& x, const Vec3Array& v, Real, Vec3Array& f) override {
    f.resize(1);
    f[0] = -m_stiffness * x[0] - m_damping * v[0];
    return 0.5 * m_stiffness * x[0].squaredNorm();
  }

  Real linearize(const Vec3Array& x, const Vec3Array& v, Real t, Real h, Vec3Array& f,
                 const Vec3Array& velocityForProduct, Vec3Array& stiffnessTimesVelocity) override {
    const Real energy = computeForces(x, v, t, f);
    // A = M − h ∂f/∂v − h² ∂f/∂x with ∂f/∂x = −k I and ∂f/∂v = −c_d I.
    m_matrix.block(m_matrix.diagonalSlot(0)) =
        (m_masses[0] + h * m_damping + h * h * m_stiffness) * Mat3::Identity();
    stiffnessTimesVelocity.resize(1);
    stiffnessTimesVelocity[0] = -m_stiffness * velocityForProduct[0];
    return energy;
  }
  const BlockSparseMatrix& systemMatrix() const override { return m_matrix; }

  std::span<const Index> prescribedVertices() const override { return {}; }
  void applyPrescribedMotion(Real, Vec3Array&, Vec3Array&) const override {}

 private:
  std::vector<Real> m_masses;
  Real m_stiffness;
  Real m_damping;  // N·s/m
  BlockSparseMatrix m_matrix;
};

}  // namespace weft
