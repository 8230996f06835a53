// weft-memory-footprint: heap bytes per vertex of a cloth, measured, beside the estimates the
// engine checks against the available memory before it allocates (ClothModel::
// estimatedBuildBytes, World::estimatedClothBytes).
//
// Every operator new of the process is counted (live bytes and their peak, from
// malloc_usable_size), around four stages of square grid cloths of growing size: grid() (peak
// while building, bytes kept), fromMesh() of the same triangles (peak), createCloth() and the
// first three frames of a curtain-like scene (peak and kept). Serial (one thread) so the peaks
// are the engine's own, not a thread pool's.
//
//   weft-memory-footprint [--sizes 101,201,401]
#include <weft/engine/World.h>

#include <CLI/CLI.hpp>

#include <malloc.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <new>
#include <sstream>
#include <string>
#include <vector>

namespace {
std::atomic<long long> g_live{0};
std::atomic<long long> g_peak{0};

void* track(void* memory) {
  if (!memory) throw std::bad_alloc();
  const long long live = g_live.fetch_add(static_cast<long long>(malloc_usable_size(memory))) +
                         static_cast<long long>(malloc_usable_size(memory));
  long long peak = g_peak.load();
  while (live > peak && !g_peak.compare_exchange_weak(peak, live)) {
  }
  return memory;
}
void untrack(void* memory) {
  if (memory) g_live.fetch_sub(static_cast<long long>(malloc_usable_size(memory)));
  std::free(memory);
}
void* alignedAlloc(std::size_t size, std::align_val_t alignment) {
  const std::size_t align = static_cast<std::size_t>(alignment);
  return std::aligned_alloc(align, (size + align - 1) / align * align);
}
}  // namespace

void* operator new(std::size_t size) { return track(std::malloc(size == 0 ? 1 : size)); }
void* operator new[](std::size_t size) { return track(std::malloc(size == 0 ? 1 : size)); }
void* operator new(std::size_t size, std::align_val_t alignment) { return track(alignedAlloc(size, alignment)); }
void* operator new[](std::size_t size, std::align_val_t alignment) { return track(alignedAlloc(size, alignment)); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try { return track(std::malloc(size == 0 ? 1 : size)); } catch (...) { return nullptr; }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  try { return track(std::malloc(size == 0 ? 1 : size)); } catch (...) { return nullptr; }
}
void* operator new(std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  try { return track(alignedAlloc(size, alignment)); } catch (...) { return nullptr; }
}
void* operator new[](std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  try { return track(alignedAlloc(size, alignment)); } catch (...) { return nullptr; }
}
void operator delete(void* memory) noexcept { untrack(memory); }
void operator delete[](void* memory) noexcept { untrack(memory); }
void operator delete(void* memory, std::size_t) noexcept { untrack(memory); }
void operator delete[](void* memory, std::size_t) noexcept { untrack(memory); }
void operator delete(void* memory, std::align_val_t) noexcept { untrack(memory); }
void operator delete[](void* memory, std::align_val_t) noexcept { untrack(memory); }
void operator delete(void* memory, std::size_t, std::align_val_t) noexcept { untrack(memory); }
void operator delete[](void* memory, std::size_t, std::align_val_t) noexcept { untrack(memory); }
void operator delete(void* memory, const std::nothrow_t&) noexcept { untrack(memory); }
void operator delete[](void* memory, const std::nothrow_t&) noexcept { untrack(memory); }
void operator delete(void* memory, std::align_val_t, const std::nothrow_t&) noexcept { untrack(memory); }
void operator delete[](void* memory, std::align_val_t, const std::nothrow_t&) noexcept { untrack(memory); }

namespace {

// Peak and kept bytes of one stage, relative to the live bytes when it started.
struct Stage {
  long long start = 0;
  void begin() {
    start = g_live.load();
    g_peak.store(start);
  }
  long long peak() const { return g_peak.load() - start; }
  long long kept() const { return g_live.load() - start; }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Heap bytes per vertex of a cloth against the engine's estimates"};
  std::vector<unsigned> sizes{101, 201, 401};
  app.add_option("--sizes", sizes, "Square grid sizes (vertices per side)")->delimiter(',');
  CLI11_PARSE(app, argc, argv);

  std::printf("| grid | vertices | triangles | grid() peak B/v | model kept B/v | fromMesh() peak B/v "
              "| model estimate B/v | cloth peak B/v (create + 3 frames) | cloth kept B/v | cloth "
              "estimate B/v |\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (unsigned side : sizes) {
    using namespace weft;
    GridSettings grid;
    grid.columns = grid.rows = side;
    grid.width = grid.height = 0.01 * (side - 1);  // 1 cm cells
    grid.origin = Vec3(0, 1, 0);
    Stage stage;
    stage.begin();
    auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
    const long long gridPeak = stage.peak(), modelKept = stage.kept();
    const double vertices = model->vertexCount(), triangles = model->triangleCount();

    TriangleMesh mesh;
    mesh.positions = model->restPositions();
    mesh.indices = model->indices();
    stage.begin();
    long long meshPeak = 0;
    {
      Result<ClothModel> fromMesh = ClothModel::fromMesh(mesh);
      meshPeak = stage.peak();
      if (!fromMesh.ok()) std::fprintf(stderr, "%s\n", fromMesh.error().message.c_str());
    }
    mesh = TriangleMesh{};

    WorldSettings worldSettings;
    worldSettings.threadCount = 1;
    World world(worldSettings);
    ClothSettings settings;
    for (Index c = 0; c < side; ++c) settings.pinnedVertices.push_back((side - 1) * side + c);
    stage.begin();
    const ClothId cloth = world.createCloth(model, settings).value();
    for (int frame = 0; frame < 3; ++frame) world.step(1.0 / 60.0);
    const long long clothPeak = stage.peak(), clothKept = stage.kept();
    (void)cloth;

    const double modelEstimate = double(ClothModel::estimatedBuildBytes(model->vertexCount(), model->triangleCount()));
    const double clothEstimate = double(World::estimatedClothBytes(model->vertexCount(), model->triangleCount()));
    std::printf("| %u x %u | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f |\n", side, side,
                vertices, triangles, gridPeak / vertices, modelKept / vertices, meshPeak / vertices,
                modelEstimate / vertices, clothPeak / vertices, clothKept / vertices,
                clothEstimate / vertices);
    std::fflush(stdout);
  }
  return 0;
}
