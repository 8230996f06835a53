// DynamicSystem: what an integrator sees of the thing it advances.
//
// A second-order system M ẍ = f(x, ẋ, t) over vertices, some of whose motion is prescribed
// (pins). Explicit integrators only ask for forces; the implicit one also asks the system to
// linearise itself into A = M − h ∂f/∂v − h² ∂f/∂x. Keeping the integrators behind this small
// interface lets every integrator run on any scene, and lets tests drive them with tiny
// analytic systems (a linear oscillator, a pendulum) through exactly the same code.
#pragma once

#include "solver/BlockSparseMatrix.h"
#include "solver/ContactCoupling.h"
#include "solver/FreeVertexMap.h"
#include "solver/VertexFilter.h"

#include <weft/Math.h>
#include <weft/threading/TaskSystem.h>

#include <span>
#include <vector>

namespace weft {

class DynamicSystem {
 public:
  virtual ~DynamicSystem() = default;

  /// Number of vertices (3 degrees of freedom each).
  virtual Index vertexCount() const = 0;
  /// kg per vertex; every mass is finite and positive.
  virtual const std::vector<Real>& masses() const = 0;

  /// Total force f(x, v, t) in N on every vertex (prescribed ones included; integrators ignore
  /// those). Returns the potential energy in J (elastic plus gravitational).
  virtual Real computeForces(const Vec3Array& x, const Vec3Array& v, Real t, Vec3Array& f) = 0;

  /// Assembles systemMatrix() = M − h ∂f/∂v − h² ∂f/∂x at (x, v, t), and writes f(x, v, t) and
  /// (∂f/∂x)·velocityForProduct. The Jacobians are the definite ones the solver needs.
  /// Returns the potential energy in J, as computeForces() does.
  virtual Real linearize(const Vec3Array& x, const Vec3Array& v, Real t, Real h, Vec3Array& f,
                         const Vec3Array& velocityForProduct, Vec3Array& stiffnessTimesVelocity) = 0;
  /// The matrix linearize() assembles into; its pattern never changes. Its rows are the
  /// vertices of freeVertexMap() (all vertices when that is null).
  virtual const BlockSparseMatrix& systemMatrix() const = 0;

  /// Rows of systemMatrix(): null when row i is vertex i. Prescribed vertices without a row are
  /// removed from the solve; their known velocity change enters through
  /// subtractPrescribedCoupling(). Prescribed vertices with a row are filtered (S = 0).
  virtual const FreeVertexMap* freeVertexMap() const { return nullptr; }
  /// rows[r] −= Σ_p A(r, p) deltaV[p] over the removed prescribed vertices p, with the blocks of
  /// the last linearize(); deltaV is indexed by vertex, rows by row. Default: nothing is removed.
  virtual void subtractPrescribedCoupling(const Vec3Array& deltaV, Vec3Array& rows) const {
    (void)deltaV, (void)rows;
  }

  /// Colours of systemMatrix()'s rows for the Gauss–Seidel preconditioner's order
  /// (FilteredPcg::setRowColors): fixed by the system's topology, not by which of its couplings
  /// are assembled or which vertices are rows, so neither changes the solve's bits. Empty: the
  /// solver colours the matrix pattern.
  virtual std::span<const Index> rowColors() const { return {}; }

  /// Vertices whose motion is prescribed (pinned), in increasing order.
  virtual std::span<const Index> prescribedVertices() const = 0;
  /// Writes the prescribed position (m) and velocity (m/s) at time t into x and v for every
  /// prescribed vertex; leaves the others untouched.
  virtual void applyPrescribedMotion(Real t, Vec3Array& x, Vec3Array& v) const = 0;

  /// Adds contact constraints to the implicit solve's filter for a step of length h from (x, v)
  /// (Baraff & Witkin §5.3), releasing the previous step's first. The filter is indexed by row
  /// of systemMatrix() (see freeVertexMap()). Default: no contacts.
  virtual void constrainContacts(const Vec3Array& x, const Vec3Array& v, Real h,
                                 VertexFilter& filter) {
    (void)x, (void)v, (void)h, (void)filter;
  }

  /// After an implicit step: by row of systemMatrix(), the impulse (N·s) the row's contact
  /// constraint applied along its constrained direction in the solve, (A Δv − b)·p (Baraff &
  /// Witkin's constraint force times h; positive pushes along p), zero for a row without one.
  /// The step's velocity change hides it (the constraint cancels the forces it resists), and
  /// Coulomb friction needs it (the contact projection's budget). Default: ignored.
  virtual void receiveContactImpulses(std::span<const Real> byRow) { (void)byRow; }

  /// Rank-one couplings of the system matrix outside its block pattern, from the last
  /// linearize() (self-contacts, ContactCoupling.h): the full matrix is systemMatrix() +
  /// Σ coefficient · JᵀJ, their forces are already in f. Indexed by vertex (not by row). Default:
  /// none.
  virtual std::span<const ContactCoupling> contactCouplings() const { return {}; }

  /// Where the integrator may run its own parallel loops (the linear solve); null: serial.
  virtual TaskSystem* taskSystem() { return nullptr; }
};

}  // namespace weft
