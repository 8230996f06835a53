// ClothForces: the internal and external forces of one cloth, and their Jacobians assembled into
// the implicit system.
//
// The loop is deliberately trivial: every element (triangle, hinge or spring) asks its pure
// kernel for conditions (forces/BaraffWitkin.h, forces/SpringCondition.h), turns them into
// ElementForces (forces/Condition.h), and scatters the result through slots precomputed at set-up
// into the block-sparse matrix. There is no search and no allocation in a step.
//
// Determinism: elements are visited in model order and each writes its own blocks in a fixed
// order, so the sums are identical run to run. (Parallel assembly comes with the threading work:
// it will colour elements or gather per row, keeping the same bits on any thread count.)
#pragma once

#include "forces/Condition.h"
#include "solver/BlockSparseMatrix.h"

#include <weft/engine/ClothModel.h>
#include <weft/engine/Material.h>

#include <array>
#include <vector>

namespace weft {

/// Everything that decides the forces on one cloth.
struct ClothForceSettings {
  ForceModel model = ForceModel::BaraffWitkin;  ///< continuum or springs
  ClothMaterial material;                       ///< continuum material (and density, drag)
  MassSpringMaterial springs;                   ///< spring stiffnesses for ForceModel::MassSpring
  Vec3 gravity{0.0, -9.81, 0.0};                ///< m/s²
  Vec3 wind{0.0, 0.0, 0.0};                     ///< m/s, air velocity for the drag force
  StiffnessMode stiffnessMode = StiffnessMode::Definite;  ///< Jacobian treatment (keep Definite)
};

class ClothForces {
 public:
  /// Precomputes element tables from the model. `masses` in kg, one per vertex.
  ClothForces(const ClothModel& model, const ClothForceSettings& settings, std::vector<Real> masses);

  /// Vertex pairs that some element couples: the sparsity pattern of the system matrix.
  std::vector<std::array<Index, 2>> coupledPairs() const;
  /// Looks up, once, the matrix slot of every block every element writes.
  void bindMatrix(const BlockSparseMatrix& matrix);

  /// f(x, v) in N on every vertex; returns the potential energy in J (elastic + gravity).
  Real computeForces(const Vec3Array& x, const Vec3Array& v, Vec3Array& f) const;
  /// A = M − h ∂f/∂v − h² ∂f/∂x, f(x, v) and (∂f/∂x)·velocityForProduct; returns the energy.
  Real assemble(const Vec3Array& x, const Vec3Array& v, Real h, BlockSparseMatrix& matrix,
                Vec3Array& f, const Vec3Array& velocityForProduct,
                Vec3Array& stiffnessTimesVelocity) const;

  const std::vector<Real>& masses() const { return m_masses; }
  const ClothForceSettings& settings() const { return m_settings; }

 private:
  struct Pass;  // one evaluation: what to compute and where to put it
  Real evaluate(const Pass& pass) const;

  template <int N>
  struct Element {
    std::array<Index, N> vertices;
    std::array<Index, N * N> slots;  // slot of block (vertices[a], vertices[b]) at a·N + b
  };
  struct SpringElement : Element<2> {
    Real restLength;
    Real stiffness;  // N/m
    Real damping;    // N·s/m
  };

  const ClothModel* m_model;
  ClothForceSettings m_settings;
  std::vector<Real> m_masses;
  std::vector<Element<3>> m_triangles;
  std::vector<Element<4>> m_hinges;
  std::vector<SpringElement> m_springs;
  std::vector<Index> m_diagonalSlots;
  bool m_bending = false;  // bending stiffness or damping non-zero
};

}  // namespace weft
