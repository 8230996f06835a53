// weft-mesh-colliders: the frame cost of a cloth on a triangle-mesh collider against the same
// cloth on the analytic shape of its size, in one process.
//
//   build/bench/weft-mesh-colliders [--frames 120] [--repeats 3] [--threads 1] [--self true]
//                                   [--queries true] [--scenes sphere,cylinder,large]
//                                   [--zones false]
//
// Pairs of scenes, each a cloth dropped from rest onto a body at the origin and draping:
//   sphere    41 × 41 vertices (1,681), 1.2 m square, 0.5 m up, on a 0.3 m sphere: the analytic
//             Sphere against a UV sphere of 6,048 triangles on the same radius (closed);
//   cylinder  35 × 35 vertices (1,225), 1.2 m square, 0.5 m up, on a 0.6 m-tall body: an
//             analytic Box 0.6 m on a side against a 258-triangle cylinder of radius 0.3 m;
//   large     71 × 71 vertices (5,041) on the 0.3 m sphere against a UV sphere of 19,800
//             triangles: a garment and a game character's mesh, in size (not run by default).
// The configurations alternate (A, M, A, M, …) so that a machine shared with other jobs slows
// both alike; a run's cost is the calling thread's CPU time per frame of World::step (and the
// wall time), the smallest of the repeats is kept, and every repeat's M / A ratio is printed.
// --zones prints, for each configuration's last repeat, the profiler zones of the calling thread
// in ms per frame (nested zones are inside their parents: "step" is the whole frame).
#include "BenchClock.h"

#include <weft/collision/Box.h>
#include <weft/collision/Sphere.h>
#include <weft/collision/TriangleMeshShape.h>
#include <weft/engine/World.h>
#include <weft/threading/Profiler.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace weft {
namespace {

using bench::threadCpuMs;
using bench::wallMs;

struct Mesh {
  std::vector<Vec3> vertices;
  std::vector<Index> indices;
};

// A UV sphere: `slices` around the y axis, `stacks` from pole to pole, counter-clockwise seen
// from outside. 2 · slices · (stacks − 1) triangles.
Mesh uvSphere(Real radius, Index slices, Index stacks) {
  Mesh mesh;
  mesh.vertices.emplace_back(0, radius, 0);
  for (Index s = 1; s < stacks; ++s) {
    const Real polar = M_PI * Real(s) / Real(stacks);
    for (Index k = 0; k < slices; ++k) {
      const Real azimuth = 2 * M_PI * Real(k) / Real(slices);
      mesh.vertices.emplace_back(radius * std::sin(polar) * std::cos(azimuth),
                                 radius * std::cos(polar),
                                 -radius * std::sin(polar) * std::sin(azimuth));
    }
  }
  mesh.vertices.emplace_back(0, -radius, 0);
  const Index south = Index(mesh.vertices.size() - 1);
  const auto ring = [&](Index s, Index k) { return 1 + (s - 1) * slices + k % slices; };
  for (Index k = 0; k < slices; ++k) {
    mesh.indices.insert(mesh.indices.end(), {0, ring(1, k), ring(1, k + 1)});
    for (Index s = 1; s + 1 < stacks; ++s) {
      mesh.indices.insert(mesh.indices.end(), {ring(s, k), ring(s + 1, k), ring(s + 1, k + 1)});
      mesh.indices.insert(mesh.indices.end(), {ring(s, k), ring(s + 1, k + 1), ring(s, k + 1)});
    }
    mesh.indices.insert(mesh.indices.end(), {south, ring(stacks - 1, k + 1), ring(stacks - 1, k)});
  }
  return mesh;
}

// A closed cylinder along y centred on the origin: `segments` around, `bands` rings of quads up
// the side, each cap a fan round its centre. 2 · segments · (bands + 1) triangles.
Mesh cylinder(Real radius, Real height, Index segments, Index bands) {
  Mesh mesh;
  for (Index b = 0; b <= bands; ++b) {
    const Real y = -0.5 * height + height * Real(b) / Real(bands);
    for (Index k = 0; k < segments; ++k) {
      const Real azimuth = 2 * M_PI * Real(k) / Real(segments);
      mesh.vertices.emplace_back(radius * std::cos(azimuth), y, -radius * std::sin(azimuth));
    }
  }
  const Index bottom = Index(mesh.vertices.size());
  mesh.vertices.emplace_back(0, -0.5 * height, 0);
  const Index top = Index(mesh.vertices.size());
  mesh.vertices.emplace_back(0, 0.5 * height, 0);
  const auto at = [&](Index b, Index k) { return b * segments + k % segments; };
  for (Index k = 0; k < segments; ++k) {
    for (Index b = 0; b < bands; ++b) {
      mesh.indices.insert(mesh.indices.end(), {at(b, k), at(b, k + 1), at(b + 1, k + 1)});
      mesh.indices.insert(mesh.indices.end(), {at(b, k), at(b + 1, k + 1), at(b + 1, k)});
    }
    mesh.indices.insert(mesh.indices.end(), {bottom, at(0, k + 1), at(0, k)});
    mesh.indices.insert(mesh.indices.end(), {top, at(bands, k), at(bands, k + 1)});
  }
  return mesh;
}

std::shared_ptr<const ClothModel> square(Index vertices, Real size, Real height) {
  GridSettings grid;
  grid.columns = grid.rows = vertices;
  grid.width = grid.height = size;
  grid.origin = Vec3(-size / 2, height, size / 2);
  grid.widthAxis = Vec3(1, 0, 0);
  grid.heightAxis = Vec3(0, 0, -1);
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

struct RunFigures {
  double cpuMs = 0;   ///< thread CPU time of step() per frame
  double wallMs = 0;  ///< wall time of step() per frame
  Real maxStrain = 0;
  Index contacts = 0;  ///< vertices in contact at the last frame
  Real faceContacts = 0;  ///< face contacts per frame (StepStats::faceContacts), mean
  Real sweeps = 0;  ///< projection sweeps per frame (StepStats::strainLimitIterations), mean
  std::string zones;  ///< "name ms, …" per frame of the calling thread's zones, when asked

  void keepFaster(const RunFigures& other) {
    cpuMs = std::min(cpuMs, other.cpuMs);
    wallMs = std::min(wallMs, other.wallMs);
  }
};

// "name ms, …": the calling thread's zones since the profiler was cleared, in ms per frame,
// largest first.
std::string zoneSummary(int frames) {
  std::map<std::string, double> totals;
  const std::vector<ZoneRecord> zones = Profiler::instance().zones();
  const std::uint32_t caller = zones.empty() ? 0 : zones.front().threadIndex;
  for (const ZoneRecord& zone : zones) {
    if (zone.threadIndex == caller) totals[zone.name] += 1e-6 * double(zone.endNs - zone.beginNs);
  }
  std::vector<std::pair<double, std::string>> sorted;
  for (const auto& [name, ms] : totals) sorted.emplace_back(ms / frames, name);
  std::sort(sorted.rbegin(), sorted.rend());
  std::string text;
  char figure[32];
  for (const auto& [ms, name] : sorted) {
    std::snprintf(figure, sizeof figure, " %.2f", ms);
    text += (text.empty() ? "" : ", ") + name + figure;
  }
  return text;
}

RunFigures run(const Shape& body, Index clothVertices, int frames, int threads, bool self,
               bool zones) {
  WorldSettings settings;
  settings.threadCount = threads;
  World world(settings);
  (void)world.addCollider(body).value();
  ClothSettings clothSettings;
  clothSettings.selfCollision = self;
  (void)world.createCloth(square(clothVertices, 1.2, 0.5), clothSettings).value();
  RunFigures figures;
  if (zones) {
    Profiler::instance().clear();
    Profiler::instance().registerThisThread("simulation");
    Profiler::instance().setEnabled(true);
  }
  for (int frame = 0; frame < frames; ++frame) {
    const double cpu = threadCpuMs(), wall = wallMs();
    world.step(1.0 / 60.0);
    figures.cpuMs += threadCpuMs() - cpu;
    figures.wallMs += wallMs() - wall;
    figures.maxStrain = std::max(figures.maxStrain, world.stats().maxStrain);
    figures.faceContacts += Real(world.stats().faceContacts) / frames;
    figures.sweeps += Real(world.stats().strainLimitIterations) / frames;
  }
  if (zones) {
    Profiler::instance().setEnabled(false);
    figures.zones = zoneSummary(frames);
  }
  figures.cpuMs /= frames;
  figures.wallMs /= frames;
  figures.contacts = world.stats().contacts;
  return figures;
}

void compare(const std::string& scene, const std::string& analyticName, const Shape& analytic,
             const std::string& meshName, const Shape& mesh, Index clothVertices, int frames,
             int repeats, int threads, bool self, bool zones) {
  RunFigures a, m;
  for (int repeat = 0; repeat < repeats; ++repeat) {
    const RunFigures ra = run(analytic, clothVertices, frames, threads, self, zones);
    const RunFigures rm = run(mesh, clothVertices, frames, threads, self, zones);
    std::printf("  %-9s repeat %d: %-22s cpu %8.3f ms/frame   %-22s cpu %8.3f ms/frame   "
                "ratio %.2f\n",
                scene.c_str(), repeat, analyticName.c_str(), ra.cpuMs, meshName.c_str(), rm.cpuMs,
                rm.cpuMs / ra.cpuMs);
    if (zones) {
      std::printf("  %-9s zones, ms/frame: %s: %s\n", scene.c_str(), analyticName.c_str(),
                  ra.zones.c_str());
      std::printf("  %-9s zones, ms/frame: %s: %s\n", scene.c_str(), meshName.c_str(),
                  rm.zones.c_str());
    }
    if (repeat == 0) {
      a = ra;
      m = rm;
    } else {
      a.keepFaster(ra);
      m.keepFaster(rm);
    }
  }
  std::printf("  %-9s best: %-22s cpu %8.3f wall %8.3f ms/frame (strain %.4f, contacts %u, "
              "face contacts %.0f/frame, sweeps %.1f/frame)\n",
              scene.c_str(), analyticName.c_str(), a.cpuMs, a.wallMs, a.maxStrain, a.contacts,
              a.faceContacts, a.sweeps);
  std::printf("  %-9s best: %-22s cpu %8.3f wall %8.3f ms/frame (strain %.4f, contacts %u, "
              "face contacts %.0f/frame, sweeps %.1f/frame)\n",
              scene.c_str(), meshName.c_str(), m.cpuMs, m.wallMs, m.maxStrain, m.contacts,
              m.faceContacts, m.sweeps);
  std::printf("  %-9s ratio mesh / analytic (best cpu): %.2f\n\n", scene.c_str(), m.cpuMs / a.cpuMs);
}

// ns per queryPoint of each shape at the same 200,000 points, uniform in the shell from the
// surface to `radius` beyond it (by distance from the centre; the cylinder's and box's corners
// make it approximate), alternating in blocks.
void queryCost(const Shape& analytic, const Shape& mesh, Real radius) {
  std::mt19937 random(7);
  std::uniform_real_distribution<Real> unit(-1, 1);
  std::vector<Vec3> points;
  while (points.size() < 200000) {
    const Vec3 direction(unit(random), unit(random), unit(random));
    if (direction.squaredNorm() > 1 || direction.squaredNorm() < 1e-6) continue;
    points.push_back(direction.normalized() * radius * (1 + 0.5 * (unit(random) + 1)));
  }
  double analyticMs = 1e300, meshMs = 1e300, sum = 0;
  for (int repeat = 0; repeat < 3; ++repeat) {
    for (const Shape* shape : {&analytic, &mesh}) {
      const double start = threadCpuMs();
      for (const Vec3& point : points) sum += queryPoint(*shape, point).distance;
      const double elapsed = threadCpuMs() - start;
      double& best = shape == &analytic ? analyticMs : meshMs;
      best = std::min(best, elapsed);
    }
  }
  std::printf("  queryPoint at points 0 to %.2f m off: analytic %.1f ns, mesh %.1f ns (ratio %.1f; "
              "checksum %.3f)\n\n",
              radius, 1e6 * analyticMs / double(points.size()), 1e6 * meshMs / double(points.size()),
              meshMs / analyticMs, sum);
}

}  // namespace
}  // namespace weft

int main(int argc, char** argv) {
  using namespace weft;
  CLI::App app{"Frame cost of a cloth on mesh colliders against analytic ones"};
  int frames = 120;
  int repeats = 3;
  int threads = 1;
  std::string scenes = "sphere,cylinder";  // "large" on request
  app.add_option("--frames", frames, "Frames per run")->check(CLI::Range(1, 100000));
  app.add_option("--repeats", repeats, "Runs per configuration (fastest kept)")
      ->check(CLI::Range(1, 20));
  app.add_option("--threads", threads, "Threads (1 = serial)")->check(CLI::Range(1, 64));
  app.add_option("--scenes", scenes, "sphere, cylinder, large (comma-separated)");
  bool self = true;
  app.add_option("--self", self, "Self-collision on (true/false)");
  bool queries = true;
  app.add_option("--queries", queries, "Also time queryPoint alone (true/false)");
  bool zones = false;
  app.add_option("--zones", zones, "Print the profiler zones per frame of each run (true/false)");
  CLI11_PARSE(app, argc, argv);

  std::printf("weft-mesh-colliders: %d frames, %d repeat(s), %d thread(s), self-collision %s\n\n",
              frames, repeats, threads, self ? "on" : "off");
  constexpr Real kRadius = 0.3;
  // A cloth of clothVertices² vertices on the analytic sphere and on a UV sphere of its radius.
  const auto compareSpheres = [&](const char* scene, Index slices, Index stacks,
                                  Index clothVertices, bool timeQueries) {
    const Mesh ball = uvSphere(kRadius, slices, stacks);
    const Shape analytic = Sphere::create(kRadius).value();
    const Shape mesh = TriangleMeshShape::create(ball.vertices, ball.indices).value();
    compare(scene, "Sphere", analytic,
            "UV sphere (" + std::to_string(ball.indices.size() / 3) + " tris)", mesh,
            clothVertices, frames, repeats, threads, self, zones);
    if (timeQueries) queryCost(analytic, mesh, kRadius);
  };
  if (scenes.find("sphere") != std::string::npos) compareSpheres("sphere", 56, 55, 41, queries);
  // A garment-sized cloth on a character-sized mesh.
  if (scenes.find("large") != std::string::npos) compareSpheres("large", 100, 100, 71, false);
  if (scenes.find("cylinder") != std::string::npos) {
    const Mesh post = cylinder(kRadius, 2 * kRadius, 43, 2);
    const Shape analytic = Box::create(Vec3(kRadius, kRadius, kRadius)).value();
    const Shape mesh = TriangleMeshShape::create(post.vertices, post.indices).value();
    compare("cylinder", "Box", analytic,
            "cylinder (" + std::to_string(post.indices.size() / 3) + " tris)", mesh, 35, frames,
            repeats, threads, self, zones);
    if (queries) queryCost(analytic, mesh, kRadius);
  }
  return 0;
}
