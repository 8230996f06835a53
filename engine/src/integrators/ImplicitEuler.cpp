#include "integrators/ImplicitEuler.h"

#include <weft/threading/FrameClock.h>
#include <weft/threading/Profiler.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace weft {
namespace {

// Re-solves of a step after the self-contact active set changed (ImplicitEuler::
// updateActiveCouplings); each costs a warm-started solve. One pass settles crumpled cloth about
// as often as four. Without the active set (every pair within a thickness at the start kept,
// pulling or not) the penalty springs glue the layers and a crumpled pile keeps stirring.
constexpr int kContactReleasePasses = 2;
// Re-solves of a step after contact constraints that pulled were released (BW98 §5.3): a
// constraint whose impulse (A Δv − b)·n is negative holds a vertex on a collider that the
// cloth's forces would take off it. A released vertex is free in the re-solve; the contact
// projection still keeps it out. Without the release the constraints of the predicted motion
// glue cloth to the floor (a sheet pulled 1.5 m up stays down).
constexpr int kConstraintReleasePasses = 2;

}  // namespace

void ImplicitEuler::reset() { m_hasWarmStart = false; }

void ImplicitEuler::saveCarriedState(Vec3Array& out) const {
  if (m_hasWarmStart) out = m_deltaV;
  else out.clear();
}

void ImplicitEuler::restoreCarriedState(const Vec3Array& in) {
  if (in.empty()) {
    reset();
    return;
  }
  resizeVertices(Index(in.size()));
  m_deltaV = in;
  m_hasWarmStart = true;
}

void ImplicitEuler::carryCarriedState(const RigidFit& motion) {
  // The warm start is a velocity change: a translation leaves it as it is.
  if (!m_hasWarmStart || motion.translationOnly()) return;
  for (Vec3& deltaV : m_deltaV) deltaV = motion.rotation * deltaV;
}

void ImplicitEuler::resizeVertices(Index vertexCount) {
  if (m_deltaV.size() == vertexCount) return;
  for (Vec3Array* array : {&m_deltaV, &m_force, &m_stiffnessTimesVelocity, &m_rightHandSide,
                           &m_iteratePosition, &m_iterateVelocity, &m_expansionVelocity,
                           &m_prescribedPosition, &m_prescribedVelocity}) {
    array->assign(vertexCount, Vec3::Zero());
  }
  m_hasWarmStart = false;
}

void ImplicitEuler::resizeRows(Index rowCount) {
  if (m_correction.size() == rowCount && m_filter.size() == rowCount) return;
  m_pcg.resize(rowCount);
  m_filter.resize(rowCount);
  m_filteredRows.clear();
  m_correction.assign(rowCount, Vec3::Zero());
  m_rowRightHandSide.assign(rowCount, Vec3::Zero());
  m_rowMass.assign(rowCount, 0);
  m_contactImpulse.assign(rowCount, 0);
}

void ImplicitEuler::measureContactImpulses(const DynamicSystem& system) {
  // The solve meets A Δv = b on the free directions only; along a contact's constrained
  // direction p the difference (A Δv − b)·p is the impulse the constraint gave the vertex (the
  // self-contact couplings are part of A, as in the solve).
  const BlockSparseMatrix& matrix = system.systemMatrix();
  for (Index row = 0; row < Index(m_contactImpulse.size()); ++row) {
    const ConstraintKind kind = m_filter.kind(row);
    m_contactImpulse[row] = 0;
    if (kind != ConstraintKind::OneDirection && kind != ConstraintKind::TwoDirections) continue;
    m_contactImpulse[row] = m_filter.direction(row, 0).dot(
        matrix.multiplyRow(row, m_correction) - m_rowRightHandSide[row]);
  }
  for (const ContactCoupling& term : m_rowCouplings) {
    const Real rate = term.coefficient * couplingRate(term, m_correction);
    for (int k = 0; k < 4; ++k) {
      const Index row = term.rows[k];
      if (row == kInvalidIndex) continue;
      const ConstraintKind kind = m_filter.kind(row);
      if (kind != ConstraintKind::OneDirection && kind != ConstraintKind::TwoDirections) continue;
      m_contactImpulse[row] += rate * term.weights[k] * term.normal.dot(m_filter.direction(row, 0));
    }
  }
}

void ImplicitEuler::gatherCouplings(const DynamicSystem& system, const FreeVertexMap& map,
                                    bool removedPins, Real h, bool newton) {
  m_rowCouplings.clear();  // keeps its capacity
  const std::span<const ContactCoupling> terms = system.contactCouplings();
  for (std::size_t index = 0; index < terms.size(); ++index) {
    if (!m_couplingActive[index]) continue;
    ContactCoupling term = terms[index];
    // The term's share of b: h (F + h K v) along Jᵀ (BW98 eq. 16), h F in a Newton iteration.
    const Real impulse =
        newton ? h * term.force : h * (term.force + h * term.stiffnessTimesVelocity);
    // A vertex without a row (a removed pin) has a known Δv: its coupling moves to the right-hand
    // side, b_i −= coefficient · w_i n Σ_p w_p nᵀ Δv_p, as the mesh's pin coupling does.
    Real removedRate = 0;
    for (int k = 0; k < 4; ++k) {
      if (term.rows[k] == kInvalidIndex) continue;
      const Index vertex = term.rows[k];
      term.rows[k] = map.row(vertex);
      if (term.rows[k] == kInvalidIndex && removedPins) {
        removedRate += term.weights[k] * term.normal.dot(m_deltaV[vertex]);
      }
    }
    const Real push = impulse - term.coefficient * removedRate;
    for (int k = 0; k < 4; ++k) {
      if (term.rows[k] == kInvalidIndex) continue;
      m_rowRightHandSide[term.rows[k]] += (push * term.weights[k]) * term.normal;
    }
    m_rowCouplings.push_back(term);
  }
}

bool ImplicitEuler::updateActiveCouplings(const DynamicSystem& system, Real h) {
  const std::span<const ContactCoupling> terms = system.contactCouplings();
  bool changed = false;
  for (std::size_t index = 0; index < terms.size(); ++index) {
    const ContactCoupling& term = terms[index];
    // The term's normal force at the end of the step is (impulse − coefficient · J Δv) / h, with
    // J Δv over all four vertices (removed pins' known Δv included: m_deltaV is by vertex).
    const Real impulse = h * (term.force + h * term.stiffnessTimesVelocity);
    const char active = impulse - term.coefficient * couplingRate(term, m_deltaV) > 0 ? 1 : 0;
    changed = changed || active != m_couplingActive[index];
    m_couplingActive[index] = active;
  }
  return changed;
}

void ImplicitEuler::solve(DynamicSystem& system, IntegratorReport& report) {
  m_pcg.setRowColors(system.rowColors());  // the Gauss–Seidel order: the system's, not the pattern's
  PcgSettings pcgSettings;
  pcgSettings.tolerance = m_settings.cgTolerance;
  pcgSettings.maxIterations = m_settings.cgMaxIterations;
  pcgSettings.warmStart = true;  // the caller prepares the initial guess in m_correction
  pcgSettings.preconditioner = m_settings.preconditioner;
  // The stopping test (SolverSettings::cgStopping); the velocity-error one weighs by the masses.
  pcgSettings.stopping = m_settings.cgStopping;
  WEFT_PROFILE_ZONE("solve");
  const std::int64_t start = FrameClock::nowNs();
  const SolveReport solve = m_pcg.solve(system.systemMatrix(), m_rowRightHandSide, m_filter,
                                        pcgSettings, m_correction, system.taskSystem(), m_rowMass,
                                        m_rowCouplings);
  report.solveMs += FrameClock::msSince(start);
  ++report.linearSolves;
  report.cgIterations += solve.iterations;
  report.cgResidual = solve.relativeResidual;
  report.cgConverged = report.cgConverged && solve.converged;
  report.solvedUnknowns = 3 * Index(m_correction.size());
}

void ImplicitEuler::keepMomentum(const DynamicSystem& system, const FreeVertexMap& map,
                                 const Vec3Array& x) {
  // The rigid motions of the cloth, Φ_i α = a + ω × r_i (r_i = x_i − c about the centre of mass
  // c), are the directions in which internal forces neither push nor turn it. Galerkin step in
  // their span: Δv += Φα with (Φᵀ A Φ) α = Φᵀ r, r = b − A Δv, so that the new residual has no
  // net force and no net torque. The PCG's early stop then changes the momentum and the angular
  // momentum no more than the exact solve does: Tᵀ A e = 0 is Tᵀ M e = 0 for a translation T (the
  // rows of the force Jacobians and of the contact couplings sum to zero; air drag aside), and
  // for a rotation R, Rᵀ A e = 0 leaves Rᵀ M e = h² (K R)ᵀ e, second order in the step, as
  // damping does not resist a rigid rotation and K R_k = e_k × f (the forces turn with the
  // cloth). A correction below the PCG's absolute floor (in the energy norm, which bounds the
  // mass norm) is one the solve does not resolve either, and is left out: a cloth at rest stays
  // exactly at rest. Rejected: the translation alone (u = Σr / Σm) leaves a free cloth turning
  // from its internal forces; M instead of A in the 6×6 system (exact only at rest).
  using Mat6 = Eigen::Matrix<Real, 6, 6>;
  using Vec6 = Eigen::Matrix<Real, 6, 1>;
  const BlockSparseMatrix& matrix = system.systemMatrix();
  const Index rows = Index(m_correction.size());
  Real mass = 0;
  Vec3 centre = Vec3::Zero();
  for (Index row = 0; row < rows; ++row) {
    mass += m_rowMass[row];
    centre += m_rowMass[row] * x[map.vertex(row)];
  }
  if (!(mass > 0)) return;
  centre /= mass;
  const auto arm = [&](Index row) -> Vec3 { return x[map.vertex(row)] - centre; };
  // Φ_iᵀ y = (y, r_i × y): a row's force and its torque about c.
  const auto project = [](const Vec3& r, const Vec3& y) {
    Vec6 out;
    out << y, r.cross(y);
    return out;
  };
  Mat6 reduced = Mat6::Zero();     // Φᵀ (A + E) Φ
  Vec6 residual = Vec6::Zero();    // Φᵀ (b − (A + E) Δv)
  for (Index row = 0; row < rows; ++row) {
    // (A Φ)_i = [Σ_j A_ij, −Σ_j A_ij [r_j]ₓ] and (A Δv)_i in one sweep over the row.
    Mat3 blockSum = Mat3::Zero(), turnSum = Mat3::Zero();
    Vec3 product = Vec3::Zero();
    for (Index slot = matrix.rowBegin(row); slot < matrix.rowEnd(row); ++slot) {
      const Mat3& block = matrix.block(slot);
      const Index column = matrix.column(slot);
      blockSum += block;
      turnSum.noalias() -= block * crossMatrix(arm(column));
      product.noalias() += block * m_correction[column];
    }
    const Vec3 r = arm(row);
    const Vec3 force = m_rowRightHandSide[row] - product;
    residual += project(r, force);
    Eigen::Matrix<Real, 3, 6> rowModes;
    rowModes << blockSum, turnSum;
    reduced.topRows<3>() += rowModes;
    reduced.bottomRows<3>().noalias() += crossMatrix(r) * rowModes;
  }
  // The contact couplings' terms c JᵀJ: J Φ and J Δv per term.
  for (const ContactCoupling& term : m_rowCouplings) {
    Vec6 modes = Vec6::Zero();
    Real rate = 0;
    for (int k = 0; k < 4; ++k) {
      const Index row = term.rows[k];
      if (row == kInvalidIndex) continue;
      modes += term.weights[k] * project(arm(row), term.normal);
      rate += term.weights[k] * term.normal.dot(m_correction[row]);
    }
    reduced.noalias() += term.coefficient * modes * modes.transpose();
    residual -= term.coefficient * rate * modes;
  }
  const Eigen::LDLT<Mat6> factor(reduced);
  Vec6 step = factor.info() == Eigen::Success ? Vec6(factor.solve(residual)) : Vec6::Zero();
  if (!step.allFinite() ||
      !(factor.vectorD().minCoeff() > 1e-12 * factor.vectorD().cwiseAbs().maxCoeff())) {
    // A degenerate cloth (a strip along one line cannot turn about it): the translation only.
    step.setZero();
    const Eigen::LDLT<Mat3> translation(reduced.topLeftCorner<3, 3>());
    step.head<3>() = translation.solve(residual.head<3>());
    if (!step.allFinite()) return;
  }
  const Real floor = PcgSettings{}.absoluteTolerance;
  if (!(step.dot(reduced * step) > floor * floor)) return;
  const Vec3 shift = step.head<3>(), turn = step.tail<3>();
  for (Index row = 0; row < rows; ++row) m_correction[row] += shift + turn.cross(arm(row));
}

void ImplicitEuler::step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
                         IntegratorReport& report) {
  stepWithHistory(system, x, v, t, h, ImplicitStepHistory{}, report);
}

void ImplicitEuler::stepWithHistory(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t,
                                    Real h, const ImplicitStepHistory& history,
                                    IntegratorReport& report) {
  const Index n = system.vertexCount();
  // The solve's step η = βh (h itself for backward Euler) and the two-step offsets, if any.
  const Real eta = history.beta * h;
  const Vec3Array* positionOffset = history.positionOffset;
  const Vec3Array* velocityOffset = history.velocityOffset;
  resizeVertices(n);
  const FreeVertexMap* systemMap = system.freeVertexMap();
  if (!systemMap && m_identityMap.vertexCount() != n) m_identityMap.build(n, {});
  const FreeVertexMap& map = systemMap ? *systemMap : m_identityMap;
  const Index rows = map.rowCount();
  resizeRows(rows);
  const std::vector<Real>& masses = system.masses();
  for (Index row = 0; row < rows; ++row) m_rowMass[row] = masses[map.vertex(row)];

  // Pins: the velocity change that puts each pinned vertex exactly on its target at t + h. A pin
  // with a row is fixed in the filter; a removed one keeps its Δv in m_deltaV, where the
  // coupling product below and the update at the end read it.
  for (Index row : m_filteredRows) m_filter.setFree(row);
  m_filteredRows.clear();  // keeps its capacity: no allocation after the first step
  // applyPrescribedMotion writes every prescribed entry, and only those are read below.
  system.applyPrescribedMotion(t + h, m_prescribedPosition, m_prescribedVelocity);
  bool removedPins = false;
  for (Index vertex : system.prescribedVertices()) {
    // x_{n+1} = x̂ + η (v_n + Δv) on the target.
    const Vec3 start = positionOffset ? Vec3(x[vertex] + (*positionOffset)[vertex]) : x[vertex];
    const Vec3 target = (m_prescribedPosition[vertex] - start) / eta - v[vertex];
    const Index row = map.row(vertex);
    if (row == kInvalidIndex) {
      m_deltaV[vertex] = target;
      removedPins = true;
    } else {
      m_filter.setFixed(row, target);
      m_filteredRows.push_back(row);
    }
  }
  // Contacts with colliders: one constrained direction each.
  system.constrainContacts(x, v, h, m_filter);

  // Baraff–Witkin step, expanded about (x_n, v_n); the stiffness acts on u (v_n without history).
  if (positionOffset) {
    for (Index i = 0; i < n; ++i) m_expansionVelocity[i] = v[i] + (*positionOffset)[i] / eta;
  }
  const Vec3Array& expansionVelocity = positionOffset ? m_expansionVelocity : v;
  {
    WEFT_PROFILE_ZONE("assembly");
    const std::int64_t start = FrameClock::nowNs();
    report.potentialEnergy =
        system.linearize(x, v, t, eta, m_force, expansionVelocity, m_stiffnessTimesVelocity);
    report.assemblyMs += FrameClock::msSince(start);
  }
  for (Index i = 0; i < n; ++i) {
    m_rightHandSide[i] = eta * (m_force[i] + eta * m_stiffnessTimesVelocity[i]);
  }
  if (velocityOffset) {
    for (Index i = 0; i < n; ++i) m_rightHandSide[i] += masses[i] * (*velocityOffset)[i];
  }
  map.gather(m_rightHandSide, m_rowRightHandSide);
  // b_f − A_fp Δv_p: the pull of removed pins on their free neighbours.
  if (removedPins) system.subtractPrescribedCoupling(m_deltaV, m_rowRightHandSide);
  // Initial guess: last step's Δv (warm start) or zero; the filter puts fixed entries on target.
  const bool warm = m_settings.warmStart && m_hasWarmStart;
  if (!warm) {
    for (Index i = 0; i < n; ++i) {
      if (map.row(i) != kInvalidIndex) m_deltaV[i].setZero();
    }
  }
  map.gather(m_deltaV, m_correction);
  // One-sided self-contacts (an active-set iteration): a penalty acts while its force at the end
  // of the step pushes. The first guess is the initial Δv's; after each solve the set is
  // updated and, if it changed, the step solved again from the last solution, a few times at
  // most (a term left pulling only delays a separation by one step, one left out lets a pair
  // approach further in one step; the self-collision pass keeps the contacts either way).
  m_couplingActive.assign(system.contactCouplings().size(), 0);  // keeps its capacity
  (void)updateActiveCouplings(system, eta);
  gatherCouplings(system, map, removedPins, eta, /*newton=*/false);
  solve(system, report);
  map.scatter(m_correction, m_deltaV);
  for (int pass = 0; pass < kContactReleasePasses && !system.contactCouplings().empty(); ++pass) {
    if (!updateActiveCouplings(system, eta)) break;
    map.gather(m_rightHandSide, m_rowRightHandSide);
    if (removedPins) system.subtractPrescribedCoupling(m_deltaV, m_rowRightHandSide);
    gatherCouplings(system, map, removedPins, eta, /*newton=*/false);
    solve(system, report);
    map.scatter(m_correction, m_deltaV);
  }
  if (system.prescribedVertices().empty() && m_filter.constrainedVertexCount() == 0) {
    keepMomentum(system, map, x);
    map.scatter(m_correction, m_deltaV);
  }
  // The contact constraints' impulses of this solve (before any Newton correction, whose
  // constraints are met already), for the system's friction. A constraint that pulls (negative
  // impulse: the cloth's forces would take the vertex off the surface) is released and the step
  // solved again (Baraff & Witkin 1998, §5.3), a few times at most: a contact may only push.
  if (m_filter.constrainedVertexCount() > Index(m_filteredRows.size())) {
    measureContactImpulses(system);
    for (int pass = 0; pass < kConstraintReleasePasses; ++pass) {
      bool released = false;
      for (Index row = 0; row < rows; ++row) {
        if (m_contactImpulse[row] < 0 && m_filter.kind(row) == ConstraintKind::OneDirection) {
          m_filter.setFree(row);
          m_contactImpulse[row] = 0;
          released = true;
        }
      }
      if (!released) break;
      solve(system, report);
      map.scatter(m_correction, m_deltaV);
      measureContactImpulses(system);
    }
    system.receiveContactImpulses(m_contactImpulse);
  } else {
    system.receiveContactImpulses({});
  }

  // Newton iterations on M Δv = h f(x_n + h(v_n + Δv), v_n + Δv); pinned vertices stay on target
  // (their correction is zero, so removed pins add nothing to the right-hand side).
  if (m_settings.newtonIterations > 0) {
    for (Index row : m_filteredRows) m_filter.setFixed(row, Vec3::Zero());
    // Contact constraints are met by Δv already: corrections stay tangent to the contacts.
    for (Index row = 0; row < rows; ++row) {
      if (m_filter.kind(row) == ConstraintKind::OneDirection) {
        m_filter.setConstrained(row, m_filter.direction(row, 0), Vec3::Zero());
      }
    }
  }
  for (int iteration = 0; iteration < m_settings.newtonIterations; ++iteration) {
    for (Index i = 0; i < n; ++i) {
      m_iterateVelocity[i] = v[i] + m_deltaV[i];
      m_iteratePosition[i] = x[i] + eta * m_iterateVelocity[i];
      if (positionOffset) m_iteratePosition[i] += (*positionOffset)[i];
    }
    {
      WEFT_PROFILE_ZONE("assembly");
      const std::int64_t start = FrameClock::nowNs();
      system.linearize(m_iteratePosition, m_iterateVelocity, t + h, eta, m_force,
                       m_iterateVelocity, m_stiffnessTimesVelocity);
      report.assemblyMs += FrameClock::msSince(start);
    }
    for (Index i = 0; i < n; ++i) m_rightHandSide[i] = eta * m_force[i] - masses[i] * m_deltaV[i];
    if (velocityOffset) {
      for (Index i = 0; i < n; ++i) m_rightHandSide[i] += masses[i] * (*velocityOffset)[i];
    }
    map.gather(m_rightHandSide, m_rowRightHandSide);
    // Every contact term again (the active set is not carried across linearisations); the pins'
    // corrections are zero.
    const std::span<const ContactCoupling> terms = system.contactCouplings();
    m_couplingActive.resize(terms.size());
    for (std::size_t index = 0; index < terms.size(); ++index) m_couplingActive[index] = terms[index].force > 0;
    gatherCouplings(system, map, /*removedPins=*/false, eta, /*newton=*/true);
    for (Index row = 0; row < rows; ++row) m_correction[row].setZero();
    solve(system, report);
    for (Index row = 0; row < rows; ++row) m_deltaV[map.vertex(row)] += m_correction[row];
  }

  for (Index i = 0; i < n; ++i) {
    v[i] += m_deltaV[i];
    x[i] += eta * v[i];
    if (positionOffset) x[i] += (*positionOffset)[i];
  }
  // Exact pin positions (the filter already made them exact up to round-off).
  system.applyPrescribedMotion(t + h, x, v);
  m_hasWarmStart = true;
}

}  // namespace weft
