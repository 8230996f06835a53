// Profiler: scoped zones recorded per thread, exported as a Chrome trace (Perfetto, chrome://tracing).
//
// Design note
// -----------
// * Recording. WEFT_PROFILE_ZONE("solve") puts a ProfileZone on the stack: it reads the clock
//   when built and, when destroyed, appends one complete event {name, begin ns, end ns, depth,
//   frame} to the calling thread's buffer. Each thread writes only its own buffer: no locks, no
//   atomic read-modify-write on the hot path (a relaxed load and a release store of the buffer's
//   count so a reader sees only finished events). Buffers are preallocated (eventsPerThread);
//   when one is full, further events are counted as dropped rather than reallocated. A thread
//   registers its buffer (one mutex lock and one allocation) the first time it records;
//   registerThisThread() does that up front, e.g. outside the frame loop.
// * Names are `const char*` with static storage (string literals): storing a pointer is free,
//   and totals group zones by the string's contents, not its address.
// * Switches. Compile time: WEFT_PROFILING=0 (CMake option WEFT_PROFILING) turns the macros into
//   nothing. Run time: setEnabled(false), the default, leaves one relaxed atomic load and a
//   branch per zone.
// * One default instance plus ordinary objects. Zones sit deep inside collision and engine
//   kernels; passing a Profiler& through every kernel signature would couple math to tooling,
//   and a trace describes one process anyway. So WEFT_PROFILE_ZONE records into
//   Profiler::instance(), a constant-initialised global (no init guard on the hot path). The
//   class is still an ordinary object: tests build their own and use WEFT_PROFILE_ZONE_ON, so
//   they never share state.
// * Reading back (zones(), frameTotals(), chromeTraceJson()) is safe while other threads record:
//   it sees the events finished before it looked. clear(), setEventsPerThread() and destroying
//   a Profiler need quiescence: no zone open or being recorded on any thread (between frames).
//
// Rejected: a global lock-free MPSC queue (contended cache line per event), std::mutex per
// event, tracing libraries (Tracy, Perfetto SDK: heavy dependencies for what is ~300 lines).
#pragma once

#include <weft/threading/FrameClock.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#ifndef WEFT_PROFILING
#define WEFT_PROFILING 1  ///< 0 compiles every WEFT_PROFILE_ZONE to nothing
#endif

namespace weft {

/// One finished zone, as read back from a Profiler.
struct ZoneRecord {
  const char* name = "";        ///< the zone's name (static storage)
  std::int64_t beginNs = 0;     ///< FrameClock::nowNs() when the zone opened
  std::int64_t endNs = 0;       ///< FrameClock::nowNs() when it closed
  std::uint64_t frameIndex = 0; ///< Profiler::frameIndex() when it opened
  std::uint32_t depth = 0;      ///< number of zones open on this thread when it opened
  std::uint32_t threadIndex = 0;///< the recording thread, in registration order (trace "tid")
};

/// Sum of the zones of one name within one frame.
struct ZoneTotal {
  std::string name;      ///< zone name
  double totalMs = 0.0;  ///< summed over threads: parallel zones add CPU time, not wall time
  std::uint32_t count = 0; ///< number of zones summed
};

/// Outcome of writing a trace: ok, or a message naming the file and what to do.
struct TraceWriteResult {
  bool ok = true;               ///< the file was written completely
  std::string error;            ///< empty when ok
  std::size_t eventCount = 0;   ///< zones written
  std::size_t droppedCount = 0; ///< zones lost to full buffers (raise eventsPerThread)
  /// True when ok.
  explicit operator bool() const { return ok; }
};

namespace detail {
/// One recorded zone in a thread buffer.
struct ProfileEvent {
  const char* name;
  std::int64_t beginNs;
  std::int64_t endNs;
  std::uint64_t frameIndex;
  std::uint32_t depth;
};

/// A thread's events; written only by that thread, read by anyone up to `count`.
struct alignas(128) ProfileThreadBuffer {
  std::unique_ptr<ProfileEvent[]> events;
  std::size_t capacity = 0;
  std::atomic<std::size_t> count{0};     ///< finished events; release-stored by the owner
  std::atomic<std::uint64_t> dropped{0}; ///< events lost because the buffer was full
  std::uint32_t depth = 0;               ///< open zones; touched only by the owner
  std::uint32_t threadIndex = 0;
  std::thread::id owner;
  std::string threadName;                ///< guarded by Profiler::m_mutex
};

/// Selects the constructor of the default instance.
struct DefaultProfilerTag {};

/// The last (profiler, buffer) pair the calling thread used: the hot-path lookup.
struct ProfilerThreadCache {
  std::uint64_t profilerId = ~std::uint64_t{0};
  ProfileThreadBuffer* buffer = nullptr;
};
inline constinit thread_local ProfilerThreadCache t_profilerCache{};
}  // namespace detail

/// Default events preallocated per thread: 32 Ki × 40 B = 1.25 MiB, about 600 frames of 50
/// zones per thread (the 10 s curtain).
inline constexpr std::size_t kDefaultProfilerEventsPerThread = std::size_t{1} << 15;

/// How a Profiler is built (Profiler::Settings).
struct ProfilerSettings {
  std::size_t eventsPerThread = kDefaultProfilerEventsPerThread;  ///< preallocated zones per
                                                                  ///< thread; raise it if
                                                                  ///< droppedCount() > 0
  bool enabled = false;                                           ///< record from the start
};

/// Collects zones from any number of threads and exports them as a Chrome trace.
class Profiler {
 public:
  /// Construction options.
  using Settings = ProfilerSettings;

  /// An independent profiler (tests, tools): its own buffers, its own switch.
  explicit Profiler(Settings settings = {});

  /// Builds the default instance behind Profiler::instance(); not for other use.
  constexpr explicit Profiler(detail::DefaultProfilerTag) noexcept {}

  ~Profiler();
  Profiler(const Profiler&) = delete;
  Profiler& operator=(const Profiler&) = delete;

  /// The default profiler that WEFT_PROFILE_ZONE records into.
  static Profiler& instance() noexcept;

  /// Turns recording on or off; zones already open still finish.
  void setEnabled(bool enabled) noexcept { m_enabled.store(enabled, std::memory_order_relaxed); }

  /// True when new zones are recorded.
  bool isEnabled() const noexcept { return m_enabled.load(std::memory_order_relaxed); }

  /// Marks the start of frame frameIndex: zones opened from now on carry it.
  void beginFrame(std::uint64_t frameIndex) noexcept {
    m_frameIndex.store(frameIndex, std::memory_order_relaxed);
  }

  /// The frame index that new zones carry.
  std::uint64_t frameIndex() const noexcept { return m_frameIndex.load(std::memory_order_relaxed); }

  /// Registers the calling thread's buffer now (locks once, allocates) instead of at its first
  /// zone; optionally names it in the trace (otherwise "thread N").
  void registerThisThread(std::string_view threadName = {});

  /// Preallocated events per thread. Reallocates and empties every buffer: call when quiescent.
  void setEventsPerThread(std::size_t eventsPerThread);

  /// Preallocated events per thread.
  std::size_t eventsPerThread() const;

  /// Forgets every recorded zone (buffers and thread names stay). Call when quiescent.
  void clear();

  /// Every finished zone, ordered by thread, then begin time, then depth (parents first).
  std::vector<ZoneRecord> zones() const;

  /// Per-name totals of the zones opened in frame frameIndex, ordered by name.
  std::vector<ZoneTotal> frameTotals(std::uint64_t frameIndex) const;

  /// Zones lost because a thread's buffer was full.
  std::size_t droppedCount() const;

  /// Number of threads that have recorded (or registered).
  std::size_t threadCount() const;

  /// The trace as Chrome trace-event JSON: complete events ("ph":"X", ts and dur in µs from the
  /// earliest zone, pid 1, tid = thread index, args {frame, depth}) and thread_name metadata.
  std::string chromeTraceJson() const;

  /// Writes chromeTraceJson() to path (open it in ui.perfetto.dev or chrome://tracing).
  TraceWriteResult writeChromeTrace(const std::string& path) const;

 private:
  friend class ProfileZone;

  /// The calling thread's buffer, registering it on first use. Hot path of ProfileZone: one
  /// thread_local compare when the thread last recorded into this profiler.
  detail::ProfileThreadBuffer* threadBuffer() {
    detail::ProfilerThreadCache& cache = detail::t_profilerCache;
    if (cache.profilerId == m_id) return cache.buffer;
    return registerSlow({});
  }

  detail::ProfileThreadBuffer* registerSlow(std::string_view threadName);
  std::string buildChromeTrace(std::size_t& zoneCount) const;

  std::atomic<bool> m_enabled{false};
  std::atomic<std::uint64_t> m_frameIndex{0};
  std::uint64_t m_id = 0;  ///< unique per profiler (0 = the default): keys the thread cache
  std::size_t m_eventsPerThread = kDefaultProfilerEventsPerThread;  ///< guarded by m_mutex
  mutable std::mutex m_mutex;  ///< guards registration, the buffer list and names
  std::vector<std::unique_ptr<detail::ProfileThreadBuffer>> m_buffers;
};

namespace detail {
/// Storage of Profiler::instance(): constant-initialised, so no guard check per zone.
extern constinit Profiler g_defaultProfiler;
}  // namespace detail

inline Profiler& Profiler::instance() noexcept { return detail::g_defaultProfiler; }

/// RAII zone: records [construction, destruction) on the calling thread if the profiler is on.
class ProfileZone {
 public:
  /// Opens zone `name` (a string literal) in profiler; costs one relaxed load when it is off.
  ProfileZone(Profiler& profiler, const char* name) {
    if (!profiler.isEnabled()) return;
    m_buffer = profiler.threadBuffer();
    m_name = name;
    m_depth = m_buffer->depth++;
    m_frameIndex = profiler.frameIndex();
    m_beginNs = FrameClock::nowNs();
  }

  /// Closes the zone and appends it to the thread's buffer (or counts it as dropped).
  ~ProfileZone() {
    if (m_buffer == nullptr) return;
    const std::int64_t endNs = FrameClock::nowNs();
    --m_buffer->depth;
    const std::size_t index = m_buffer->count.load(std::memory_order_relaxed);
    if (index < m_buffer->capacity) {
      m_buffer->events[index] = {m_name, m_beginNs, endNs, m_frameIndex, m_depth};
      // Publish: a reader that sees the new count sees the event.
      m_buffer->count.store(index + 1, std::memory_order_release);
    } else {
      m_buffer->dropped.fetch_add(1, std::memory_order_relaxed);
    }
  }

  ProfileZone(const ProfileZone&) = delete;
  ProfileZone& operator=(const ProfileZone&) = delete;

 private:
  detail::ProfileThreadBuffer* m_buffer = nullptr;  ///< nullptr: profiler was off, record nothing
  const char* m_name = nullptr;
  std::int64_t m_beginNs = 0;
  std::uint64_t m_frameIndex = 0;
  std::uint32_t m_depth = 0;
};

}  // namespace weft

#define WEFT_PROFILE_CONCAT_INNER(a, b) a##b
#define WEFT_PROFILE_CONCAT(a, b) WEFT_PROFILE_CONCAT_INNER(a, b)

#if WEFT_PROFILING
/// Records the rest of the enclosing scope as zone `name` (a string literal) in Profiler::instance().
#define WEFT_PROFILE_ZONE(name) \
  ::weft::ProfileZone WEFT_PROFILE_CONCAT(weftProfileZone_, __COUNTER__)(::weft::Profiler::instance(), name)
/// Records the rest of the enclosing scope as zone `name` in the given Profiler.
#define WEFT_PROFILE_ZONE_ON(profiler, name) \
  ::weft::ProfileZone WEFT_PROFILE_CONCAT(weftProfileZone_, __COUNTER__)(profiler, name)
#else
#define WEFT_PROFILE_ZONE(name) static_cast<void>(0)
// sizeof keeps `profiler` "used" (no -Wunused warnings) without evaluating it.
#define WEFT_PROFILE_ZONE_ON(profiler, name) static_cast<void>(sizeof(profiler))
#endif
