#include "integrators/Bdf2.h"

#include <algorithm>
#include <cmath>

namespace weft {
namespace {

// The carried state's layout: a header (warm-start count, history flag, h_{n−1}), a second one
// (the time the last step ended), then the warm start, x_{n−1} and v_{n−1}.
constexpr std::size_t kHeaderSize = 2;

}  // namespace

void Bdf2::reset() {
  m_implicit.reset();
  m_hasHistory = false;
}

void Bdf2::step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
                IntegratorReport& report) {
  const std::size_t n = x.size();
  // The history serves only a step that follows on from the last one (1e-6 h forgives the
  // round-off of substep times summed within a frame) at a ratio BDF2 is stable at.
  const Real ratio = m_hasHistory ? h / m_previousStep : 0;
  const bool useHistory = m_hasHistory && m_previousPosition.size() == n &&
                          std::abs(t - m_nextTime) <= 1e-6 * h && ratio > 0 &&
                          ratio <= kMaxStepRatio * (1 + 1e-9);  // 2h / h may round above 2
  ImplicitStepHistory history;
  m_positionOffset.resize(n);  // sized on the first step: no allocation later
  m_velocityOffset.resize(n);
  if (useHistory) {
    const Real denominator = 1 + 2 * ratio;
    const Real b = ratio * ratio / denominator;
    history.beta = (1 + ratio) / denominator;
    for (std::size_t i = 0; i < n; ++i) {
      m_positionOffset[i] = b * (x[i] - m_previousPosition[i]);
      m_velocityOffset[i] = b * (v[i] - m_previousVelocity[i]);
    }
    history.positionOffset = &m_positionOffset;
    history.velocityOffset = &m_velocityOffset;
  }
  // The next step's history: this step's start (assignment keeps the capacity).
  m_previousPosition = x;
  m_previousVelocity = v;
  m_implicit.stepWithHistory(system, x, v, t, h, history, report);
  m_previousStep = h;
  m_nextTime = t + h;
  m_hasHistory = true;
}

void Bdf2::saveCarriedState(Vec3Array& out) const {
  // Straight into `out`, whose capacity a frame-start save reuses: no allocation in a steady step.
  const std::span<const Vec3> warm = m_implicit.warmStart();
  out.clear();
  if (warm.empty() && !m_hasHistory) return;
  out.reserve(kHeaderSize + warm.size() + 2 * m_previousPosition.size());
  out.push_back(Vec3(Real(warm.size()), m_hasHistory ? 1 : 0, m_previousStep));
  out.push_back(Vec3(m_nextTime, 0, 0));
  out.insert(out.end(), warm.begin(), warm.end());
  if (m_hasHistory) {
    out.insert(out.end(), m_previousPosition.begin(), m_previousPosition.end());
    out.insert(out.end(), m_previousVelocity.begin(), m_previousVelocity.end());
  }
}

std::size_t Bdf2::carriedStateCapacity(std::size_t vertexCount) const {
  return kHeaderSize + 3 * vertexCount;  // the warm start, x_{n−1} and v_{n−1}
}

void Bdf2::restoreCarriedState(const Vec3Array& in) {
  reset();
  if (in.size() < kHeaderSize) return;
  const std::size_t warmCount = std::size_t(in[0].x());
  const bool history = in[0].y() != 0;
  if (kHeaderSize + warmCount > in.size()) return;  // not this integrator's state: start afresh
  const std::size_t rest = in.size() - kHeaderSize - warmCount;
  if (history ? rest % 2 != 0 : rest != 0) return;
  const auto warmBegin = in.begin() + kHeaderSize;
  m_implicit.restoreCarriedState(Vec3Array(warmBegin, warmBegin + std::ptrdiff_t(warmCount)));
  if (history) {
    const auto positions = warmBegin + std::ptrdiff_t(warmCount);
    const auto velocities = positions + std::ptrdiff_t(rest / 2);
    m_previousPosition.assign(positions, velocities);
    m_previousVelocity.assign(velocities, in.end());
    m_previousStep = in[0].z();
    m_nextTime = in[1].x();
    m_hasHistory = true;
  }
}

void Bdf2::carryCarriedState(const RigidFit& motion) {
  m_implicit.carryCarriedState(motion);
  if (!motion.translationOnly()) {
    m_hasHistory = false;
    return;
  }
  for (Vec3& x : m_previousPosition) x = motion.apply(x);
}

}  // namespace weft
