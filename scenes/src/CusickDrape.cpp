#include <weft/scenes/CusickDrape.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

namespace weft {
namespace {

constexpr Real kPi = std::numbers::pi_v<Real>;
constexpr Real kShadowCell = 0.0005;  // m, the raster the shadow is measured on

struct Ring {
  std::vector<Index> vertices;  // sorted by angle, angles in [0, 2π)
  std::vector<Real> angles;
};

// Triangles between two rings, each advancing the ring whose next vertex comes first in angle
// (both start at their smallest angle and close where they began).
void zipRings(const Ring& inner, const Ring& outer, std::vector<Index>& indices) {
  const std::size_t m = inner.vertices.size(), n = outer.vertices.size();
  const auto unwrapped = [](const Ring& ring, std::size_t k) {
    const std::size_t count = ring.vertices.size();
    return ring.angles[k % count] + 2 * kPi * Real(k / count);
  };
  std::size_t i = 0, j = 0;
  while (i < m || j < n) {
    const bool advanceInner = j == n || (i < m && unwrapped(inner, i + 1) < unwrapped(outer, j + 1));
    const Index a = inner.vertices[i % m], b = outer.vertices[j % n];
    if (advanceInner) {
      indices.insert(indices.end(), {a, b, inner.vertices[(i + 1) % m]});
      ++i;
    } else {
      indices.insert(indices.end(), {a, b, outer.vertices[(j + 1) % n]});
      ++j;
    }
  }
}

}  // namespace

Result<TriangleMesh> cusickDiscMesh(const CusickDrapeSettings& settings) {
  const Real radius = settings.specimenRadius, support = settings.supportRadius;
  const Real spacing = settings.spacing;
  if (!(support > 0) || !(radius > support) || !std::isfinite(radius)) {
    return Error{"Cusick drape: supportRadius must be positive and below specimenRadius (m)"};
  }
  if (!(spacing > 0) || spacing > 0.25 * support) {
    return Error{"Cusick drape: spacing must be positive and at most a quarter of supportRadius"};
  }
  std::mt19937 random(settings.seed);
  std::uniform_real_distribution<Real> unit(0, 1);
  // Ring radii: the clamp and the hem exactly, evenly between (rows of equilateral triangles).
  const Real rowHeight = spacing * std::sqrt(3.0) / 2;
  std::vector<Real> radii;
  const int innerRows = std::max(2, int(std::lround(support / rowHeight)));
  for (int k = 1; k <= innerRows; ++k) radii.push_back(support * k / innerRows);
  const int outerRows = std::max(2, int(std::lround((radius - support) / rowHeight)));
  for (int k = 1; k <= outerRows; ++k) radii.push_back(support + (radius - support) * k / outerRows);

  TriangleMesh mesh;
  mesh.positions.push_back(Vec3::Zero());  // the centre
  std::vector<Ring> rings;
  for (std::size_t r = 0; r < radii.size(); ++r) {
    const Real ringRadius = radii[r];
    const bool exact = std::abs(ringRadius - support) < 1e-12 || r + 1 == radii.size();
    const int count = std::max(6, int(std::lround(2 * kPi * ringRadius / spacing)));
    const Real step = 2 * kPi / count, turn = step * unit(random);
    const Real radialJitter = exact ? 0 : 0.2 * (ringRadius - (r ? radii[r - 1] : 0));
    Ring ring;
    std::vector<std::pair<Real, Vec3>> points;
    for (int k = 0; k < count; ++k) {
      Real angle = turn + step * (k + 0.3 * (unit(random) - 0.5));
      angle = std::fmod(angle + 2 * kPi, 2 * kPi);
      const Real rho = ringRadius + radialJitter * (unit(random) - 0.5);
      points.push_back({angle, Vec3(rho * std::cos(angle), 0, rho * std::sin(angle))});
    }
    std::sort(points.begin(), points.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [angle, position] : points) {
      ring.vertices.push_back(Index(mesh.positions.size()));
      ring.angles.push_back(angle);
      mesh.positions.push_back(position);
    }
    rings.push_back(std::move(ring));
  }
  // The centre fan, then ring to ring.
  const Ring& first = rings.front();
  for (std::size_t k = 0; k < first.vertices.size(); ++k) {
    mesh.indices.insert(mesh.indices.end(),
                        {0, first.vertices[k], first.vertices[(k + 1) % first.vertices.size()]});
  }
  for (std::size_t r = 0; r + 1 < rings.size(); ++r) zipRings(rings[r], rings[r + 1], mesh.indices);
  // One winding for all: normals up (+y).
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const Vec3& a = mesh.positions[mesh.indices[t]];
    const Vec3 normal = (mesh.positions[mesh.indices[t + 1]] - a).cross(mesh.positions[mesh.indices[t + 2]] - a);
    if (normal.y() < 0) std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
  }
  for (const Vec3& p : mesh.positions) mesh.materialCoordinates.push_back(Vec2(p.x(), p.z()));
  return mesh;
}

Result<CusickDrapeScene> CusickDrapeScene::create(const CusickDrapeSettings& settings) {
  Result<TriangleMesh> mesh = cusickDiscMesh(settings);
  if (!mesh.ok()) return mesh.error();
  Result<ClothModel> model = ClothModel::fromMesh(mesh.value());
  if (!model.ok()) return model.error();
  CusickDrapeScene scene;
  scene.m_model = std::make_shared<const ClothModel>(std::move(model).value());
  scene.m_specimenRadius = settings.specimenRadius;
  scene.m_supportRadius = settings.supportRadius;
  WorldSettings worldSettings;
  worldSettings.threadCount = settings.threadCount;
  scene.m_world = std::make_unique<World>(worldSettings);
  ClothSettings cloth;
  cloth.material = settings.material;
  cloth.solver = settings.solver;
  cloth.sleep.enabled = false;
  const Vec3Array& rest = scene.m_model->restPositions();
  for (Index i = 0; i < Index(rest.size()); ++i) {
    const Real r = Vec2(rest[i].x(), rest[i].z()).norm();
    if (r <= settings.supportRadius * (1 + 1e-9)) cloth.pinnedVertices.push_back(i);
    if (r >= settings.specimenRadius * (1 - 1e-9)) scene.m_hem.push_back(i);
  }
  Result<ClothId> id = scene.m_world->createCloth(scene.m_model, cloth);
  if (!id.ok()) return id.error();
  scene.m_cloth = id.value();
  return scene;
}

Real CusickDrapeScene::drapeCoefficient() const {
  const std::span<const Vec3> x = m_world->positions(m_cloth).value();
  const int cells = int(std::ceil(2 * m_specimenRadius / kShadowCell)) + 2;
  const Real origin = -0.5 * cells * kShadowCell;
  std::vector<std::uint8_t> covered(std::size_t(cells) * std::size_t(cells), 0);
  const std::vector<Index>& indices = m_model->indices();
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    Vec2 p[3];
    for (int k = 0; k < 3; ++k) {
      const Vec3& q = x[indices[t + std::size_t(k)]];
      p[k] = Vec2((q.x() - origin) / kShadowCell, (q.z() - origin) / kShadowCell);
    }
    const Real area = (p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x();
    if (area == 0) continue;
    const int i0 = std::max(0, int(std::floor(std::min({p[0].x(), p[1].x(), p[2].x()}))));
    const int i1 = std::min(cells - 1, int(std::ceil(std::max({p[0].x(), p[1].x(), p[2].x()}))));
    const int j0 = std::max(0, int(std::floor(std::min({p[0].y(), p[1].y(), p[2].y()}))));
    const int j1 = std::min(cells - 1, int(std::ceil(std::max({p[0].y(), p[1].y(), p[2].y()}))));
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const Vec2 c(i + 0.5, j + 0.5);
        bool inside = true;
        for (int k = 0; k < 3 && inside; ++k) {
          const Vec2 u = p[k], v = p[(k + 1) % 3];
          const Real edge = (v - u).x() * (c - u).y() - (v - u).y() * (c - u).x();
          inside = area > 0 ? edge >= 0 : edge <= 0;
        }
        if (inside) covered[std::size_t(j) * std::size_t(cells) + std::size_t(i)] = 1;
      }
    }
  }
  const Real shadow =
      Real(std::count(covered.begin(), covered.end(), 1)) * kShadowCell * kShadowCell;
  const Real supportArea = kPi * m_supportRadius * m_supportRadius;
  const Real specimenArea = kPi * m_specimenRadius * m_specimenRadius;
  return (shadow - supportArea) / (specimenArea - supportArea);
}

Real CusickDrapeScene::hemSpeed() const {
  const std::span<const Vec3> v = m_world->velocities(m_cloth).value();
  Real fastest = 0;
  for (Index i : m_hem) fastest = std::max(fastest, v[i].norm());
  return fastest;
}

}  // namespace weft
