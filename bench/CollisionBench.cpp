// Collision stage benchmarks on the curtain gathered by its rod (frame 330 of the script: deep
// folds, the heaviest self-contact), at sizes 1, 4, 16 and on 1 and 2 threads:
//   CollisionRefit      the BVH refit to the step's swept boxes
//   CollisionSelfQuery  the BVH self query (candidate triangle pairs)
//   CollisionDetect     the contact detection of a step (broad phase, feature pairs, closest
//                       points at both ends); counters: broad_ms, features_ms, narrow_ms per call
//   CollisionImpacts    the impact stage of a step (swept tests, impulses, impact zones)
//   CurtainStep         whole frames of the curtain script with self-collision on and off
// Run in Release: build/bench/weft-bench --benchmark_filter='Collision|CurtainStep'
// Arguments are {size, threads} (and {self} for CurtainStep).
#include "Cloth.h"
#include "contact/ContactDetector.h"
#include "contact/ImpactResolver.h"

#include <weft/scenes/Curtain.h>
#include <weft/threading/Profiler.h>

#include <benchmark/benchmark.h>

#include <map>
#include <memory>

namespace weft {
namespace {

constexpr Index kGatheredFrame = 330;  // 5.5 s: the rod holds the curtain at 30 % of its width

// The curtain at kGatheredFrame: positions, velocities and inverse masses (0 on the rod).
struct GatheredCurtain {
  std::shared_ptr<const ClothModel> model;
  Vec3Array start, velocity;
  std::vector<Real> inverseMasses;
  ClothMaterial material;

  explicit GatheredCurtain(Index size) {
    CurtainSettings settings;
    settings.size = size;
    CurtainScene scene = CurtainScene::create(settings).value();
    for (Index frame = 0; frame < kGatheredFrame; ++frame) scene.stepFrame();
    model = std::make_shared<const ClothModel>(scene.model());
    const auto x = scene.world().positions(scene.cloth()).value();
    const auto v = scene.world().velocities(scene.cloth()).value();
    start.assign(x.begin(), x.end());
    velocity.assign(v.begin(), v.end());
    const std::vector<Real> masses = model->vertexMasses(material.arealDensity);
    inverseMasses.resize(masses.size());
    for (std::size_t i = 0; i < masses.size(); ++i) inverseMasses[i] = 1 / masses[i];
    const Index columns = model->gridSize()[0], rows = model->gridSize()[1];
    for (Index c = 0; c < columns; ++c) inverseMasses[(rows - 1) * columns + c] = 0;
  }
};

GatheredCurtain& gathered(Index size) {
  static std::map<Index, std::unique_ptr<GatheredCurtain>> cache;
  std::unique_ptr<GatheredCurtain>& entry = cache[size];
  if (!entry) entry = std::make_unique<GatheredCurtain>(size);
  return *entry;
}

TaskSystem& tasks(int threads) {
  static std::map<int, std::unique_ptr<TaskSystem>> cache;
  std::unique_ptr<TaskSystem>& entry = cache[threads];
  if (!entry) entry = std::make_unique<TaskSystem>(TaskSystemSettings{threads});
  return *entry;
}

// The step's end positions: where the velocities carry the start in one frame.
Vec3Array stepEnd(const GatheredCurtain& curtain) {
  Vec3Array end(curtain.start.size());
  for (std::size_t i = 0; i < end.size(); ++i) {
    end[i] = curtain.start[i] + CurtainScene::kFrameDt * curtain.velocity[i];
  }
  return end;
}

void CollisionRefit(benchmark::State& state) {
  GatheredCurtain& curtain = gathered(Index(state.range(0)));
  TaskSystem& taskSystem = tasks(int(state.range(1)));
  Bvh bvh = Bvh::build(curtain.model->indices(), curtain.model->restPositions()).value();
  const Vec3Array end = stepEnd(curtain);
  for (auto _ : state) {
    bvh.refit(curtain.start, end, curtain.material.thickness, &taskSystem);
    benchmark::DoNotOptimize(bvh.bounds());
  }
  state.counters["triangles"] = double(curtain.model->triangleCount());
}

void CollisionSelfQuery(benchmark::State& state) {
  GatheredCurtain& curtain = gathered(Index(state.range(0)));
  TaskSystem& taskSystem = tasks(int(state.range(1)));
  Bvh bvh = Bvh::build(curtain.model->indices(), curtain.model->restPositions()).value();
  bvh.refit(curtain.start, stepEnd(curtain), curtain.material.thickness, &taskSystem);
  PerWorker<std::vector<TrianglePair>> workerPairs(taskSystem);
  std::vector<TrianglePair> pairs;
  for (auto _ : state) {
    bvh.querySelf(pairs, taskSystem, workerPairs);
    benchmark::DoNotOptimize(pairs.data());
  }
  state.counters["pairs"] = double(pairs.size());
}

// The gathered curtain as a one-cloth contact space, its step ending at stepEnd().
struct GatheredSpace {
  std::unique_ptr<Cloth> cloth;
  ContactSpace space;

  GatheredSpace(GatheredCurtain& curtain, TaskSystem& taskSystem) {
    ClothSettings settings;
    settings.material = curtain.material;
    const Index columns = curtain.model->gridSize()[0], rows = curtain.model->gridSize()[1];
    for (Index c = 0; c < columns; ++c) settings.pinnedVertices.push_back((rows - 1) * columns + c);
    cloth = Cloth::create(curtain.model, settings, WorldSettings{}, &taskSystem).value();
    (void)cloth->setState(curtain.start, curtain.velocity);
    Cloth* cloths[] = {cloth.get()};
    space.build(cloths);
  }
  void reset(const GatheredCurtain& curtain, const Vec3Array& end) {
    space.startX = curtain.start;
    space.startV = curtain.velocity;
    space.x = end;
    space.v = curtain.velocity;
  }
};

void recordZones(benchmark::State& state, std::uint64_t frame) {
  Profiler& profiler = Profiler::instance();
  const double calls = double(state.iterations());
  for (const ZoneTotal& zone : profiler.frameTotals(frame)) {
    if (zone.name == "broad phase") state.counters["broad_ms"] = zone.totalMs / calls;
    if (zone.name == "feature pairs") state.counters["features_ms"] = zone.totalMs / calls;
    if (zone.name == "narrow phase") state.counters["narrow_ms"] = zone.totalMs / calls;
    if (zone.name == "swept tests") state.counters["swept_ms"] = zone.totalMs / calls;
    if (zone.name == "impact zones") state.counters["zones_ms"] = zone.totalMs / calls;
  }
  state.counters["dropped_zones"] = double(profiler.droppedCount());
  profiler.clear();
}

void CollisionDetect(benchmark::State& state) {
  GatheredCurtain& curtain = gathered(Index(state.range(0)));
  TaskSystem& taskSystem = tasks(int(state.range(1)));
  GatheredSpace gatheredSpace(curtain, taskSystem);
  gatheredSpace.reset(curtain, stepEnd(curtain));
  ContactDetector detector;
  detector.build(gatheredSpace.space, &taskSystem);
  ContactSet set;
  DetectionCounts counts;
  detector.detect(gatheredSpace.space, {}, {}, {}, true, 0, set, counts);  // sizes every buffer
  Profiler& profiler = Profiler::instance();
  profiler.clear();
  const std::uint64_t frame = 1'000'000 + 100 * std::uint64_t(state.range(0)) + state.range(1);
  profiler.beginFrame(frame);
  profiler.setEnabled(true);
  for (auto _ : state) {
    detector.detect(gatheredSpace.space, {}, {}, {}, true, 0, set, counts);
    benchmark::DoNotOptimize(set.contacts.data());
  }
  profiler.setEnabled(false);
  recordZones(state, frame);
  state.counters["contacts"] = double(set.size());
}

void CollisionImpacts(benchmark::State& state) {
  GatheredCurtain& curtain = gathered(Index(state.range(0)));
  TaskSystem& taskSystem = tasks(int(state.range(1)));
  GatheredSpace gatheredSpace(curtain, taskSystem);
  const Vec3Array end = stepEnd(curtain);
  ImpactResolver impacts;
  impacts.build(gatheredSpace.space, &taskSystem);
  const Real h = CurtainScene::kFrameDt;
  gatheredSpace.reset(curtain, end);
  ImpactReport report = impacts.resolve(gatheredSpace.space, ContactSet{}, {}, h, true);  // sizes every buffer
  Profiler& profiler = Profiler::instance();
  profiler.clear();
  const std::uint64_t frame = 2'000'000 + 100 * std::uint64_t(state.range(0)) + state.range(1);
  profiler.beginFrame(frame);
  profiler.setEnabled(true);
  for (auto _ : state) {
    gatheredSpace.reset(curtain, end);
    report = impacts.resolve(gatheredSpace.space, ContactSet{}, {}, h, true);
  }
  profiler.setEnabled(false);
  recordZones(state, frame);
  state.counters["impacts"] = double(report.impacts);
}

// Frames 240–420 of the script (gathering and holding: the self-contact-heavy part), cycled.
void CurtainStep(benchmark::State& state) {
  CurtainSettings settings;
  settings.size = Index(state.range(0));
  settings.threadCount = int(state.range(1));
  settings.selfCollision = state.range(2) != 0;
  auto start = [&] {
    CurtainScene scene = CurtainScene::create(settings).value();
    for (Index frame = 0; frame < 240; ++frame) scene.stepFrame();
    return scene;
  };
  CurtainScene scene = start();
  for (auto _ : state) {
    scene.stepFrame();
    if (scene.frame() >= 420) {
      state.PauseTiming();
      scene = start();
      state.ResumeTiming();
    }
  }
  state.counters["self_contacts"] = double(scene.world().stats().selfContacts);
}

#define WEFT_COLLISION_SIZES \
  ->ArgsProduct({{1, 4, 16}, {1, 2}})->ArgNames({"size", "threads"})->Unit(benchmark::kMillisecond)
BENCHMARK(CollisionRefit) WEFT_COLLISION_SIZES;
BENCHMARK(CollisionSelfQuery) WEFT_COLLISION_SIZES;
// A fixed number of calls keeps the profiler's zone buffers from filling up.
BENCHMARK(CollisionDetect) WEFT_COLLISION_SIZES->Iterations(40);
BENCHMARK(CollisionImpacts) WEFT_COLLISION_SIZES->Iterations(40);
BENCHMARK(CurtainStep)
    ->ArgsProduct({{1, 4, 16}, {1, 2}, {0, 1}})
    ->ArgNames({"size", "threads", "self"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(90);

}  // namespace
}  // namespace weft
