#include <weft/scenes/Cantilever.h>

#include <array>
#include <cmath>
#include <string>

namespace weft {

Result<CantileverScene> CantileverScene::create(const CantileverSettings& settings) {
  if (!(settings.overhang > 0) || !(settings.width > 0) || settings.overhangSegments < 2) {
    return Error{"cantilever: overhang and width must be positive (m), with at least 2 segments "
                 "along the overhang"};
  }
  // Columns run along the strip (x), rows across it (z); the two columns behind the edge (x ≤ 0)
  // lie on the platform and are pinned.
  const Real spacing = settings.overhang / Real(settings.overhangSegments);
  GridSettings grid;
  grid.columns = settings.overhangSegments + 3;
  // Square cells: as many segments across as the spacing along gives (at least 2).
  grid.rows = std::max<Index>(2, Index(std::lround(settings.width / spacing))) + 1;
  grid.width = spacing * Real(grid.columns - 1);
  grid.height = settings.width;
  grid.origin = Vec3(-2 * spacing, 0, -0.5 * settings.width);
  grid.widthAxis = Vec3(1, 0, 0);
  grid.heightAxis = Vec3(0, 0, 1);
  Result<ClothModel> model = ClothModel::grid(grid);
  if (!model.ok()) return model.error();
  auto shared = std::make_shared<const ClothModel>(std::move(model).value());

  CantileverScene scene;
  WorldSettings worldSettings;
  worldSettings.threadCount = 1;
  scene.m_world = std::make_unique<World>(worldSettings);
  ClothSettings cloth;
  cloth.material = settings.material;
  cloth.solver = settings.solver;
  cloth.selfCollision = false;
  cloth.sleep.enabled = false;
  for (Index row = 0; row < grid.rows; ++row) {
    for (Index column = 0; column < 3; ++column) cloth.pinnedVertices.push_back(row * grid.columns + column);
    scene.m_tip.push_back(row * grid.columns + grid.columns - 1);
  }
  scene.m_edgeVertex = 2;  // row 0, x = 0
  Result<ClothId> id = scene.m_world->createCloth(shared, cloth);
  if (!id.ok()) return id.error();
  scene.m_cloth = id.value();
  return scene;
}

Real CantileverScene::chordAngle() const {
  const std::span<const Vec3> x = m_world->positions(m_cloth).value();
  Vec3 tip = Vec3::Zero();
  for (Index i : m_tip) tip += x[i];
  tip /= Real(m_tip.size());
  const Vec3 chord = tip - x[m_edgeVertex];
  return std::atan2(-chord.y(), chord.x());
}

Real CantileverScene::largestSpeed() const {
  Real fastest = 0;
  for (const Vec3& v : m_world->velocities(m_cloth).value()) fastest = std::max(fastest, v.norm());
  return fastest;
}

namespace {

// The heavy elastica θ'' = −λ (1 − s) cos θ on s ∈ [0, 1], θ(0) = 0, from θ'(0) = κ: returns θ'(1)
// and the tip's chord angle (RK4, 2000 steps).
std::pair<Real, Real> shoot(Real load, Real rootCurvature) {
  constexpr int kSteps = 2000;
  const Real ds = 1.0 / kSteps;
  Real theta = 0, curvature = rootCurvature, x = 0, y = 0;
  const auto rhs = [&](Real s, Real t, Real k) {
    return std::array<Real, 4>{k, -load * (1 - s) * std::cos(t), std::cos(t), std::sin(t)};
  };
  for (int step = 0; step < kSteps; ++step) {
    const Real s = step * ds;
    const auto k1 = rhs(s, theta, curvature);
    const auto k2 = rhs(s + ds / 2, theta + ds / 2 * k1[0], curvature + ds / 2 * k1[1]);
    const auto k3 = rhs(s + ds / 2, theta + ds / 2 * k2[0], curvature + ds / 2 * k2[1]);
    const auto k4 = rhs(s + ds, theta + ds * k3[0], curvature + ds * k3[1]);
    theta += ds / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]);
    curvature += ds / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]);
    x += ds / 6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2]);
    y += ds / 6 * (k1[3] + 2 * k2[3] + 2 * k3[3] + k4[3]);
  }
  return {curvature, std::atan2(y, x)};
}

// The chord angle of the heavy elastica at load λ: the root curvature found by bisection so that
// the tip carries no moment (θ'(1) = 0; θ'(1) grows with θ'(0)).
Real elasticaChordAngle(Real load) {
  Real low = 0, high = load;  // θ'(0) ≤ λ/2 · ∫ ... ≤ λ
  for (int iteration = 0; iteration < 80; ++iteration) {
    const Real middle = 0.5 * (low + high);
    (shoot(load, middle).first < 0 ? low : high) = middle;
  }
  return shoot(load, 0.5 * (low + high)).second;
}

}  // namespace

Real CantileverScene::elasticaLoad(Real chordAngle) {
  Real low = 1e-6, high = 200;  // the chord angle grows with the load
  for (int iteration = 0; iteration < 60; ++iteration) {
    const Real middle = std::sqrt(low * high);
    (elasticaChordAngle(middle) < chordAngle ? low : high) = middle;
  }
  return std::sqrt(low * high);
}

Real CantileverScene::bendingLength(const CantileverSettings& settings, Real seconds) {
  const auto settledAngle = [&](Real overhang) {
    CantileverSettings at = settings;
    at.overhang = overhang;
    CantileverScene scene = CantileverScene::create(at).value();
    // Until still (0.1 mm/s: light fabric sinks slowly against the air), at most `seconds`.
    const int frames = int(std::lround(seconds / kFrameDt));
    for (int frame = 0; frame < frames; ++frame) {
      scene.stepFrame();
      if (frame > 30 && scene.largestSpeed() < 1e-4) break;
    }
    return scene.chordAngle();
  };
  // Bracket 41.5° by doubling from 1 cm, then secant steps on the bracket (regula falsi).
  Real low = 0.01, high = 0.01;
  Real lowAngle = settledAngle(low), highAngle = lowAngle;
  if (lowAngle > kTestAngle) return std::nan("");
  while (highAngle < kTestAngle) {
    low = high;
    lowAngle = highAngle;
    high *= 2;
    if (high > 0.4) return std::nan("");
    highAngle = settledAngle(high);
  }
  for (int iteration = 0; iteration < 4; ++iteration) {
    const Real guess = low + (high - low) * (kTestAngle - lowAngle) / (highAngle - lowAngle);
    const Real angle = settledAngle(guess);
    if (angle < kTestAngle) {
      low = guess;
      lowAngle = angle;
    } else {
      high = guess;
      highAngle = angle;
    }
  }
  const Real overhang = low + (high - low) * (kTestAngle - lowAngle) / (highAngle - lowAngle);
  return 0.5 * overhang;
}

}  // namespace weft
