// ContactCoupling: see the design note in the header.
#include <solver/ContactCoupling.h>

namespace weft {

ContactPenalty contactPenalty(std::span<const Vec3, 4> positions, const std::array<Real, 4>& weights,
                              const Vec3& normal, Real thickness, Real stiffness) {
  ContactPenalty penalty;
  Vec3 point = Vec3::Zero();
  for (int k = 0; k < 4; ++k) point += weights[k] * positions[k];
  penalty.gap = normal.dot(point);
  const Real overlap = thickness - penalty.gap;
  penalty.force = stiffness * overlap;
  penalty.active = penalty.gap < thickness;
  if (penalty.active) penalty.energy = Real(0.5) * stiffness * overlap * overlap;
  return penalty;
}

Real couplingRate(const ContactCoupling& term, const Vec3Array& v) {
  Vec3 sum = Vec3::Zero();
  for (int k = 0; k < 4; ++k) {
    if (term.rows[k] != kInvalidIndex) sum += term.weights[k] * v[term.rows[k]];
  }
  return term.normal.dot(sum);
}

void addCouplingProduct(std::span<const ContactCoupling> terms, const Vec3Array& x, Vec3Array& y,
                        bool offDiagonalOnly) {
  for (const ContactCoupling& term : terms) {
    // nᵀ x_k per entry, then entry i gets coefficient · w_i n Σ_j w_j (nᵀ x_j).
    std::array<Real, 4> along{};
    for (int k = 0; k < 4; ++k) {
      if (term.rows[k] != kInvalidIndex) along[k] = term.weights[k] * term.normal.dot(x[term.rows[k]]);
    }
    for (int i = 0; i < 4; ++i) {
      if (term.rows[i] == kInvalidIndex) continue;
      Real rate = 0;  // summed in entry order, without the entry itself when off-diagonal only
      for (int j = 0; j < 4; ++j) {
        if (!(offDiagonalOnly && j == i)) rate += along[j];
      }
      y[term.rows[i]] += (term.coefficient * term.weights[i] * rate) * term.normal;
    }
  }
}

}  // namespace weft
