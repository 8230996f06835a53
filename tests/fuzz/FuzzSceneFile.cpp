// libFuzzer target: scene JSON → parseSceneText() → ScriptedScene::create() → script evaluation.
// A description that parses must build (the parser promises the engine accepts it) and its
// scripts must evaluate at any time without a crash. Grids are capped at a few thousand vertices
// so that each input runs in milliseconds; OBJ paths resolve into a folder that does not exist.
#include <weft/scenes/SceneFile.h>
#include <weft/scenes/ScriptedScene.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  weft::SceneLoadOptions options;
  options.baseDirectory = "/nonexistent/weft-fuzz";
  options.maxVerticesPerCloth = 4096;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  weft::SceneParseOutcome outcome = weft::parseSceneText(text, options);
  if (!outcome.scene) {
    if (outcome.issues.empty()) __builtin_trap();  // a refusal always says why
    return 0;
  }
  weft::ScriptedSceneSettings settings;
  settings.threadCount = 1;
  weft::Result<weft::ScriptedScene> scene = weft::ScriptedScene::create(std::move(*outcome.scene), settings);
  if (!scene.ok()) {
    // The parser accepted something the engine refuses: a gap in validation worth fixing.
    std::fprintf(stderr, "parsed but not built: %s\n", scene.error().message.c_str());
    __builtin_trap();
  }
  std::vector<weft::Vec3> targets;
  for (std::size_t k = 0; k < scene->clothCount(); ++k) {
    for (weft::Real t : {0.0, 0.5, 3.0, 1e9}) scene->pinTargetsAt(k, t, targets);
  }
  for (const weft::ColliderDescription& collider : scene->description().colliders) {
    if (collider.keyframes.empty()) continue;
    for (weft::Real t : {0.0, 0.5, 3.0, 1e9}) (void)weft::keyframePose(collider, t);
  }
  return 0;
}
