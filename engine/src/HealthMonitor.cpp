#include "HealthMonitor.h"

#include "Cloth.h"

#include <weft/engine/InputLimits.h>

#include <algorithm>

namespace weft {
namespace {

// m/s: no cloth motion comes near it (a 250 m/s projectile drags cloth at 250 m/s), while a
// blown-up explicit step passes it within a few substeps.
constexpr Real kDivergedSpeed = kMaxSpeed;
// Kinetic energy beyond this multiple of what the frame could supply: energy from nowhere.
constexpr Real kEnergyJumpFactor = 100;
// m/s: a speed scale below which no energy is suspicious (round-off on a cloth at rest).
constexpr Real kQuietSpeed = 0.01;

}  // namespace

HealthFailure checkSubstepHealth(const ContactSpace& space) {
  bool finite = true, slow = true, inRange = true;
  for (const Vec3& x : space.x) {
    finite = finite && x.allFinite();
    inRange = inRange && x.cwiseAbs().maxCoeff() <= kMaxSimulatedCoordinate;
  }
  for (const Vec3& v : space.v) {
    finite = finite && v.allFinite();
    slow = slow && v.squaredNorm() < kDivergedSpeed * kDivergedSpeed;
  }
  if (!finite) return HealthFailure::NonFinite;
  if (!slow) return HealthFailure::Speed;
  if (!inRange) return HealthFailure::OutOfRange;
  return HealthFailure::None;
}

HealthFailure checkFrameHealth(const Cloth& cloth, Real startStrain, Real startKinetic,
                               Real endStrain, Real endKinetic,
                               std::span<const RigidMotion> colliderStarts) {
  if (endStrain > kDivergedStrain && endStrain > startStrain) return HealthFailure::Strain;
  // The energy the frame could give the cloth: what it had (kinetic, and elastic: the potential
  // minus gravity's part, −Σ m g·x), the whole cloth thrown at the fastest driver's speed, a
  // free fall through its own size, and the work of the per-vertex external forces.
  const std::vector<Real>& mass = cloth.masses();
  const Vec3& gravity = cloth.forces().settings().gravity;
  const Vec3Array& start = cloth.frameStartPositions();
  Real totalMass = 0, gravityPotential = 0;
  for (Index i = 0; i < cloth.vertexCount(); ++i) {
    totalMass += mass[i];
    gravityPotential -= mass[i] * gravity.dot(start[i]);
  }
  const Real elastic = std::max<Real>(0, cloth.frameStartPotential() - gravityPotential);
  const Real size = cloth.model().characteristicLength();
  const Real frameLength = cloth.frameLength();
  Real driverSpeed = std::max({kQuietSpeed, cloth.forces().settings().wind.norm(),
                               cloth.largestPinTravel() / frameLength});
  for (const RigidMotion& motion : colliderStarts) {
    const Real reach = (motion.pose.position - start[0]).norm() + size;
    driverSpeed = std::max(driverSpeed, motion.linearVelocity.norm() +
                                            motion.angularVelocity.norm() * reach);
  }
  // Work of the caller's per-vertex forces: at most |F| times how far the vertex can go.
  Real externalWork = 0;
  const Vec3Array& external = cloth.forces().externalForces();
  const Vec3Array& startVelocity = cloth.frameStartVelocities();
  for (std::size_t i = 0; i < external.size(); ++i) {
    const Real force = external[i].norm();
    if (force == 0) continue;
    const Real T = frameLength;
    externalWork += force * (size + startVelocity[i].norm() * T + force * T * T / mass[i]);
  }
  const Real available = startKinetic + elastic + externalWork +
                         0.5 * totalMass * (driverSpeed * driverSpeed + 2 * gravity.norm() * size);
  if (endKinetic > kEnergyJumpFactor * available) return HealthFailure::EnergyJump;
  return HealthFailure::None;
}

}  // namespace weft
