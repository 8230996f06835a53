#include <weft/scenes/ScriptedScene.h>

#include <algorithm>
#include <cmath>

namespace weft {
namespace {

constexpr Real kPi = 3.14159265358979323846;

// The segment of `keyframes` that holds t: index i with time[i] < t ≤ time[i + 1], or −1 before
// the first keyframe and size − 1 after the last (the value is then held).
template <typename Keyframe>
std::ptrdiff_t segmentAt(const std::vector<Keyframe>& keyframes, Real t) {
  if (t <= keyframes.front().time) return -1;
  const auto after = std::lower_bound(keyframes.begin(), keyframes.end(), t,
                                      [](const Keyframe& k, Real time) { return k.time < time; });
  return (after - keyframes.begin()) - 1;
}

// v0 + (v1 − v0)·e, written this way (not (1 − e)·v0 + e·v1) so that a held value stays exact.
template <typename T>
T interpolate(const T& v0, const T& v1, Real e) {
  return v0 + (v1 - v0) * e;
}

}  // namespace

Real ease(Easing easing, Real fraction) {
  const Real s = std::clamp<Real>(fraction, 0, 1);
  return easing == Easing::Smoothstep ? s * s * (3 - 2 * s) : s;
}

Vec3 pinTarget(const PinScript& script, const Vec3& start, Real t) {
  const std::vector<PinKeyframe>& keys = script.keyframes;
  const std::ptrdiff_t segment = segmentAt(keys, t);
  Vec3 translation, scale;
  Quat rotation = Quat::Identity();
  if (segment < 0 || segment + 1 >= std::ptrdiff_t(keys.size())) {
    const PinKeyframe& held = segment < 0 ? keys.front() : keys.back();
    translation = held.translation;
    scale = held.scale;
    rotation = held.rotation;
  } else {
    const PinKeyframe& a = keys[segment];
    const PinKeyframe& b = keys[segment + 1];
    const Real e = ease(script.easing, (t - a.time) / (b.time - a.time));
    translation = interpolate(a.translation, b.translation, e);
    scale = interpolate(a.scale, b.scale, e);
    if (script.rotates) rotation = a.rotation.slerp(e, b.rotation);
  }
  const Vec3 local = (start - script.anchor).cwiseProduct(scale);
  // Without rotation keys the rotation is skipped, not multiplied by the identity, so a script
  // that only scales (the curtain's gather) evaluates exactly anchor + translation + local.
  return script.anchor + translation + (script.rotates ? Vec3(rotation * local) : local);
}

Pose keyframePose(const ColliderDescription& collider, Real t) {
  const std::vector<ColliderKeyframe>& keys = collider.keyframes;
  const std::ptrdiff_t segment = segmentAt(keys, t);
  Pose pose;
  if (segment < 0 || segment + 1 >= std::ptrdiff_t(keys.size())) {
    const ColliderKeyframe& held = segment < 0 ? keys.front() : keys.back();
    pose.position = held.position;
    pose.rotation = held.rotation;
    return pose;
  }
  const ColliderKeyframe& a = keys[segment];
  const ColliderKeyframe& b = keys[segment + 1];
  const Real e = ease(collider.easing, (t - a.time) / (b.time - a.time));
  pose.position = interpolate(a.position, b.position, e);
  pose.rotation = collider.rotates ? a.rotation.slerp(e, b.rotation) : a.rotation;
  return pose;
}

Vec3 windAt(const SceneDescription& scene, Real t) {
  const std::vector<WindKeyframe>& keys = scene.windKeyframes;
  if (keys.empty()) return scene.wind;
  const std::ptrdiff_t segment = segmentAt(keys, t);
  if (segment < 0) return keys.front().wind;
  if (segment + 1 >= std::ptrdiff_t(keys.size())) return keys.back().wind;
  const WindKeyframe& a = keys[segment];
  const WindKeyframe& b = keys[segment + 1];
  return interpolate(a.wind, b.wind, ease(scene.windEasing, (t - a.time) / (b.time - a.time)));
}

Result<ScriptedScene> ScriptedScene::create(SceneDescription description,
                                            const ScriptedSceneSettings& settings) {
  ScriptedScene scene;
  WorldSettings worldSettings;
  worldSettings.gravity = description.gravity;
  worldSettings.wind = description.wind;
  worldSettings.threadCount = settings.threadCount;
  worldSettings.taskSystem = settings.taskSystem;
  if (!(description.frameDt > 0 && std::isfinite(description.frameDt))) {
    return Error{"/run/frameDt: must be a positive number of seconds"};
  }
  Result<World> world = World::create(worldSettings);
  if (!world.ok()) return Error{"scene settings: " + world.error().message};
  scene.m_world = std::make_unique<World>(std::move(world).value());

  for (std::size_t k = 0; k < description.cloths.size(); ++k) {
    const ClothDescription& cloth = description.cloths[k];
    const std::string path = "/cloths/" + std::to_string(k);
    if (!cloth.model) return Error{path + ": has no model"};
    Result<ClothId> id = scene.m_world->createCloth(cloth.model, cloth.settings);
    if (!id.ok()) return Error{path + ": " + id.error().message};
    scene.m_cloths.push_back(id.value());
  }
  // Colliders after cloths, as CurtainScene adds them: creation order is part of what a run
  // reproduces bit for bit.
  for (std::size_t k = 0; k < description.colliders.size(); ++k) {
    const ColliderDescription& collider = description.colliders[k];
    Result<ColliderId> id = scene.m_world->addCollider(collider.shape, collider.settings);
    if (!id.ok()) return Error{"/colliders/" + std::to_string(k) + ": " + id.error().message};
    scene.m_colliders.push_back(id.value());
  }

  // Initial pleats, in the same arithmetic as CurtainScene's waviness so that curtain.json starts
  // from the same bits.
  for (std::size_t k = 0; k < description.cloths.size(); ++k) {
    const ClothDescription& cloth = description.cloths[k];
    if (cloth.pleats.amplitude == 0 || !cloth.grid) continue;
    const GridSettings& grid = *cloth.grid;
    const Mat3& rotation = cloth.settings.rotation;
    const Vec3 origin = rotation * grid.origin + cloth.settings.translation;
    const Vec3 widthAxis = rotation * grid.widthAxis.normalized();
    const Vec3 heightAxis = rotation * grid.heightAxis.normalized();
    const Vec3 normal = widthAxis.cross(heightAxis);
    const Vec3 lastRow = origin + heightAxis * grid.height;
    Vec3Array positions(scene.m_world->positions(scene.m_cloths[k]).value().begin(),
                        scene.m_world->positions(scene.m_cloths[k]).value().end());
    for (Vec3& p : positions) {
      const Real fade = (lastRow - p).dot(heightAxis) / grid.height;  // 1 at row 0, 0 at the last
      const Real across = (p - origin).dot(widthAxis);
      p += normal * (cloth.pleats.amplitude * fade *
                     std::sin(2 * kPi * across / cloth.pleats.wavelength));
    }
    const Vec3Array velocities(positions.size(), Vec3::Zero());
    Status state = scene.m_world->setState(scene.m_cloths[k], positions, velocities);
    if (!state.ok()) return Error{"/cloths/" + std::to_string(k) + "/initialPleats: " + state.error().message};
  }

  // Pins riding on colliders keep the offsets they have once the cloth is placed and pleated.
  for (std::size_t k = 0; k < description.cloths.size(); ++k) {
    const std::vector<PinGroup>& groups = description.cloths[k].pins;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      if (!groups[g].attachedCollider) continue;
      const std::size_t collider = *groups[g].attachedCollider;
      if (collider >= scene.m_colliders.size()) {
        return Error{"/cloths/" + std::to_string(k) + "/pins/" + std::to_string(g) +
                     "/attachTo: names collider " + std::to_string(collider) + ", but the scene has " +
                     std::to_string(scene.m_colliders.size())};
      }
      Status attached = scene.m_world->attachToCollider(scene.m_cloths[k], groups[g].vertices,
                                                        scene.m_colliders[collider]);
      if (!attached.ok()) {
        return Error{"/cloths/" + std::to_string(k) + "/pins/" + std::to_string(g) + "/attachTo: " +
                     attached.error().message};
      }
    }
  }

  // Pin start positions: where the pins are once the cloth is placed (and pleated).
  for (std::size_t k = 0; k < description.cloths.size(); ++k) {
    const std::span<const Vec3> x = scene.m_world->positions(scene.m_cloths[k]).value();
    Vec3Array starts;
    bool scripted = false;
    for (Index vertex : description.cloths[k].settings.pinnedVertices) starts.push_back(x[vertex]);
    for (const PinGroup& group : description.cloths[k].pins) scripted = scripted || group.script.has_value();
    scene.m_pinStarts.push_back(std::move(starts));
    scene.m_scripted.push_back(scripted);
  }
  scene.m_description = std::move(description);
  return scene;
}

void ScriptedScene::pinTargetsAt(std::size_t k, Real t, std::vector<Vec3>& targets) const {
  const Vec3Array& starts = m_pinStarts[k];
  targets.resize(starts.size());
  std::size_t next = 0;
  for (const PinGroup& group : m_description.cloths[k].pins) {
    for (std::size_t i = 0; i < group.vertices.size(); ++i, ++next) {
      targets[next] = group.script ? pinTarget(*group.script, starts[next], t) : starts[next];
    }
  }
}

StepStatus ScriptedScene::stepFrame() {
  const Real endTime = Real(m_frame + 1) * m_description.frameDt;
  // A script can still produce a non-finite target (a scale of 1e300 on a far-away pin); the world
  // refuses it, the pins hold where they are, and the frame reports InvalidInput.
  StepStatus refused = StepStatus::Ok;
  for (std::size_t k = 0; k < m_cloths.size(); ++k) {
    if (!m_scripted[k]) continue;
    pinTargetsAt(k, endTime, m_targets);
    if (!m_world->setPinTargets(m_cloths[k], m_targets).ok()) refused = StepStatus::InvalidInput;
  }
  if (!m_description.windKeyframes.empty()) {
    if (!m_world->setWind(windAt(m_description, endTime)).ok()) refused = StepStatus::InvalidInput;
  }
  for (std::size_t k = 0; k < m_colliders.size(); ++k) {
    const ColliderDescription& collider = m_description.colliders[k];
    if (collider.keyframes.empty()) continue;
    // Velocities that bring the collider where its track wants it at the end of the frame.
    const Pose target = keyframePose(collider, endTime);
    RigidMotion current = motion(*m_world->collider(m_colliders[k]).value());
    current.linearVelocity = (target.position - current.pose.position) / m_description.frameDt;
    if (collider.rotates) {
      // The rotation from here to the target, as an angle about an axis, spread over the frame
      // (the shorter way round).
      Quat delta = target.rotation * current.pose.rotation.conjugate();
      if (delta.w() < 0) delta.coeffs() = -delta.coeffs();
      const Eigen::AngleAxis<Real> turn(delta.normalized());
      current.angularVelocity = turn.axis() * (turn.angle() / m_description.frameDt);
    }
    if (!m_world->setColliderMotion(m_colliders[k], current).ok()) refused = StepStatus::InvalidInput;
  }
  ++m_frame;
  return m_world->step(m_description.frameDt) | refused;
}

}  // namespace weft
