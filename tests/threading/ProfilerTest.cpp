// Profiler: nested zones from several threads, exported as Chrome trace JSON that parses and
// nests; the runtime switch; full buffers; per-frame totals; the default instance and its macro.
// Zones are opened with ProfileZone objects (what WEFT_PROFILE_ZONE_ON expands to) so the suite
// does not depend on the WEFT_PROFILING compile switch.
#include <weft/threading/Profiler.h>
#include <weft/threading/TaskSystem.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

namespace weft {
namespace {

/// Written and never read, so the optimiser keeps the loops whose results land here.
thread_local volatile double t_sink = 0.0;

/// A little work so that zones have non-zero length (nothing about time is asserted).
double spin(int n) {
  double x = 0.0;
  for (int i = 0; i < n; ++i) x += std::sqrt(static_cast<double>(i));
  t_sink = x;
  return x;
}

/// The zones one simulated substep records on one thread: three levels deep.
void recordSubstep(Profiler& profiler) {
  ProfileZone zone1(profiler, "assembly");
  spin(200);
  {
    ProfileZone zone2(profiler, "solve");
    spin(200);
    {
      ProfileZone zone3(profiler, "broad phase");
      spin(100);
    }
    {
      ProfileZone zone4(profiler, "narrow phase");
      spin(100);
    }
  }
  ProfileZone zone5(profiler, "response");
  spin(100);
}

nlohmann::json readJson(const std::string& path) {
  std::ifstream file(path);
  EXPECT_TRUE(file.good()) << path;
  return nlohmann::json::parse(file);  // throws (and fails the test) if it is not JSON
}

/// A file name in the test temp directory, unique per process (other builds share /tmp).
std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + std::to_string(::getpid()) + "_" + name;
}

TEST(Profiler, NestedZonesFromSeveralThreadsExportAsAChromeTraceThatNests) {
  Profiler profiler({.eventsPerThread = 4096, .enabled = true});
  profiler.registerThisThread("main");
  constexpr int kThreads = 3, kSubsteps = 4;
  profiler.beginFrame(7);
  {
    ProfileZone zone6(profiler, "health");
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
      threads.emplace_back([&profiler] {
        for (int s = 0; s < kSubsteps; ++s) recordSubstep(profiler);
      });
    }
    for (int s = 0; s < kSubsteps; ++s) recordSubstep(profiler);
    for (auto& thread : threads) thread.join();
  }
  // Zones inside TaskSystem blocks, recorded by the arena's workers and by the caller.
  profiler.beginFrame(8);
  {
    TaskSystem tasks({.threadCount = 2});
    ProfileZone zone7(profiler, "render");
    tasks.parallelFor(64, 4, [&](TaskSystem::Index, TaskSystem::Index, int) {
      ProfileZone zone8(profiler, "capture");
      spin(500);
    });
  }

  const std::size_t zonesPerSubstep = 5;
  const std::size_t expectedZones = (kThreads + 1) * kSubsteps * zonesPerSubstep + 1 + 1 + 16;
  EXPECT_EQ(profiler.zones().size(), expectedZones);
  EXPECT_EQ(profiler.droppedCount(), 0u);
  EXPECT_GE(profiler.threadCount(), static_cast<std::size_t>(kThreads + 1));

  const std::string path = tempPath("weft_profiler_trace.json");
  const TraceWriteResult written = profiler.writeChromeTrace(path);
  ASSERT_TRUE(written.ok) << written.error;
  EXPECT_EQ(written.eventCount, expectedZones);
  EXPECT_EQ(written.droppedCount, 0u);

  const nlohmann::json trace = readJson(path);
  ASSERT_TRUE(trace.contains("traceEvents"));
  ASSERT_TRUE(trace["traceEvents"].is_array());

  struct Span {
    double ts, dur;
    int depth;
    std::string name;
    std::uint64_t frame;
  };
  std::map<int, std::vector<Span>> spansByThread;
  std::map<int, std::string> threadNames;
  std::multiset<std::string> names;
  for (const nlohmann::json& event : trace["traceEvents"]) {
    ASSERT_TRUE(event.contains("ph") && event["ph"].is_string());
    ASSERT_TRUE(event.contains("pid") && event["pid"].is_number_integer());
    ASSERT_TRUE(event.contains("tid") && event["tid"].is_number_integer());
    ASSERT_TRUE(event.contains("name") && event["name"].is_string());
    if (event["ph"] == "M") {
      if (event["name"] == "thread_name") threadNames[event["tid"].get<int>()] = event["args"]["name"].get<std::string>();
      continue;
    }
    ASSERT_EQ(event["ph"], "X");
    ASSERT_TRUE(event["ts"].is_number());
    ASSERT_TRUE(event["dur"].is_number());
    ASSERT_GE(event["dur"].get<double>(), 0.0);
    ASSERT_GE(event["ts"].get<double>(), 0.0);
    ASSERT_FALSE(event["name"].get<std::string>().empty());
    names.insert(event["name"].get<std::string>());
    spansByThread[event["tid"].get<int>()].push_back({event["ts"].get<double>(), event["dur"].get<double>(),
                                                      event["args"]["depth"].get<int>(),
                                                      event["name"].get<std::string>(),
                                                      event["args"]["frame"].get<std::uint64_t>()});
  }
  EXPECT_EQ(names.size(), expectedZones);
  EXPECT_EQ(names.count("assembly"), (kThreads + 1) * kSubsteps);
  EXPECT_EQ(names.count("broad phase"), (kThreads + 1) * kSubsteps);
  EXPECT_EQ(names.count("health"), 1u);
  EXPECT_EQ(names.count("render"), 1u);
  EXPECT_EQ(names.count("capture"), 16u);
  EXPECT_GE(spansByThread.size(), static_cast<std::size_t>(kThreads + 1));
  EXPECT_EQ(threadNames[0], "main");
  for (const auto& [tid, spans] : spansByThread) {
    EXPECT_TRUE(threadNames.count(tid)) << "no thread_name metadata for tid " << tid;
  }

  // Nesting: on each tid, every zone of depth d > 0 lies inside the innermost open zone of
  // depth d − 1 that precedes it. Tolerance: 1 ns (timestamps are µs doubles from integer ns).
  constexpr double kToleranceUs = 1e-3;
  int checkedChildren = 0;
  for (auto& [tid, spans] : spansByThread) {
    std::vector<Span> open;  // the current chain of ancestors
    for (const Span& span : spans) {  // exported in (begin, depth) order per thread
      // The parent of a zone at depth d is the latest zone of depth d − 1 opened before it.
      while (static_cast<int>(open.size()) > span.depth) open.pop_back();
      ASSERT_EQ(static_cast<int>(open.size()), span.depth)
          << "zone '" << span.name << "' on tid " << tid << " has depth " << span.depth
          << " but no enclosing parent";
      if (!open.empty()) {
        const Span& parent = open.back();
        EXPECT_GE(span.ts, parent.ts - kToleranceUs) << span.name << " starts before " << parent.name;
        EXPECT_LE(span.ts + span.dur, parent.ts + parent.dur + kToleranceUs)
            << span.name << " ends after " << parent.name;
        EXPECT_EQ(span.frame, parent.frame);
        ++checkedChildren;
      }
      open.push_back(span);
    }
  }
  // Per substep: solve in assembly, broad and narrow in solve; capture zones on the caller are
  // inside render.
  EXPECT_GE(checkedChildren, (kThreads + 1) * kSubsteps * 3);

  // The expected structure, from the zones read back directly.
  for (const ZoneRecord& zone : profiler.zones()) {
    const std::string name = zone.name;
    // Thread 0 is "main", whose substeps run inside "health": one level deeper.
    const std::uint32_t base = zone.threadIndex == 0 ? 1u : 0u;
    if (name == "assembly") {
      EXPECT_EQ(zone.depth, base);
    } else if (name == "solve") {
      EXPECT_EQ(zone.depth, base + 1);
    } else if (name == "broad phase" || name == "narrow phase") {
      EXPECT_EQ(zone.depth, base + 2);
    }
    EXPECT_LE(zone.beginNs, zone.endNs);
    EXPECT_TRUE(zone.frameIndex == 7 || zone.frameIndex == 8);
  }
  std::remove(path.c_str());
}

TEST(Profiler, DisabledProfilerRecordsNothing) {
  Profiler profiler({.eventsPerThread = 64, .enabled = false});
  EXPECT_FALSE(profiler.isEnabled());
  recordSubstep(profiler);
  std::thread other([&] { recordSubstep(profiler); });
  other.join();
  EXPECT_TRUE(profiler.zones().empty());
  EXPECT_EQ(profiler.threadCount(), 0u);  // not even a buffer registration
  const nlohmann::json trace = nlohmann::json::parse(profiler.chromeTraceJson());
  for (const auto& event : trace["traceEvents"]) EXPECT_NE(event["ph"], "X");
}

TEST(Profiler, SwitchingOffStopsNewZones) {
  Profiler profiler({.eventsPerThread = 64, .enabled = true});
  { ProfileZone zone9(profiler, "solve"); }
  profiler.setEnabled(false);
  { ProfileZone zone10(profiler, "assembly"); }
  profiler.setEnabled(true);
  { ProfileZone zone11(profiler, "health"); }
  const std::vector<ZoneRecord> zones = profiler.zones();
  ASSERT_EQ(zones.size(), 2u);
  EXPECT_STREQ(zones[0].name, "solve");
  EXPECT_STREQ(zones[1].name, "health");
}

TEST(Profiler, FullBufferDropsZonesInsteadOfGrowing) {
  Profiler profiler({.eventsPerThread = 4, .enabled = true});
  for (int i = 0; i < 10; ++i) {
    ProfileZone zone12(profiler, "narrow phase");
  }
  EXPECT_EQ(profiler.zones().size(), 4u);
  EXPECT_EQ(profiler.droppedCount(), 6u);
  const TraceWriteResult written = profiler.writeChromeTrace(tempPath("weft_profiler_full.json"));
  EXPECT_TRUE(written.ok) << written.error;
  EXPECT_EQ(written.eventCount, 4u);
  EXPECT_EQ(written.droppedCount, 6u);
  profiler.setEventsPerThread(16);  // reallocates and empties
  EXPECT_EQ(profiler.eventsPerThread(), 16u);
  EXPECT_TRUE(profiler.zones().empty());
  EXPECT_EQ(profiler.droppedCount(), 0u);
  for (int i = 0; i < 10; ++i) {
    ProfileZone zone13(profiler, "narrow phase");
  }
  EXPECT_EQ(profiler.zones().size(), 10u);
  std::remove(tempPath("weft_profiler_full.json").c_str());
}

TEST(Profiler, FrameTotalsGroupZonesByNameWithinAFrame) {
  Profiler profiler({.eventsPerThread = 256, .enabled = true});
  profiler.beginFrame(1);
  for (int i = 0; i < 3; ++i) recordSubstep(profiler);
  profiler.beginFrame(2);
  recordSubstep(profiler);
  // The same name from a different string object is the same zone.
  const std::string dynamicName = std::string("sol") + "ve";
  {
    ProfileZone zone14(profiler, dynamicName.c_str());
    spin(10);
  }

  const std::vector<ZoneTotal> first = profiler.frameTotals(1);
  ASSERT_EQ(first.size(), 5u);
  std::map<std::string, ZoneTotal> byName;
  for (const ZoneTotal& total : first) byName[total.name] = total;
  EXPECT_EQ(byName["assembly"].count, 3u);
  EXPECT_EQ(byName["solve"].count, 3u);
  EXPECT_EQ(byName["broad phase"].count, 3u);
  EXPECT_EQ(byName["response"].count, 3u);
  // A parent's time includes its children's (intervals nest, so this holds exactly).
  EXPECT_GE(byName["solve"].totalMs, byName["broad phase"].totalMs);
  EXPECT_GE(byName["assembly"].totalMs, byName["solve"].totalMs);
  EXPECT_TRUE(std::is_sorted(first.begin(), first.end(),
                             [](const ZoneTotal& a, const ZoneTotal& b) { return a.name < b.name; }));

  const std::vector<ZoneTotal> second = profiler.frameTotals(2);
  std::map<std::string, std::uint32_t> counts;
  for (const ZoneTotal& total : second) counts[total.name] = total.count;
  EXPECT_EQ(counts["assembly"], 1u);
  EXPECT_EQ(counts["solve"], 2u);
  EXPECT_TRUE(profiler.frameTotals(3).empty());
}

TEST(Profiler, ClearForgetsZonesButKeepsThreads) {
  Profiler profiler({.eventsPerThread = 64, .enabled = true});
  profiler.registerThisThread("main");
  recordSubstep(profiler);
  EXPECT_FALSE(profiler.zones().empty());
  profiler.clear();
  EXPECT_TRUE(profiler.zones().empty());
  EXPECT_EQ(profiler.threadCount(), 1u);
  recordSubstep(profiler);
  EXPECT_EQ(profiler.zones().size(), 5u);
}

TEST(Profiler, SeparateProfilersDoNotShareZones) {
  Profiler a({.eventsPerThread = 64, .enabled = true});
  Profiler b({.eventsPerThread = 64, .enabled = true});
  { ProfileZone zone15(a, "solve"); }
  { ProfileZone zone16(b, "assembly"); }
  { ProfileZone zone17(a, "health"); }  // back to a: finds its buffer again
  ASSERT_EQ(a.zones().size(), 2u);
  ASSERT_EQ(b.zones().size(), 1u);
  EXPECT_STREQ(b.zones()[0].name, "assembly");
  EXPECT_EQ(a.threadCount(), 1u);
}

// The other tests build ProfileZone directly, so they also pass with -DWEFT_PROFILING=OFF; this
// one is about the macros.
TEST(Profiler, MacroRecordsIntoTheDefaultInstance) {
#if !WEFT_PROFILING
  GTEST_SKIP() << "built with WEFT_PROFILING=OFF: the macros are compiled out";
#endif
  Profiler& profiler = Profiler::instance();
  EXPECT_FALSE(profiler.isEnabled());  // off unless someone turns it on
  profiler.clear();
  { WEFT_PROFILE_ZONE("capture"); }
  EXPECT_TRUE(profiler.zones().empty());
  profiler.setEnabled(true);
  {
    WEFT_PROFILE_ZONE("render");
    WEFT_PROFILE_ZONE("capture");
  }
  profiler.setEnabled(false);
  const std::vector<ZoneRecord> zones = profiler.zones();
  ASSERT_EQ(zones.size(), 2u);
  EXPECT_STREQ(zones[0].name, "render");
  EXPECT_EQ(zones[0].depth, 0u);
  EXPECT_STREQ(zones[1].name, "capture");
  EXPECT_EQ(zones[1].depth, 1u);
  profiler.clear();
}

TEST(Profiler, WritingToAMissingDirectoryFailsWithAReadableError) {
  Profiler profiler({.eventsPerThread = 8, .enabled = true});
  { ProfileZone zone18(profiler, "solve"); }
  const std::string path = "/nonexistent-weft-dir/trace.json";
  const TraceWriteResult written = profiler.writeChromeTrace(path);
  EXPECT_FALSE(written.ok);
  EXPECT_FALSE(static_cast<bool>(written));
  EXPECT_NE(written.error.find(path), std::string::npos) << written.error;
}

}  // namespace
}  // namespace weft
