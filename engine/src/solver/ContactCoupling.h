// ContactCoupling: the implicit step's self-contact terms, which couple the four vertices of a
// contact pair outside the system matrix's fixed block pattern.
//
// Design note.
// - The term. A self-contact pair (vertex–triangle or edge–edge, ContactResolver) is four vertices
//   with signed barycentric weights w (Σ w = 0: the first side minus the second) and a unit normal
//   n from the second side to the first. Its gap is d = nᵀ Σ_k w_k x_k = J x with the 1×12 row
//   J = (w_0 nᵀ, …, w_3 nᵀ). A penalty keeps d at the thickness d₀ while the pair is in contact:
//       E = ½ k (d₀ − d)²,   f = −∂E/∂x = k (d₀ − d) Jᵀ,   ∂f/∂x = −k JᵀJ,
//   and a damping along the normal, f = −c Jᵀ J v, ∂f/∂v = −c JᵀJ. With n and w frozen over the
//   step (they are taken at the step start) f is linear in x and v, so backward Euler treats the
//   term exactly: it adds (h² k + h c) JᵀJ to A = M − h ∂f/∂v − h² ∂f/∂x. That is symmetric
//   positive semidefinite of rank one, so A stays SPD and A ⪰ M (the velocity test's bound holds).
//   Block (i, j) of JᵀJ is w_i w_j n nᵀ.
// - Why not in the matrix. The system matrix has a fixed block pattern (the mesh's couplings);
//   the pairs change every step and join vertices the mesh does not. FilteredPcg takes the terms
//   as a list and applies them itself (matrix-free): the product (A + E) c is A's SpMV plus
//   Σ_terms coefficient · Jᵀ (J c), a rank-one update per pair (addCouplingProduct), run serially
//   in list order, so its bits do not depend on the thread count. Contacts are few (hundreds)
//   against thousands of rows.
// - Removed rows. A vertex without a row of the solve (a removed pin, FreeVertexMap) has
//   kInvalidIndex here: its known velocity change enters the right-hand side instead
//   (ImplicitEuler), exactly as the pin coupling of the mesh does.
#pragma once

#include <weft/Math.h>

#include <array>
#include <span>

namespace weft {

/// One rank-one coupling coefficient · JᵀJ of up to four rows, J = (w_0 nᵀ, …, w_3 nᵀ).
struct ContactCoupling {
  /// Rows (or vertices, where the owner says so); kInvalidIndex: no row, the entry is skipped.
  std::array<Index, 4> rows{kInvalidIndex, kInvalidIndex, kInvalidIndex, kInvalidIndex};
  std::array<Real, 4> weights{};  ///< signed barycentric weights w
  Vec3 normal = Vec3::Zero();     ///< unit normal n
  Real coefficient = 0;           ///< kg, h² k + h c: what the term adds to A (≥ 0)
  /// N, the term's normal force at the expansion point (spring and damping: k (d₀ − d) − c J v),
  /// for the system that owns the term; the solve itself reads only the rows above.
  Real force = 0;
  /// N/s, the normal part of ∂f/∂x times the product velocity (−k J v): BW98's h ∂f/∂x v term.
  Real stiffnessTimesVelocity = 0;
};

/// The penalty of one pair at positions x: its gap d = J x (m), the spring's normal force
/// λ = k (d₀ − d) (N; vertex k's force is λ w_k n), extended linearly beyond d₀ where it is
/// negative (it would pull: the integrator's active set drops such a term), and the energy
/// ½ k (d₀ − d)² (J) while in contact (d < d₀), zero apart. A pure kernel, tested alone.
struct ContactPenalty {
  Real gap = 0;
  Real energy = 0;
  Real force = 0;
  bool active = false;
};
ContactPenalty contactPenalty(std::span<const Vec3, 4> positions, const std::array<Real, 4>& weights,
                              const Vec3& normal, Real thickness, Real stiffness);

/// J v = nᵀ Σ_k w_k v_k over the entries with a row (kInvalidIndex rows contribute nothing).
Real couplingRate(const ContactCoupling& term, const Vec3Array& v);

/// y += Σ_terms coefficient · Jᵀ (J x) over rows, in list order (serial: the same bits on any
/// thread count). offDiagonalOnly: leaves out the blocks (i, i) of each term (i.e. adds
/// coefficient · w_i n Σ_{j≠i} w_j nᵀ x_j), the part a preconditioner that holds the diagonal
/// blocks does not see.
void addCouplingProduct(std::span<const ContactCoupling> terms, const Vec3Array& x, Vec3Array& y,
                        bool offDiagonalOnly = false);

/// The diagonal block coefficient · w_i² n nᵀ of entry i of a term.
inline Mat3 couplingDiagonalBlock(const ContactCoupling& term, int entry) {
  const Real scale = term.coefficient * term.weights[entry] * term.weights[entry];
  return scale * (term.normal * term.normal.transpose());
}

}  // namespace weft
