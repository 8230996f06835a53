// The stretch/shear/damping kernel of one triangle, alone, on the curtain's triangles: the three
// conditions through accumulateConditionForces in Definite mode (the path ClothForces keeps for
// Exact mode, and took for every assembly before stretchShear()) against the fused stretchShear(), each
// with its scatter into the system matrix, forces and (∂f/∂x)·u. One thread, model order:
//   build/bench/weft-bench --benchmark_filter=MembraneKernel --benchmark_repetitions=10
//                          --benchmark_enable_random_interleaving=true   (one line)
// Counter per_triangle: ns per triangle (the kernel and its scatter, on one thread).
#include "forces/BaraffWitkin.h"
#include "forces/Condition.h"
#include "solver/BlockSparseMatrix.h"

#include <weft/scenes/Curtain.h>

#include <benchmark/benchmark.h>

#include <map>
#include <memory>

namespace weft {
namespace {

// The curtain a few frames into its script, its triangles' matrix slots and rest constants.
struct MembraneSetup {
  std::unique_ptr<CurtainScene> scene;
  BlockSparseMatrix matrix;
  std::vector<std::array<Index, 9>> slots;  // slot of block (corner a, corner b) at 3a + b
  std::vector<StretchShearRest> membranes;
  Vec3Array x, v, f, product;

  explicit MembraneSetup(Index size) {
    CurtainSettings settings;
    settings.size = size;
    scene = std::make_unique<CurtainScene>(CurtainScene::create(settings).value());
    for (int frame = 0; frame < 12; ++frame) scene->stepFrame();
    const auto positions = scene->world().positions(scene->cloth()).value();
    const auto velocities = scene->world().velocities(scene->cloth()).value();
    x.assign(positions.begin(), positions.end());
    v.assign(velocities.begin(), velocities.end());
    f.assign(x.size(), Vec3::Zero());
    product.assign(x.size(), Vec3::Zero());
    const ClothModel& model = scene->model();
    const ClothMaterial material;
    std::vector<std::array<Index, 2>> pairs;
    for (const TriangleRest& triangle : model.triangles()) {
      const auto& t = triangle.vertices;
      pairs.push_back({t[0], t[1]});
      pairs.push_back({t[0], t[2]});
      pairs.push_back({t[1], t[2]});
    }
    matrix.build(model.vertexCount(), pairs);
    for (const TriangleRest& triangle : model.triangles()) {
      std::array<Index, 9> slot;
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) slot[3 * a + b] = matrix.slot(triangle.vertices[a], triangle.vertices[b]);
      }
      slots.push_back(slot);
      membranes.push_back(
          makeStretchShearRest(triangle, material.warpRestScale, material.weftRestScale));
    }
  }
};

MembraneSetup& membraneSetup(Index size) {
  static std::map<Index, std::unique_ptr<MembraneSetup>> cache;
  std::unique_ptr<MembraneSetup>& entry = cache[size];
  if (!entry) entry = std::make_unique<MembraneSetup>(size);
  return *entry;
}

// The separate conditions and ElementForces<3>, scattered as ClothForces scatters an element.
// Not inlined, so bench/tools/callgrind-per-call can count one call.
[[gnu::noinline]] Real separateKernels(MembraneSetup& setup, const ClothMaterial& material, Real h) {
  const std::vector<TriangleRest>& triangles = setup.scene->model().triangles();
  const StiffnessMode mode = StiffnessMode::Definite;
  Real energy = 0;
  ElementForces<3> local;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const TriangleRest& rest = triangles[t];
    const auto& corner = rest.vertices;
    const Vec3 &x0 = setup.x[corner[0]], &x1 = setup.x[corner[1]], &x2 = setup.x[corner[2]];
    Eigen::Matrix<Real, 9, 1> velocities;
    for (int a = 0; a < 3; ++a) velocities.segment<3>(3 * a) = setup.v[corner[a]];
    local.setZero();
    const StretchConditions stretch = stretchConditions(
        x0, x1, x2, rest, material.warpRestScale, material.weftRestScale, true);
    accumulateConditionForces(stretch.warp, material.warpStretchStiffness,
                              material.stretchDamping, velocities, mode, true, local);
    accumulateConditionForces(stretch.weft, material.weftStretchStiffness,
                              material.stretchDamping, velocities, mode, true, local);
    accumulateConditionForces(shearCondition(x0, x1, x2, rest, false), material.shearStiffness,
                              material.shearDamping, velocities, mode, true, local);
    energy += local.energy;
    for (int a = 0; a < 3; ++a) {
      setup.f[corner[a]] += local.force.segment<3>(3 * a);
      Vec3 product = Vec3::Zero();
      for (int b = 0; b < 3; ++b) {
        const Mat3 positionBlock = local.positionJacobian.block<3, 3>(3 * a, 3 * b);
        setup.matrix.block(setup.slots[t][3 * a + b]) -=
            h * local.velocityJacobian.block<3, 3>(3 * a, 3 * b) + (h * h) * positionBlock;
        product += positionBlock * setup.v[corner[b]];
      }
      setup.product[corner[a]] += product;
    }
  }
  return energy;
}

// stretchShear() and addStretchShearBlock(), scattered as ClothForces scatters a triangle.
[[gnu::noinline]] Real fusedKernel(MembraneSetup& setup, const ClothMaterial& material, Real h) {
  const std::vector<TriangleRest>& triangles = setup.scene->model().triangles();
  const StretchShearCoefficients coefficients{material.warpStretchStiffness,
                                              material.weftStretchStiffness,
                                              material.shearStiffness, material.stretchDamping,
                                              material.shearDamping};
  Real energy = 0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& corner = triangles[t].vertices;
    const std::array<Vec3, 3> x{setup.x[corner[0]], setup.x[corner[1]], setup.x[corner[2]]};
    const std::array<Vec3, 3> v{setup.v[corner[0]], setup.v[corner[1]], setup.v[corner[2]]};
    const StretchShearTerms terms =
        stretchShear(x, v, v, setup.membranes[t], coefficients, h, true);
    energy += terms.energy;
    for (int a = 0; a < 3; ++a) {
      setup.f[corner[a]] += terms.force[a];
      setup.product[corner[a]] += terms.stiffnessTimesVelocity[a];
      for (int b = 0; b < 3; ++b) {
        addStretchShearBlock(terms, setup.membranes[t], a, b,
                             setup.matrix.block(setup.slots[t][3 * a + b]));
      }
    }
  }
  return energy;
}

// Arguments {size, kernel: 0 separate conditions, 1 fused}.
void MembraneKernel(benchmark::State& state) {
  MembraneSetup& setup = membraneSetup(Index(state.range(0)));
  const ClothMaterial material;
  const Real h = CurtainScene::kFrameDt;
  for (auto _ : state) {
    benchmark::DoNotOptimize(state.range(1) == 0 ? separateKernels(setup, material, h)
                                                 : fusedKernel(setup, material, h));
    benchmark::DoNotOptimize(setup.matrix.block(0).data());
  }
  const double triangles = double(setup.scene->model().triangleCount());
  state.counters["triangles"] = triangles;
  state.counters["per_triangle"] = benchmark::Counter(
      triangles * double(state.iterations()),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

BENCHMARK(MembraneKernel)
    ->ArgsProduct({{1, 16}, {0, 1}})
    ->ArgNames({"size", "fused"})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace weft
