#include <weft/threading/Profiler.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <limits>

namespace weft {

namespace detail {
constinit Profiler g_defaultProfiler{DefaultProfilerTag{}};
}  // namespace detail

namespace {
/// Ids for non-default profilers; 0 is the default instance. Never reused, so a thread cache
/// left pointing at a destroyed profiler's buffer can never match again.
std::atomic<std::uint64_t> g_nextProfilerId{1};

std::unique_ptr<detail::ProfileEvent[]> allocateEvents(std::size_t count) {
  return std::unique_ptr<detail::ProfileEvent[]>(new detail::ProfileEvent[count]);
}

/// Snapshot of one thread's finished events (count read with acquire: events before it are done).
void appendZones(const detail::ProfileThreadBuffer& buffer, std::vector<ZoneRecord>& out) {
  const std::size_t count = buffer.count.load(std::memory_order_acquire);
  for (std::size_t i = 0; i < count; ++i) {
    const detail::ProfileEvent& event = buffer.events[i];
    out.push_back({event.name, event.beginNs, event.endNs, event.frameIndex, event.depth,
                   buffer.threadIndex});
  }
}
}  // namespace

Profiler::Profiler(Settings settings)
    : m_enabled(settings.enabled),
      m_id(g_nextProfilerId.fetch_add(1, std::memory_order_relaxed)),
      m_eventsPerThread(std::max<std::size_t>(1, settings.eventsPerThread)) {}

Profiler::~Profiler() = default;

detail::ProfileThreadBuffer* Profiler::registerSlow(std::string_view threadName) {
  const std::thread::id self = std::this_thread::get_id();
  std::lock_guard lock(m_mutex);
  detail::ProfileThreadBuffer* buffer = nullptr;
  // A thread that alternates between profilers finds its old buffer again.
  for (const auto& candidate : m_buffers) {
    if (candidate->owner == self) {
      buffer = candidate.get();
      break;
    }
  }
  if (buffer == nullptr) {
    auto created = std::make_unique<detail::ProfileThreadBuffer>();
    created->events = allocateEvents(m_eventsPerThread);
    created->capacity = m_eventsPerThread;
    created->threadIndex = static_cast<std::uint32_t>(m_buffers.size());
    created->owner = self;
    created->threadName = "thread " + std::to_string(created->threadIndex);
    buffer = created.get();
    m_buffers.push_back(std::move(created));
  }
  if (!threadName.empty()) buffer->threadName = std::string(threadName);
  detail::t_profilerCache = {m_id, buffer};
  return buffer;
}

void Profiler::registerThisThread(std::string_view threadName) { registerSlow(threadName); }

void Profiler::setEventsPerThread(std::size_t eventsPerThread) {
  std::lock_guard lock(m_mutex);
  m_eventsPerThread = std::max<std::size_t>(1, eventsPerThread);
  for (const auto& buffer : m_buffers) {
    buffer->count.store(0, std::memory_order_relaxed);
    buffer->events = allocateEvents(m_eventsPerThread);
    buffer->capacity = m_eventsPerThread;
    buffer->dropped.store(0, std::memory_order_relaxed);
  }
}

std::size_t Profiler::eventsPerThread() const {
  std::lock_guard lock(m_mutex);
  return m_eventsPerThread;
}

void Profiler::clear() {
  std::lock_guard lock(m_mutex);
  for (const auto& buffer : m_buffers) {
    buffer->count.store(0, std::memory_order_release);
    buffer->dropped.store(0, std::memory_order_relaxed);
  }
}

std::vector<ZoneRecord> Profiler::zones() const {
  std::vector<ZoneRecord> result;
  {
    std::lock_guard lock(m_mutex);
    for (const auto& buffer : m_buffers) appendZones(*buffer, result);
  }
  // Buffers hold zones in closing order (children first); readers want opening order.
  std::sort(result.begin(), result.end(), [](const ZoneRecord& a, const ZoneRecord& b) {
    if (a.threadIndex != b.threadIndex) return a.threadIndex < b.threadIndex;
    if (a.beginNs != b.beginNs) return a.beginNs < b.beginNs;
    return a.depth < b.depth;
  });
  return result;
}

std::vector<ZoneTotal> Profiler::frameTotals(std::uint64_t frameIndex) const {
  std::vector<ZoneTotal> totals;
  for (const ZoneRecord& zone : zones()) {
    if (zone.frameIndex != frameIndex) continue;
    // Group by contents: the same literal may have different addresses in different objects.
    auto it = std::find_if(totals.begin(), totals.end(),
                           [&](const ZoneTotal& total) { return total.name == zone.name; });
    if (it == totals.end()) {
      totals.push_back({zone.name, 0.0, 0});
      it = totals.end() - 1;
    }
    it->totalMs += FrameClock::msBetween(zone.beginNs, zone.endNs);
    ++it->count;
  }
  std::sort(totals.begin(), totals.end(),
            [](const ZoneTotal& a, const ZoneTotal& b) { return a.name < b.name; });
  return totals;
}

std::size_t Profiler::droppedCount() const {
  std::lock_guard lock(m_mutex);
  std::size_t dropped = 0;
  for (const auto& buffer : m_buffers) dropped += buffer->dropped.load(std::memory_order_relaxed);
  return dropped;
}

std::size_t Profiler::threadCount() const {
  std::lock_guard lock(m_mutex);
  return m_buffers.size();
}

std::string Profiler::chromeTraceJson() const {
  std::size_t zoneCount = 0;
  return buildChromeTrace(zoneCount);
}

std::string Profiler::buildChromeTrace(std::size_t& zoneCount) const {
  const std::vector<ZoneRecord> records = zones();
  zoneCount = records.size();
  std::vector<std::pair<std::uint32_t, std::string>> threadNames;
  {
    std::lock_guard lock(m_mutex);
    for (const auto& buffer : m_buffers) threadNames.emplace_back(buffer->threadIndex, buffer->threadName);
  }
  // Timestamps from the earliest zone keep the numbers small; µs with ns resolution as doubles.
  std::int64_t originNs = std::numeric_limits<std::int64_t>::max();
  for (const ZoneRecord& zone : records) originNs = std::min(originNs, zone.beginNs);

  nlohmann::json events = nlohmann::json::array();
  events.push_back({{"name", "process_name"}, {"ph", "M"}, {"pid", 1}, {"tid", 0},
                    {"args", {{"name", "weft"}}}});
  for (const auto& [threadIndex, name] : threadNames) {
    events.push_back({{"name", "thread_name"}, {"ph", "M"}, {"pid", 1}, {"tid", threadIndex},
                      {"args", {{"name", name}}}});
    events.push_back({{"name", "thread_sort_index"}, {"ph", "M"}, {"pid", 1}, {"tid", threadIndex},
                      {"args", {{"sort_index", threadIndex}}}});
  }
  // Sorted by thread, begin, depth: a parent precedes the children that start with it, which is
  // the order the trace viewers need to nest zones with equal timestamps.
  for (const ZoneRecord& zone : records) {
    events.push_back({{"name", zone.name},
                      {"cat", "weft"},
                      {"ph", "X"},
                      {"ts", FrameClock::usBetween(originNs, zone.beginNs)},
                      {"dur", FrameClock::usBetween(zone.beginNs, zone.endNs)},
                      {"pid", 1},
                      {"tid", zone.threadIndex},
                      {"args", {{"frame", zone.frameIndex}, {"depth", zone.depth}}}});
  }
  nlohmann::json trace = {{"traceEvents", std::move(events)}, {"displayTimeUnit", "ms"}};
  // replace: a name that is not UTF-8 must not make the export throw.
  return trace.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

TraceWriteResult Profiler::writeChromeTrace(const std::string& path) const {
  TraceWriteResult result;
  std::string json;
  try {
    json = buildChromeTrace(result.eventCount);
  } catch (const std::exception& error) {
    result.ok = false;
    result.error = "Chrome trace '" + path + "': could not build the JSON (" + error.what() + ")";
    return result;
  }
  result.droppedCount = droppedCount();
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) {
    result.ok = false;
    result.error = "Chrome trace '" + path + "': cannot open for writing (" + std::strerror(errno) +
                   "); check that the directory exists and is writable";
    return result;
  }
  file.write(json.data(), static_cast<std::streamsize>(json.size()));
  file.close();
  if (!file) {
    result.ok = false;
    result.error = "Chrome trace '" + path + "': write failed (" + std::strerror(errno) +
                   "); check free disk space";
  }
  return result;
}

}  // namespace weft
