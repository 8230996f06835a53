#include "StagePlanner.h"

#include "Cloth.h"

#include <algorithm>
#include <limits>

namespace weft {
namespace {

// m: a sleeping cloth watches colliders within this distance beyond its contact thickness: far
// enough that a collider cannot reach it unseen within a frame unless it moves (and a moving
// collider near it wakes it anyway), near enough that distant traffic leaves it asleep.
constexpr Real kWakeMargin = 0.01;

// Hash of the colliders that could touch the cloth within the coming frame, and whether any of
// them moves: what a sleeping cloth watches.
std::uint64_t colliderFingerprint(const Cloth& cloth, std::span<const ColliderFrame> colliders,
                                  Real frameDt, bool& anyMoving) {
  Aabb box = Aabb::empty();
  for (const Vec3& x : cloth.positions()) box.expand(x);
  const Real thickness = cloth.settings().material.thickness;
  const Real margin = thickness * (1 + 1e-6) + 1e-9 + kWakeMargin;
  std::uint64_t hash = 1469598103934665603ull;
  auto mix = [&hash](const void* data, std::size_t bytes) {
    const unsigned char* byte = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < bytes; ++k) hash = (hash ^ byte[k]) * 1099511628211ull;
  };
  anyMoving = false;
  for (std::size_t k = 0; k < colliders.size(); ++k) {
    const RigidMotion& motion = colliders[k].start;
    const bool moving = !motion.linearVelocity.isZero() || !motion.angularVelocity.isZero();
    Real reach = margin;
    if (moving) {
      // Where the body can get within the frame: its travel, and for a spinning body the sweep
      // of its box about its origin.
      const Aabb body = bounds(colliders[k].shape);
      const Real radius = std::max((body.min - motion.pose.position).norm(),
                                   (body.max - motion.pose.position).norm());
      reach += frameDt * (motion.linearVelocity.norm() + motion.angularVelocity.norm() * radius);
      if (!std::isfinite(reach)) reach = std::numeric_limits<Real>::max();
    }
    if (!mayTouch(colliders[k].shape, box, reach)) continue;
    anyMoving = anyMoving || moving;
    mix(&k, sizeof k);
    mix(motion.pose.position.data(), sizeof(Real) * 3);
    mix(motion.pose.rotation.coeffs().data(), sizeof(Real) * 4);
  }
  return hash;
}

}  // namespace

void StagePlanner::build(const ContactSpace& space) {
  m_folds.clear();
  for (Cloth* cloth : space.cloths()) {
    m_folds.push_back(cloth->settings().selfCollision
                          ? std::make_unique<FoldCulling>(cloth->model())
                          : nullptr);
  }
  m_boxes.resize(space.cloths().size());
}

bool StagePlanner::steps(Cloth& cloth, std::span<const ColliderFrame> colliders, Real frameDt,
                         bool& woke) {
  woke = false;
  ClothSleep& sleep = cloth.sleepState();
  if (sleep.sleeping) {
    bool anyMoving = false;
    const bool collidersChanged =
        colliderFingerprint(cloth, colliders, frameDt, anyMoving) != sleep.fingerprint || anyMoving;
    const bool pinsMoved = cloth.largestPinTravel() > 0;
    if (!sleep.wakeRequested && !pinsMoved && !collidersChanged) return false;
    sleep.sleeping = false;
    sleep.quietFrames = 0;
    woke = true;
  }
  sleep.wakeRequested = false;
  return true;
}

void StagePlanner::afterFrame(Cloth& cloth, std::span<const ColliderFrame> colliders, Real frameDt,
                              bool pinsMoved) {
  const SleepSettings& settings = cloth.settings().sleep;
  ClothSleep& sleep = cloth.sleepState();
  if (!settings.enabled) return;
  // Quiet: every free vertex slow, and its velocity barely changed over the frame.
  Real speed2 = 0, change2 = 0;
  const Vec3Array& v = cloth.velocities();
  const Vec3Array& v0 = cloth.frameStartVelocities();
  for (Index i = 0; i < cloth.vertexCount(); ++i) {
    if (cloth.pinnedMask()[i]) continue;
    speed2 = std::max(speed2, v[i].squaredNorm());
    change2 = std::max(change2, (v[i] - v0[i]).squaredNorm());
  }
  const Real change = settings.acceleration * frameDt;
  const bool quiet = !pinsMoved && speed2 < settings.speed * settings.speed && change2 < change * change;
  sleep.quietFrames = quiet ? sleep.quietFrames + 1 : 0;
  if (sleep.quietFrames < settings.frames) return;
  bool anyMoving = false;
  const std::uint64_t fingerprint = colliderFingerprint(cloth, colliders, frameDt, anyMoving);
  if (anyMoving) return;  // a body moves near it: stay awake
  sleep.sleeping = true;
  sleep.fingerprint = fingerprint;
  cloth.zeroVelocities();
}

bool StagePlanner::pairsNeeded(const ContactSpace& space, std::span<const char> stepping,
                               Index& needed, Index& skipped) {
  const std::span<Cloth* const> cloths = space.cloths();
  bool any = false;
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    const Index first = space.firstVertex(c), count = cloths[c]->vertexCount();
    Aabb box = Aabb::empty();
    for (Index i = first; i < first + count; ++i) {
      box.expand(space.startX[i]);
      box.expand(space.x[i]);
    }
    box.inflate(kPairReach * space.owners[c].thickness);
    m_boxes[c] = box;
    if (!stepping[c] || !m_folds[c]) continue;
    const std::span<const Vec3> start(space.startX.data() + first, count);
    const std::span<const Vec3> end(space.x.data() + first, count);
    if (m_skip && m_folds[c]->cannotTouchItself(start, end, kPairReach * space.owners[c].thickness)) {
      ++skipped;
    } else {
      ++needed;
      any = true;
    }
  }
  for (std::size_t c = 0; c < cloths.size() && !any; ++c) {
    if (!space.owners[c].otherCloths) continue;
    for (std::size_t d = c + 1; d < cloths.size() && !any; ++d) {
      if (!space.owners[d].otherCloths || (!stepping[c] && !stepping[d])) continue;
      any = !m_skip || m_boxes[c].overlaps(m_boxes[d]);
    }
  }
  return any;
}

}  // namespace weft
