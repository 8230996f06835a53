// HealthMonitor: the checks that tell a diverging integration from motion, and the retry policy.
//
// After every substep the state must be finite, no vertex faster than 10⁴ m/s and none farther
// than 10⁹ m from the origin (a NaN spreads through the whole mesh within one solve; a diverging
// explicit method passes any physical speed within a few substeps; a frame of 10³⁰⁸ s carries a
// slow cloth where doubles cannot tell its vertices apart, and every pair of its triangles would
// be a contact to test). After every attempt at a frame, no edge may have grown past 100 times
// its rest length (and longer than at the frame start), and the kinetic energy may not exceed 100
// times what the frame could supply: what the cloth had, the cloth thrown at the fastest driver's
// speed (pins, collider surfaces, wind), a fall through its own size, and the work of the
// caller's forces. The thresholds sit far above any physical motion. A failed frame is restored
// and retried with twice the substeps, kMaxRetries times; if it still fails the world stays where
// the frame started, and the step's flags say so.
#pragma once

#include "contact/ContactSpace.h"

#include <weft/collision/RigidMotion.h>
#include <weft/engine/StepStats.h>

#include <span>

namespace weft {

class Cloth;

/// Strain (l / l_rest − 1) of a diverged integration: cloth tears long before.
inline constexpr Real kDivergedStrain = 99;

/// Retries of a failed frame, each with twice the substeps: up to 8 times the planned number.
inline constexpr int kMaxHealthRetries = 3;

/// The substep check over every vertex of the contact space.
HealthFailure checkSubstepHealth(const ContactSpace& space);

/// The end-of-frame check of one cloth, given its strain and kinetic energy at the frame start
/// and end and the colliders' motions at the frame start.
HealthFailure checkFrameHealth(const Cloth& cloth, Real startStrain, Real startKinetic,
                               Real endStrain, Real endKinetic,
                               std::span<const RigidMotion> colliderStarts);

}  // namespace weft
