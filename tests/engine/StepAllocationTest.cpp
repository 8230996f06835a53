// World::step() allocates nothing once a cloth has taken its first step (docs/architecture.md): the
// matrix pattern, solver scratch and integrator buffers are all sized up front or on first use.
// Counted by replacing the global operator new for this test binary; counting is switched on
// only around the steps under test. The replacement also keeps the heap's live and peak bytes
// for the whole binary (HeapCounter.h).
#include <weft/collision/TriangleMeshShape.h>
#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>
#include <weft/scenes/Curtain.h>

#include <gtest/gtest.h>

#include "HeapCounter.h"
#include "collision/CollisionTestSupport.h"

#include <malloc.h>

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
// Heap bytes live and their peak (HeapCounter.h), from the allocator's usable sizes.
std::atomic<long long> g_liveBytes{0};
std::atomic<long long> g_peakBytes{0};

void* noteNew(void* memory) {
  if (!memory) return memory;
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  const long long size = static_cast<long long>(malloc_usable_size(memory));
  const long long live = g_liveBytes.fetch_add(size, std::memory_order_relaxed) + size;
  long long peak = g_peakBytes.load(std::memory_order_relaxed);
  while (live > peak && !g_peakBytes.compare_exchange_weak(peak, live, std::memory_order_relaxed)) {
  }
  return memory;
}
// Not inlined: GCC would then see free() on a pointer from operator new and warn.
[[gnu::noinline]] void freeNoted(void* memory) {
  if (memory) g_liveBytes.fetch_sub(static_cast<long long>(malloc_usable_size(memory)), std::memory_order_relaxed);
  std::free(memory);
}
void* alignedAllocate(std::size_t size, std::align_val_t alignment) {
  const std::size_t align = static_cast<std::size_t>(alignment);
  return std::aligned_alloc(align, (size + align - 1) / align * align);
}
}  // namespace

namespace weft::test {
long long heapLiveBytes() { return g_liveBytes.load(); }
long long heapPeakBytes() { return g_peakBytes.load(); }
void resetHeapPeak() { g_peakBytes.store(g_liveBytes.load()); }
}  // namespace weft::test

void* operator new(std::size_t size) {
  if (void* memory = noteNew(std::malloc(size == 0 ? 1 : size))) return memory;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, std::align_val_t alignment) {
  if (void* memory = noteNew(alignedAllocate(size, alignment))) return memory;
  throw std::bad_alloc();
}
// Every other form of new is replaced too, so that no block from the library's allocator reaches
// the free() below (std::stable_sort's nothrow temporary buffer did, and AddressSanitizer reports
// that as an alloc-dealloc mismatch).
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return noteNew(std::malloc(size == 0 ? 1 : size));
}
void* operator new(std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return noteNew(alignedAllocate(size, alignment));
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new[](std::size_t size, std::align_val_t alignment) { return operator new(size, alignment); }
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept { return operator new(size, tag); }
void* operator new[](std::size_t size, std::align_val_t alignment, const std::nothrow_t& tag) noexcept {
  return operator new(size, alignment, tag);
}
void operator delete(void* memory, const std::nothrow_t&) noexcept { freeNoted(memory); }
void operator delete(void* memory, std::align_val_t, const std::nothrow_t&) noexcept { freeNoted(memory); }
void operator delete[](void* memory) noexcept { freeNoted(memory); }
void operator delete[](void* memory, std::size_t) noexcept { freeNoted(memory); }
void operator delete[](void* memory, std::align_val_t) noexcept { freeNoted(memory); }
void operator delete[](void* memory, std::size_t, std::align_val_t) noexcept { freeNoted(memory); }
void operator delete[](void* memory, const std::nothrow_t&) noexcept { freeNoted(memory); }
void operator delete[](void* memory, std::align_val_t, const std::nothrow_t&) noexcept { freeNoted(memory); }
void operator delete(void* memory) noexcept { freeNoted(memory); }
void operator delete(void* memory, std::size_t) noexcept { freeNoted(memory); }
void operator delete(void* memory, std::align_val_t) noexcept { freeNoted(memory); }
void operator delete(void* memory, std::size_t, std::align_val_t) noexcept { freeNoted(memory); }

namespace weft {
namespace {

TEST(StepAllocation, SteadyStepsAllocateNothing) {
  for (IntegratorKind integrator :
       {IntegratorKind::ImplicitEuler, IntegratorKind::Bdf2, IntegratorKind::RungeKutta4}) {
    CurtainSettings settings;
    settings.solver.integrator = integrator;
    settings.solver.newtonIterations = isImplicit(integrator) ? 1 : 0;
    CurtainScene scene = CurtainScene::create(settings).value();
    scene.stepFrame();  // first step sizes the scratch buffers
    g_allocations = 0;
    g_counting = true;
    for (int frame = 0; frame < 2; ++frame) scene.stepFrame();
    g_counting = false;
    EXPECT_EQ(g_allocations.load(), 0) << integratorName(integrator);
  }
}

TEST(StepAllocation, ADensePadRestingOnASheetAllocatesNothing) {
  // Two cloths in contact, their pairs projected with the strain limits: once the pad rests,
  // the frames reuse the buffers of the first ones.
  World world;
  auto square = [](Index vertices, Real size) {
    GridSettings grid;
    grid.columns = grid.rows = vertices;
    grid.width = grid.height = size;
    grid.origin = Vec3(-size / 2, 1.0, size / 2);
    grid.widthAxis = Vec3(1, 0, 0);
    grid.heightAxis = Vec3(0, 0, -1);
    return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  };
  ClothSettings sheet;
  sheet.material = cottonFabric();
  sheet.pinnedVertices = {0, 8, 72, 80};
  ClothSettings pad;
  pad.material = cottonFabric();
  pad.material.arealDensity *= 100;
  pad.translation = Vec3(0.02, 0.05, -0.03);
  ASSERT_TRUE(world.createCloth(square(9, 0.5), sheet).ok());
  ASSERT_TRUE(world.createCloth(square(4, 0.12), pad).ok());
  for (int frame = 0; frame < 90; ++frame) world.step(1.0 / 60.0);
  g_allocations = 0;
  g_counting = true;
  for (int frame = 0; frame < 30; ++frame) world.step(1.0 / 60.0);
  g_counting = false;
  EXPECT_GT(world.stats().clothContacts, 0u);
  EXPECT_EQ(g_allocations.load(), 0);
}

TEST(StepAllocation, AClothDrapedOverAMeshBoxAllocatesNothing) {
  // A mesh collider's vertex and face contacts (its edges as cores, MeshEdge) reuse their
  // buffers once the cloth has draped over its sharp edges (in the first second the contact
  // lists still grow).
  World world;
  const test::MeshArrays box = test::makeBox(Vec3(0.1, 0.1, 0.1));
  ASSERT_TRUE(world.addCollider(TriangleMeshShape::create(box.positions, box.indices).value()).ok());
  GridSettings grid;
  grid.columns = grid.rows = 15;
  grid.width = grid.height = 0.5;
  grid.origin = Vec3(-0.25, 0.2, 0.25);
  grid.widthAxis = Vec3(1, 0, 0);
  grid.heightAxis = Vec3(0, 0, -1);
  ClothSettings settings;
  settings.material = cottonFabric();
  ASSERT_TRUE(world
                  .createCloth(std::make_shared<const ClothModel>(ClothModel::grid(grid).value()),
                               settings)
                  .ok());
  for (int frame = 0; frame < 120; ++frame) world.step(1.0 / 60.0);  // draped and still
  g_allocations = 0;
  g_counting = true;
  Index faceContacts = 0;
  for (int frame = 0; frame < 30; ++frame) {
    world.step(1.0 / 60.0);
    faceContacts += world.stats().faceContacts;
  }
  g_counting = false;
  EXPECT_GT(world.stats().contacts, 0u);
  EXPECT_GT(faceContacts, 0u);
  EXPECT_EQ(g_allocations.load(), 0);
}

TEST(StepAllocation, TheCounterSeesAllocations) {
  // Guards the test above against a counter that counts nothing.
  g_allocations = 0;
  g_counting = true;
  auto* vector = new std::vector<int>(100);
  g_counting = false;
  delete vector;
  EXPECT_GE(g_allocations.load(), 2);
}

}  // namespace
}  // namespace weft
