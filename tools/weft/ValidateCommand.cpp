// weft validate: parse every scene file, check it, and build its world (no stepping), so that
// what the engine would refuse is reported too. Errors are printed one per line as
// "file: /json/path: message".
#include "Commands.h"

#include <weft/scenes/ScriptedScene.h>

namespace weft {

int validateScenes(const ValidateOptions& options, std::ostream& out) {
  std::size_t invalid = 0;
  for (const std::string& path : options.scenes) {
    SceneParseOutcome outcome = parseSceneFile(path);
    if (!outcome.scene) {
      ++invalid;
      out << path << ": " << outcome.issues.size() << " error(s)\n";
      for (const SceneIssue& issue : outcome.issues) {
        out << "  " << (issue.path.empty() ? "/" : issue.path) << ": " << issue.message << "\n";
      }
      continue;
    }
    const SceneDescription& scene = *outcome.scene;
    const std::size_t cloths = scene.cloths.size(), colliders = scene.colliders.size();
    const Index frames = scene.frames;
    // What the mesh import changed, so a seam welded or a face flipped is never a surprise.
    std::string notes;
    for (const ClothDescription& cloth : scene.cloths) {
      const MeshImport& import = cloth.model->meshImport();
      if (import.weldedVertices == 0 && import.flippedTriangles == 0) continue;
      notes += "  cloth '" + cloth.name + "' (" + cloth.objPath + "): welded " +
               std::to_string(import.weldedVertices) + " coincident vertices, flipped " +
               std::to_string(import.flippedTriangles) + " triangles to a consistent winding\n";
    }
    ScriptedSceneSettings settings;
    settings.threadCount = 1;  // building only: no need for a thread pool
    Result<ScriptedScene> built = ScriptedScene::create(std::move(*outcome.scene), settings);
    if (!built.ok()) {
      ++invalid;
      out << path << ": 1 error(s)\n  " << built.error().message << "\n";
      continue;
    }
    out << path << ": valid (" << cloths << " cloth(s), " << colliders << " collider(s), " << frames
        << " frames)\n" << notes;
  }
  if (invalid == 0) {
    out << "all " << options.scenes.size() << " scene files are valid\n";
    return 0;
  }
  out << invalid << " of " << options.scenes.size() << " scene files have errors\n";
  return 1;
}

}  // namespace weft
