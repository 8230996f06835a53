// Checks shared by the contact scenes (ClothClothTest, CollisionScenesTest, ...): intersecting
// triangle pairs within and between cloths (the exact triangle–triangle test), the deepest
// vertex inside a collider, and the health monitor's rollbacks and retries.
#pragma once

#include <weft/collision/Proximity.h>
#include <weft/collision/SelfIntersectionCounter.h>
#include <weft/engine/World.h>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace weft::test {

/// A horizontal square of vertices × vertices at height `height`, centred on the y axis; its
/// front faces +y.
inline std::shared_ptr<const ClothModel> horizontalSquare(Index vertices, Real size, Real height) {
  GridSettings grid;
  grid.columns = vertices;
  grid.rows = vertices;
  grid.width = size;
  grid.height = size;
  grid.origin = Vec3(-size / 2, height, size / 2);
  grid.widthAxis = Vec3(1, 0, 0);
  grid.heightAxis = Vec3(0, 0, -1);
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

/// An upright square of vertices × vertices in the plane z = 0, `size` m on a side, centred on
/// the y axis with its bottom row (vertices 0 … vertices − 1) at height `bottom`.
inline std::shared_ptr<const ClothModel> uprightSquare(Index vertices, Real size, Real bottom) {
  GridSettings grid;
  grid.columns = grid.rows = vertices;
  grid.width = grid.height = size;
  grid.origin = Vec3(-size / 2, bottom, 0);
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

/// Appends a horizontal square grid of vertices × vertices centred on `centre` (front face +y)
/// to `mesh`, for models made of several disconnected layers (ClothModel::fromMesh); returns the
/// index of its first vertex.
inline Index appendHorizontalSquare(TriangleMesh& mesh, Index vertices, Real size, const Vec3& centre) {
  GridSettings grid;
  grid.columns = grid.rows = vertices;
  grid.width = grid.height = size;
  grid.origin = centre + Vec3(-size / 2, 0, size / 2);
  grid.widthAxis = Vec3(1, 0, 0);
  grid.heightAxis = Vec3(0, 0, -1);
  const ClothModel layer = ClothModel::grid(grid).value();
  const Index first = Index(mesh.positions.size());
  mesh.positions.insert(mesh.positions.end(), layer.restPositions().begin(), layer.restPositions().end());
  for (Index index : layer.indices()) mesh.indices.push_back(first + index);
  return first;
}

/// Counts intersecting triangle pairs of several cloths of one world taken as one mesh: pairs
/// within each cloth and between any two (pairs sharing a vertex of one cloth are not counted,
/// as in SelfIntersectionCounter).
class IntersectionCounter {
 public:
  IntersectionCounter(const World& world, std::vector<ClothId> cloths) : m_cloths(std::move(cloths)) {
    std::vector<Index> indices;
    Vec3Array positions;
    for (ClothId cloth : m_cloths) {
      const ClothRenderView view = world.renderView(cloth).value();
      const Index offset = Index(positions.size());
      for (Index index : view.indices) indices.push_back(index + offset);
      positions.insert(positions.end(), view.positions.begin(), view.positions.end());
    }
    m_counter = std::make_unique<SelfIntersectionCounter>(
        SelfIntersectionCounter::create(indices, positions).value());
  }

  /// Intersecting pairs at the world's current positions.
  Index count(const World& world) {
    m_positions.clear();
    for (ClothId cloth : m_cloths) {
      const std::span<const Vec3> x = world.positions(cloth).value();
      m_positions.insert(m_positions.end(), x.begin(), x.end());
    }
    return m_counter->count(m_positions);
  }

 private:
  std::vector<ClothId> m_cloths;
  std::unique_ptr<SelfIntersectionCounter> m_counter;
  Vec3Array m_positions;
};

/// The health monitor's interventions over a run, from World::step()'s flags. A rolled-back
/// frame (StepStatus::RolledBack) ends where it started, so a scene the monitor kept freezing
/// would pass every other check: contact scenes assert none. A frame retried with a smaller step
/// (StepStatus::RetriedWithSmallerStep) is allowed only up to a bound the scene declares, with
/// its reason.
class StepHealth {
 public:
  /// Records one frame's flags and returns them.
  StepStatus operator()(StepStatus status) {
    const int frame = m_frames++;  // counted from 0, as the scenes' loops do
    if (hasFlag(status, StepStatus::RolledBack) && m_rolledBack++ == 0) m_firstRolledBack = frame;
    if (hasFlag(status, StepStatus::RetriedWithSmallerStep) && m_retried++ == 0) m_firstRetried = frame;
    return status;
  }
  int rolledBack() const { return m_rolledBack; }
  int retried() const { return m_retried; }

  /// No frame rolled back; at most `allowedRetries` retried, for the reason `why`.
  void expectHealthy(const std::string& scene, int allowedRetries = 0, const char* why = nullptr) const {
    EXPECT_EQ(m_rolledBack, 0) << scene << ": " << m_rolledBack << " of " << m_frames
                               << " frames rolled back (the first: frame " << m_firstRolledBack << ")";
    EXPECT_LE(m_retried, allowedRetries)
        << scene << ": " << m_retried << " of " << m_frames << " frames retried with a smaller "
        << "step (the first: frame " << m_firstRetried << ")" << (why ? std::string("; ") + why : "");
  }

 private:
  int m_frames = 0, m_rolledBack = 0, m_retried = 0, m_firstRolledBack = -1, m_firstRetried = -1;
};

/// Smallest signed distance (m) of any vertex of `cloth` to the collider: negative = inside.
inline Real closestApproach(const World& world, ClothId cloth, ColliderId collider) {
  const Shape* shape = world.collider(collider).value();
  Real closest = std::numeric_limits<Real>::infinity();
  for (const Vec3& x : world.positions(cloth).value()) {
    closest = std::min(closest, queryPoint(*shape, x).distance);
  }
  return closest;
}

/// Smallest distance (m) from a vertex of cloth `a` to a triangle of cloth `b` (brute force).
inline Real closestDistanceBetween(const World& world, ClothId a, ClothId b) {
  const ClothRenderView second = world.renderView(b).value();
  Real closest = std::numeric_limits<Real>::infinity();
  for (const Vec3& x : world.positions(a).value()) {
    for (std::size_t t = 0; t + 2 < second.indices.size(); t += 3) {
      const Vec3& p0 = second.positions[second.indices[t]];
      const Vec3& p1 = second.positions[second.indices[t + 1]];
      const Vec3& p2 = second.positions[second.indices[t + 2]];
      closest = std::min(closest, closestPointOnTriangle(x, p0, p1, p2).distance);
    }
  }
  return closest;
}

/// The corner drop of the contact scenes: a square model (horizontalSquare) turned upright (a
/// quarter turn about x), then a diamond (45° about z), its lowest vertex `lift` above the floor
/// (y = 0), so that it lands on one corner, buckles, and the rest falls onto it.
inline ClothSettings cornerDrop(const ClothModel& model, Real lift) {
  ClothSettings settings;
  const Mat3 upright = Eigen::AngleAxis<Real>(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
  const Mat3 onCorner = Eigen::AngleAxis<Real>(M_PI / 4, Vec3::UnitZ()).toRotationMatrix();
  settings.rotation = onCorner * upright;
  Real lowest = 1e9;
  for (const Vec3& p : model.restPositions()) lowest = std::min(lowest, Vec3(settings.rotation * p).y());
  settings.translation = Vec3(0, lift - lowest, 0);
  return settings;
}

/// Mean height of the vertices (m): how far a pile has come down. A sheet standing on an edge
/// holds it at half its side, one lying flat at its thickness.
inline Real meanVertexHeight(std::span<const Vec3> positions) {
  Real sum = 0;
  for (const Vec3& p : positions) sum += p.y();
  return sum / Real(positions.size());
}

/// The napkin fold's pin targets: the row pinned at z = +size/2 (start) carried by the fraction
/// `s` ∈ [0, 1] of a half turn about the x axis through the middle, ending 2 cm above the floor.
inline std::vector<Vec3> napkinFoldTargets(const std::vector<Vec3>& start, Real s, Real size) {
  const Real angle = M_PI * s;
  std::vector<Vec3> targets = start;
  for (Vec3& target : targets) {
    target.z() = 0.5 * size * std::cos(angle);
    target.y() = 0.01 + 0.01 * s + 0.5 * size * std::sin(angle);
  }
  return targets;
}

}  // namespace weft::test
