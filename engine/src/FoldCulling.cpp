#include "FoldCulling.h"

#include <weft/collision/Aabb.h>
#include <weft/threading/Profiler.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace weft {
namespace {

Index findRoot(std::vector<Index>& parent, Index i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// Distance from p to the segment [a, b] (2D points stored in Vec3 with z = 0).
Real pointSegmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const Real length2 = ab.squaredNorm();
  Real s = length2 > 0 ? (p - a).dot(ab) / length2 : 0;
  s = std::clamp<Real>(s, 0, 1);
  return (p - (a + s * ab)).norm();
}

// Sign of the 2D cross product (b − a) × (c − a).
Real orient(const Vec3& a, const Vec3& b, const Vec3& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

// Distance between two 2D segments that share no endpoint: 0 when they cross, else the smallest
// endpoint-to-segment distance (where disjoint segments come closest).
Real segmentDistance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Real a = orient(p0, p1, q0), b = orient(p0, p1, q1);
  const Real c = orient(q0, q1, p0), d = orient(q0, q1, p1);
  if (((a < 0 && b > 0) || (a > 0 && b < 0)) && ((c < 0 && d > 0) || (c > 0 && d < 0))) return 0;
  return std::min({pointSegmentDistance(p0, q0, q1), pointSegmentDistance(p1, q0, q1),
                   pointSegmentDistance(q0, p0, p1), pointSegmentDistance(q1, p0, p1)});
}

}  // namespace

FoldCulling::FoldCulling(const ClothModel& model) : m_model(&model) {
  const Index n = model.vertexCount();
  std::vector<Index> piece(n), loop(n);
  std::iota(piece.begin(), piece.end(), Index(0));
  std::iota(loop.begin(), loop.end(), Index(0));
  const std::vector<Index>& indices = model.indices();
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    for (int k = 1; k < 3; ++k) piece[findRoot(piece, indices[t + k])] = findRoot(piece, indices[t]);
  }
  std::vector<char> onBoundary(n, 0);
  for (const Edge& edge : model.edges()) {
    if (edge.triangles[1] != kInvalidIndex) continue;
    m_boundaryEdges.push_back(edge.vertices);
    loop[findRoot(loop, edge.vertices[1])] = findRoot(loop, edge.vertices[0]);
    onBoundary[edge.vertices[0]] = onBoundary[edge.vertices[1]] = 1;
  }
  Index pieces = 0, loops = 0, used = 0;
  std::vector<char> inMesh(n, 0);
  for (Index v : indices) inMesh[v] = 1;
  for (Index v = 0; v < n; ++v) {
    used += inMesh[v];
    pieces += inMesh[v] && findRoot(piece, v) == v;
    loops += onBoundary[v] && findRoot(loop, v) == v;
  }
  // A disk: one piece, one boundary loop, V − E + F = 1 (no handles, no holes).
  const long long euler = (long long)used - (long long)model.edges().size() +
                          (long long)model.triangleCount();
  m_applicable = used == n && pieces == 1 && loops == 1 && euler == 1;
  m_intervals.reserve(m_boundaryEdges.size());
}

bool FoldCulling::cannotTouchItself(std::span<const Vec3> start, std::span<const Vec3> end,
                                    Real thickness) {
  if (!m_applicable) return false;
  WEFT_PROFILE_ZONE("fold culling");
  const std::vector<Index>& indices = m_model->indices();
  // Largest displacement over the step first: it is the cheapest way to fail. Measured from a
  // common shift c (the middle of the displacements' box): moving every vertex by t·c moves no
  // feature relative to another, so the argument holds for the displacements less c.
  Aabb moves = Aabb::empty();
  for (std::size_t i = 0; i < start.size(); ++i) moves.expand(Vec3(end[i] - start[i]));
  const Vec3 common = 0.5 * (moves.min + moves.max);
  Real displacement2 = 0;
  for (std::size_t i = 0; i < start.size(); ++i) {
    displacement2 = std::max(displacement2, (end[i] - start[i] - common).squaredNorm());
  }
  const Real displacement = std::sqrt(displacement2);
  const Real needed = thickness + 2 * displacement;  // δ must exceed this

  Vec3 axis = Vec3::Zero();
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const Vec3& x0 = start[indices[t]];
    axis += (start[indices[t + 1]] - x0).cross(start[indices[t + 2]] - x0);
  }
  const Real axisLength = axis.norm();
  if (!(axisLength > 0)) return false;
  axis /= axisLength;
  // An orthonormal frame (u, w) of the projection plane.
  const Vec3 helper = std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 u = axis.cross(helper).normalized();
  const Vec3 w = axis.cross(u);
  auto project = [&](Index i) { return Vec3(start[i].dot(u), start[i].dot(w), 0); };

  // 1–2. Orientation and altitude of every projected triangle.
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const Vec3 p0 = project(indices[t]), p1 = project(indices[t + 1]), p2 = project(indices[t + 2]);
    const Real twiceArea = orient(p0, p1, p2);
    if (!(twiceArea > 0)) return false;  // flipped or edge-on: a fold may start here
    const Real longest = std::sqrt(std::max({(p1 - p0).squaredNorm(), (p2 - p1).squaredNorm(),
                                             (p0 - p2).squaredNorm()}));
    if (!(twiceArea > needed * longest)) return false;  // altitude = 2·area / longest edge
  }

  // 2. Boundary features that share no vertex, by a sweep along u over intervals widened by
  // the needed separation: only overlapping intervals can hold pairs closer than that.
  m_intervals.clear();
  for (Index e = 0; e < m_boundaryEdges.size(); ++e) {
    const Real a = start[m_boundaryEdges[e][0]].dot(u), b = start[m_boundaryEdges[e][1]].dot(u);
    m_intervals.push_back({std::min(a, b) - needed, std::max(a, b) + needed, e});
  }
  std::sort(m_intervals.begin(), m_intervals.end(),
            [](const Interval& a, const Interval& b) { return a.low < b.low || (a.low == b.low && a.edge < b.edge); });
  for (std::size_t i = 0; i < m_intervals.size(); ++i) {
    const std::array<Index, 2>& first = m_boundaryEdges[m_intervals[i].edge];
    const Vec3 p0 = project(first[0]), p1 = project(first[1]);
    for (std::size_t j = i + 1; j < m_intervals.size() && m_intervals[j].low <= m_intervals[i].high; ++j) {
      const std::array<Index, 2>& second = m_boundaryEdges[m_intervals[j].edge];
      const Vec3 q0 = project(second[0]), q1 = project(second[1]);
      Real distance;
      if (first[0] == second[0]) {
        distance = std::min(pointSegmentDistance(p1, q0, q1), pointSegmentDistance(q1, p0, p1));
      } else if (first[0] == second[1]) {
        distance = std::min(pointSegmentDistance(p1, q0, q1), pointSegmentDistance(q0, p0, p1));
      } else if (first[1] == second[0]) {
        distance = std::min(pointSegmentDistance(p0, q0, q1), pointSegmentDistance(q1, p0, p1));
      } else if (first[1] == second[1]) {
        distance = std::min(pointSegmentDistance(p0, q0, q1), pointSegmentDistance(q0, p0, p1));
      } else {
        distance = segmentDistance(p0, p1, q0, q1);
      }
      if (!(distance > needed)) return false;
    }
  }
  return true;
}

}  // namespace weft
