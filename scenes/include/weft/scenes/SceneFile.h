// Scene files: a JSON description of cloths, colliders, scripts, camera and run length, parsed
// into a validated SceneDescription that ScriptedScene turns into a World.
//
// Design note
// -----------
// Parsing and validation happen in one pass over the JSON tree, and every problem is reported
// with its JSON Pointer path (RFC 6901, e.g. "/cloths/0/material/arealDensity") and the fix, so a
// file with five mistakes is fixed in one round, not five. Unknown keys are errors too: a typo
// such as "arealDensty" would otherwise silently fall back to the default. Everything that can be
// checked without stepping is checked here — value ranges, pin indices against the built model
// (the ClothModel is built while parsing, OBJ files included), keyframe order — so ScriptedScene
// only ever sees descriptions that the engine accepts.
//
// Scripts are keyframe tracks evaluated at the end time of each frame; between keyframes a value
// moves as v0 + (v1 − v0)·ease(s), s = (t − t0) / (t1 − t0), with ease the identity (linear) or
// smoothstep. Before the first keyframe a track holds the first value, after the last one the last.
// The format itself is documented key by key in scenes/data/README.md.
//
// A pin group can instead ride on a collider ("attachTo", World::attachToCollider()): the
// collider is named, and names are resolved once cloths and colliders are both read. The wind can
// follow a keyframe track ("windScript"), applied through World::setWind() each frame.
//
// Not in the format (the World API has no such thing yet): releasing pins during a run,
// per-vertex initial velocities.
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/collision/RigidMotion.h>
#include <weft/collision/Shape.h>
#include <weft/engine/ClothModel.h>
#include <weft/engine/World.h>

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace weft {

/// How a value moves between two keyframes.
enum class Easing {
  Linear,      ///< constant speed between keyframes (the default)
  Smoothstep,  ///< 3s² − 2s³: starts and stops without a jump in velocity
};

/// One keyframe of a pin script: an affine map of the pins' start positions about the anchor.
/// target = anchor + translation + rotation · (scale ⊙ (start − anchor)).
struct PinKeyframe {
  Real time = 0;                   ///< s, from the start of the run
  Vec3 translation = Vec3::Zero(); ///< m
  Quat rotation = Quat::Identity();  ///< about the anchor
  Vec3 scale = Vec3::Ones();       ///< per world axis, about the anchor (1 = unchanged)
};

/// Moves a group of pins along keyframes.
struct PinScript {
  Vec3 anchor = Vec3::Zero();      ///< m, the fixed point of rotation and scale
  Easing easing = Easing::Linear;  ///< between every pair of keyframes
  std::vector<PinKeyframe> keyframes;  ///< at least one, times strictly increasing
  bool rotates = false;            ///< some keyframe has a rotation (else rotation is skipped)
};

/// A set of pinned vertices and how they move (held where they start when there is neither a
/// script nor a collider to ride on).
struct PinGroup {
  std::vector<Index> vertices;     ///< into the cloth's model, each pinned once in the cloth
  std::optional<PinScript> script; ///< none: the pins stay at their start positions
  /// Index into SceneDescription::colliders of the collider the pins ride on (World::
  /// attachToCollider(): they keep their start offsets in its body frame), or none.
  std::optional<std::size_t> attachedCollider;
};

/// Gentle sinusoidal pleats a grid cloth starts with (the curtain's initial waviness): the
/// displacement a·f·sin(2π w / λ) along the grid normal (widthAxis × heightAxis), where w is the
/// distance from the origin along the width and f falls linearly from 1 at row 0 to 0 at the
/// last row.
struct InitialPleats {
  Real amplitude = 0;      ///< m, a
  Real wavelength = 0.25;  ///< m, λ
};

/// One cloth of a scene.
struct ClothDescription {
  std::string name;                         ///< for messages and reports
  std::shared_ptr<const ClothModel> model;  ///< built while parsing
  std::optional<GridSettings> grid;         ///< the grid it was built from (none for meshes)
  std::string objPath;                      ///< the OBJ it was read from (resolved), if any
  ClothSettings settings;                   ///< pinnedVertices = all pin groups in order
  std::vector<PinGroup> pins;               ///< pin groups, in file order
  InitialPleats pleats;                     ///< amplitude 0: starts flat (grids only)
};

/// Keyframe of a collider's pose.
struct ColliderKeyframe {
  Real time = 0;                     ///< s
  Vec3 position = Vec3::Zero();      ///< m
  Quat rotation = Quat::Identity();  ///< body → world
};

/// One kinematic collider of a scene.
struct ColliderDescription {
  std::string name;                ///< for messages and reports
  Shape shape;                     ///< posed at its start (time 0), with its constant velocities
  ColliderSettings settings;       ///< friction
  Easing easing = Easing::Linear;  ///< between keyframes
  std::vector<ColliderKeyframe> keyframes;  ///< empty: moves with its constant velocities
  bool rotates = false;            ///< some keyframe turns it (else its angular velocity is kept)
};

/// Keyframe of the wind (the air's velocity, felt through the material's airDrag).
struct WindKeyframe {
  Real time = 0;            ///< s
  Vec3 wind = Vec3::Zero(); ///< m/s
};

/// Where the picture of `weft run --render` is taken from (weft/render CameraSettings' fields).
struct SceneCamera {
  Vec3 eye{0.0, 1.25, 3.2};        ///< m
  Vec3 target{0.0, 1.25, 0.0};     ///< m
  Vec3 up{0.0, 1.0, 0.0};          ///< world direction that appears up
  Real verticalFovDegrees = 45.0;  ///< degrees, full vertical field of view
  int width = 1280;                ///< pixels
  int height = 720;                ///< pixels
};

/// A whole scene: world settings, run length, camera, cloths and colliders.
struct SceneDescription {
  std::string name;           ///< "name" of the file, else the file's stem
  std::string description;    ///< free text
  Vec3 gravity{0.0, -9.81, 0.0};  ///< m/s²
  Vec3 wind{0.0, 0.0, 0.0};       ///< m/s (the first keyframe's when windKeyframes has any)
  Easing windEasing = Easing::Linear;      ///< between wind keyframes
  std::vector<WindKeyframe> windKeyframes; ///< empty: the wind stays `wind`
  Index frames = 600;             ///< frames of a full run
  Real frameDt = 1.0 / 60.0;      ///< s per frame
  SceneCamera camera;             ///< for `weft run --render`
  std::vector<ClothDescription> cloths;        ///< at least one, in file order
  std::vector<ColliderDescription> colliders;  ///< in file order
};

/// One problem in a scene file.
struct SceneIssue {
  std::string path;     ///< JSON Pointer of the offending value ("" = the whole document)
  std::string message;  ///< what is wrong and what to write instead
};

/// Limits that keep hostile or mistaken files from exhausting memory while parsing.
struct SceneLoadOptions {
  /// Directory that relative OBJ paths are resolved against (loadSceneFile: the file's own).
  std::string baseDirectory = ".";
  /// Grids and meshes above this are refused, and so is any cloth whose model and world state
  /// (ClothModel::estimatedBuildBytes + World::estimatedClothBytes) exceed the available memory.
  Index maxVerticesPerCloth = 4'000'000;
  Index maxIssues = 50;                    ///< stop collecting after this many problems
  std::uint64_t maxFileBytes = 64ull << 20;  ///< bytes; larger scene files are refused unread
};

/// The outcome of parsing: a description when `issues` is empty.
struct SceneParseOutcome {
  std::optional<SceneDescription> scene;  ///< the validated scene; none when there are issues
  std::vector<SceneIssue> issues;         ///< every problem found (up to maxIssues)
};

/// Parses and validates scene JSON. Never throws.
SceneParseOutcome parseSceneText(std::string_view json, const SceneLoadOptions& options = {});
/// Reads and parses a scene file (a regular file of at most options.maxFileBytes); relative OBJ
/// paths are resolved against its directory.
SceneParseOutcome parseSceneFile(const std::string& path, SceneLoadOptions options = {});

/// parseSceneFile() as a Result: the error lists one "path: message" line per issue.
Result<SceneDescription> loadSceneFile(const std::string& path, SceneLoadOptions options = {});
/// parseSceneText() as a Result.
Result<SceneDescription> loadSceneText(std::string_view json, const SceneLoadOptions& options = {});

/// "path: message" lines, one per issue ("/" for the document itself).
std::string formatIssues(const std::vector<SceneIssue>& issues);

/// Parses an integrator name as integratorName() spells it ("implicit-euler", "rk4", ...).
std::optional<IntegratorKind> integratorFromName(std::string_view name);

/// Parses an easing name: "linear" or "smoothstep".
std::optional<Easing> easingFromName(std::string_view name);

}  // namespace weft
