// RigidFit: the rigid motion that best carries one point set onto another (Kabsch / Procrustes).
//
// A pin teleport (SolverSettings::pinTeleportDistance) carries the cloth with its pins: by the
// rotation and translation that map the pins' old targets onto the new ones in the least-squares
// sense, so a character respawned facing the other way takes its cape along turned, not dragged
// through the half-turn. The rotation comes from the SVD of the 3 × 3 cross-covariance of the two
// centred sets, with the reflection fix (det = −1 flips the weakest axis). Pin sets that do not
// determine a rotation fall back to the part they do determine:
//   - one pin, or pins that coincide: translation only;
//   - collinear pins (a cape pinned along its top edge): the rotation about their line is
//     undetermined. The fit maps the old line onto the new one and chooses the turn about the line
//     that maps the plane of the old line and `up` (gravity) onto the plane of the new line and
//     `up`, the side `up` points to kept: a line turned about the vertical is turned exactly so,
//     and a line turned end for end (a half-turn, where the smallest rotation has no preferred
//     axis and round-off would pick one) turns about the vertical, not upside down. When `up` is
//     zero or along either line, the smallest rotation that maps the old line onto the new one.
// Serial and free of thread-dependent sums: the same bits on any thread count.
#pragma once

#include <weft/Math.h>

#include <span>

namespace weft {

/// Which part of a rigid motion the points determined.
enum class RigidFitKind {
  Translation,  ///< one point, or points that coincide: rotation = identity
  Line,         ///< collinear points: the rotation about their line is chosen (see file note)
  Full,         ///< rotation and translation from the least-squares fit
};

/// x ↦ rotation · (x − fromCentroid) + toCentroid.
struct RigidFit {
  Mat3 rotation = Mat3::Identity();
  Vec3 fromCentroid = Vec3::Zero();
  Vec3 toCentroid = Vec3::Zero();
  /// toCentroid − fromCentroid computed as the mean of the points' displacements (the carry of a
  /// pure translation, without the round-off of subtracting two centroids far from the origin).
  Vec3 meanDisplacement = Vec3::Zero();
  RigidFitKind kind = RigidFitKind::Translation;
  /// True when the rotation is exactly the identity (a translation carries x + meanDisplacement).
  bool translationOnly() const { return rotation == Mat3::Identity(); }
  /// rad, in [0, π]: the angle the rotation turns about its axis.
  Real angle() const;
  Vec3 apply(const Vec3& x) const {
    return translationOnly() ? Vec3(x + meanDisplacement)
                             : Vec3(rotation * (x - fromCentroid) + toCentroid);
  }
};

/// Best rigid motion from `from` to `to` (same sizes, at least one point). A rotation within
/// round-off of the identity (‖R − I‖ ≤ 1e-12) is returned as exactly the identity, so a pure
/// translation carries as one. `up` breaks the tie of collinear points (see the file note).
RigidFit fitRigidMotion(std::span<const Vec3> from, std::span<const Vec3> to, const Vec3& up);

}  // namespace weft
