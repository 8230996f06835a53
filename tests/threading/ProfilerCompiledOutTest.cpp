// WEFT_PROFILING=0 turns the zone macros into nothing: no object, no recording, even with the
// profiler switched on. This translation unit is built as if the CMake option were OFF.
#undef WEFT_PROFILING
#define WEFT_PROFILING 0
#include <weft/threading/Profiler.h>

#include <gtest/gtest.h>

namespace weft {
namespace {

TEST(ProfilerCompiledOut, ZoneMacrosRecordNothing) {
  Profiler profiler({.eventsPerThread = 16, .enabled = true});
  {
    WEFT_PROFILE_ZONE_ON(profiler, "solve");
    WEFT_PROFILE_ZONE("assembly");
  }
  EXPECT_TRUE(profiler.zones().empty());
  EXPECT_EQ(profiler.threadCount(), 0u);
  // The class itself still works when used directly.
  { ProfileZone zone(profiler, "health"); }
  EXPECT_EQ(profiler.zones().size(), 1u);
}

}  // namespace
}  // namespace weft
