#include <weft/threading/TaskSystem.h>

#include <thread>

namespace weft {

namespace detail {

PartialBuffer::~PartialBuffer() {
  if (m_data != nullptr) ::operator delete(m_data, std::align_val_t{kAlignment});
}

void* PartialBuffer::reserve(std::size_t bytes) {
  if (bytes <= m_capacity) return m_data;
  // Grow geometrically so a scene that slowly adds contacts does not reallocate every frame.
  const std::size_t newCapacity = std::max(bytes, 2 * m_capacity);
  void* data = ::operator new(newCapacity, std::align_val_t{kAlignment});
  if (m_data != nullptr) ::operator delete(m_data, std::align_val_t{kAlignment});
  m_data = data;
  m_capacity = newCapacity;
  return m_data;
}

}  // namespace detail

std::string validate(const TaskSystemSettings& settings) {
  if (settings.threadCount >= 0 && settings.threadCount <= TaskSystemSettings::kMaxThreadCount) return {};
  return "TaskSystemSettings::threadCount = " + std::to_string(settings.threadCount) +
         " is out of range: give 0 (the machine's cores), 1 (serial) or up to " +
         std::to_string(TaskSystemSettings::kMaxThreadCount) + " threads";
}

namespace {
int resolveThreadCount(int requested) {
  // Out of range (validate() names the mistake): the serial reference, which spawns nothing.
  if (requested < 0 || requested > TaskSystemSettings::kMaxThreadCount) return 1;
  if (requested > 0) return requested;
  // hardware_concurrency() may return 0 when it cannot tell: fall back to the serial reference.
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}
}  // namespace

TaskSystem::TaskSystem(Settings settings) : m_threadCount(resolveThreadCount(settings.threadCount)) {
  if (m_threadCount == 1) return;  // serial reference: no arena, no TBB
  m_ownedArena = std::make_unique<tbb::task_arena>(m_threadCount);
  // Build the arena now rather than inside the first step; this creates no threads by itself.
  m_ownedArena->initialize();
  m_arena = m_ownedArena.get();
}

TaskSystem::TaskSystem(tbb::task_arena& arena) {
  arena.initialize();  // a no-op if the caller already did it; fixes max_concurrency()
  m_threadCount = std::max(1, arena.max_concurrency());
  if (m_threadCount > 1) m_arena = &arena;
}

TaskSystem::~TaskSystem() = default;

}  // namespace weft
