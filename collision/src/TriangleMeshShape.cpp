// Triangle-mesh collider: validation, pseudo-normals, closest-point search. See
// TriangleMeshShape.h for the design note.
#include <weft/collision/TriangleMeshShape.h>

#include <weft/collision/Proximity.h>

#include "ShapeSupport.h"
#include "TriangleRegions.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

namespace weft {
namespace {

// Triangles per leaf of the collider's tree: a point query prunes by box, and small boxes prune
// most (the cloth's self query wants large leaves instead, Bvh::kMaxLeafTriangles).
constexpr Index kLeafTriangles = 4;

std::string describeTriangle(Index t, Index a, Index b, Index c) {
  std::ostringstream text;
  text << "TriangleMeshShape: triangle " << t << " (vertices " << a << ", " << b << ", " << c
       << ")";
  return text.str();
}

// |p − closest point of triangle (a, b, c)|²: closestPointOnTriangle's region walk without the
// square root and the result record, for the many triangles a search rejects. The winner is
// measured again with closestPointOnTriangle for its exact features.
Real squaredDistanceToTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  return detail::closestTriangleRegion(p, a, b, c, [&](Real wa, Real wb, Real wc) {
    return (p - (wa * a + wb * b + wc * c)).squaredNorm();
  });
}

// True when segment a → a + travel meets box (slab test; a zero component of travel is a slab
// the segment is either in or out of).
bool segmentMeetsBox(const Vec3& a, const Vec3& travel, const Aabb& box) {
  Real enter = 0, leave = 1;
  for (int axis = 0; axis < 3; ++axis) {
    if (travel[axis] == 0) {
      if (a[axis] < box.min[axis] || a[axis] > box.max[axis]) return false;
      continue;
    }
    const Real inverse = 1 / travel[axis];
    Real near = (box.min[axis] - a[axis]) * inverse;
    Real far = (box.max[axis] - a[axis]) * inverse;
    if (near > far) std::swap(near, far);
    enter = std::max(enter, near);
    leave = std::min(leave, far);
    if (enter > leave) return false;
  }
  return true;
}

Real cornerAngle(const Vec3& corner, const Vec3& next, const Vec3& previous) {
  const Vec3 e1 = next - corner;
  const Vec3 e2 = previous - corner;
  return std::atan2(e1.cross(e2).norm(), e1.dot(e2));
}

}  // namespace

Result<TriangleMeshShape> TriangleMeshShape::create(std::span<const Vec3> localVertices,
                                                    std::span<const Index> indices,
                                                    const RigidMotion& motion) {
  if (indices.empty()) {
    return Error{"TriangleMeshShape: no triangles; pass three vertex indices per triangle"};
  }
  if (indices.size() % 3 != 0) {
    std::ostringstream text;
    text << "TriangleMeshShape: " << indices.size()
         << " indices is not a multiple of three; pass three vertex indices per triangle";
    return Error{text.str()};
  }
  for (std::size_t v = 0; v < localVertices.size(); ++v) {
    if (!isFinite(localVertices[v])) {
      std::ostringstream text;
      text << "TriangleMeshShape: vertex " << v << " " << detail::formatVec(localVertices[v])
           << " is not finite; pass finite positions in metres";
      return Error{text.str()};
    }
  }
  const Index triangleCount = static_cast<Index>(indices.size() / 3);
  for (Index t = 0; t < triangleCount; ++t) {
    const Index a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
    for (Index i : {a, b, c}) {
      if (i >= localVertices.size()) {
        std::ostringstream text;
        text << describeTriangle(t, a, b, c) << ": index " << i << " is out of range (there are "
             << localVertices.size() << " vertices)";
        return Error{text.str()};
      }
    }
    if (a == b || b == c || c == a) {
      return Error{describeTriangle(t, a, b, c) +
                   ": repeated vertex index; every triangle needs three distinct vertices"};
    }
    const Vec3& x0 = localVertices[a];
    const Vec3& x1 = localVertices[b];
    const Vec3& x2 = localVertices[c];
    const Real longest =
        std::max({(x1 - x0).squaredNorm(), (x2 - x1).squaredNorm(), (x0 - x2).squaredNorm()});
    // Area² below 1e-12 of the longest edge⁴: a sliver without a usable normal.
    if (!((x1 - x0).cross(x2 - x0).squaredNorm() > 1e-12 * longest * longest)) {
      return Error{describeTriangle(t, a, b, c) +
                   ": zero area (collinear or coincident vertices); remove or fix it"};
    }
  }

  TriangleMeshShape shape;
  if (Status status = shape.setMotion(motion); !status) return status.error();
  auto geometry = std::make_shared<Geometry>();
  geometry->vertices.assign(localVertices.begin(), localVertices.end());
  geometry->indices.assign(indices.begin(), indices.end());
  Result<Bvh> tree = Bvh::build(geometry->indices, geometry->vertices, kLeafTriangles);
  if (!tree) return tree.error();
  geometry->bvh = std::move(tree).value();

  // Face normals, angle-weighted vertex normals.
  const auto& x = geometry->vertices;
  geometry->faceNormals.resize(triangleCount);
  geometry->corners.resize(3 * std::size_t(triangleCount));
  geometry->vertexNormals.assign(x.size(), Vec3::Zero());
  for (Index t = 0; t < triangleCount; ++t) {
    const Index corner[3] = {indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]};
    const Vec3 normal = (x[corner[1]] - x[corner[0]]).cross(x[corner[2]] - x[corner[0]]).normalized();
    geometry->faceNormals[t] = normal;
    for (int k = 0; k < 3; ++k) geometry->corners[3 * t + k] = x[corner[k]];
    for (int k = 0; k < 3; ++k) {
      const Real angle = cornerAngle(x[corner[k]], x[corner[(k + 1) % 3]], x[corner[(k + 2) % 3]]);
      geometry->vertexNormals[corner[k]] += angle * normal;
    }
  }
  for (Vec3& n : geometry->vertexNormals) {
    if (n.squaredNorm() > 0) n.normalize();
  }

  // Edge normals: the sum of the face normals of every triangle on the undirected edge. Sorting
  // (edge key, slot) groups the triangles of one edge.
  std::vector<std::pair<std::uint64_t, Index>> edgeSlots(3 * std::size_t(triangleCount));
  for (Index t = 0; t < triangleCount; ++t) {
    for (Index k = 0; k < 3; ++k) {
      Index a = indices[3 * t + k], b = indices[3 * t + (k + 1) % 3];
      if (a > b) std::swap(a, b);
      edgeSlots[3 * t + k] = {(std::uint64_t(a) << 32) | b, 3 * t + k};
    }
  }
  std::sort(edgeSlots.begin(), edgeSlots.end());
  geometry->edgeNormals.assign(edgeSlots.size(), Vec3::Zero());
  geometry->triangleEdges.assign(edgeSlots.size(), 0);
  geometry->closed = true;
  // Per edge: its signed turn (positive convex, infinite on a border or fin) and width.
  std::vector<std::pair<Real, Real>> turnAndWidth;
  for (std::size_t begin = 0; begin < edgeSlots.size();) {
    std::size_t end = begin;
    Vec3 sum = Vec3::Zero();
    while (end < edgeSlots.size() && edgeSlots[end].first == edgeSlots[begin].first) {
      sum += geometry->faceNormals[edgeSlots[end].second / 3];
      ++end;
    }
    // Closed: every edge has exactly two triangles (a border edge has one, a fin three or more).
    if (end - begin != 2) geometry->closed = false;
    if (sum.squaredNorm() > 0) sum.normalize();
    MeshEdge edge;
    edge.a = Index(edgeSlots[begin].first >> 32);
    edge.b = Index(edgeSlots[begin].first & 0xffffffffu);
    for (std::size_t i = begin; i < end; ++i) {
      geometry->edgeNormals[edgeSlots[i].second] = sum;
      geometry->triangleEdges[edgeSlots[i].second] = Index(geometry->edges.size());
    }
    turnAndWidth.push_back(edgeTurnAndWidth(*geometry, edge,
                                            std::span(edgeSlots).subspan(begin, end - begin)));
    geometry->edges.push_back(edge);
    begin = end;
  }
  setEdgeShapes(*geometry, turnAndWidth);
  shape.m_geometry = std::move(geometry);
  return shape;
}

std::pair<Real, Real> TriangleMeshShape::edgeTurnAndWidth(
    const Geometry& geometry, const MeshEdge& edge,
    std::span<const std::pair<std::uint64_t, Index>> slots) {
  const Real infinity = std::numeric_limits<Real>::infinity();
  if (slots.size() != 2) return {infinity, 0};
  const auto& x = geometry.vertices;
  const Real length = (x[edge.b] - x[edge.a]).norm();
  Real width = infinity;
  for (const auto& slot : slots) {
    const Vec3* corner = &geometry.corners[3 * (slot.second / 3)];
    width = std::min(width, (corner[1] - corner[0]).cross(corner[2] - corner[0]).norm() / length);
  }
  const Index first = slots[0].second / 3, second = slots[1].second / 3;
  const Vec3& n1 = geometry.faceNormals[first];
  const Vec3& n2 = geometry.faceNormals[second];
  const Real turn = std::atan2(n1.cross(n2).norm(), n1.dot(n2));
  // The second triangle's far corner below the first's plane: the edge is convex.
  Real farSide = 0;
  for (int k = 0; k < 3; ++k) farSide += n1.dot(geometry.corners[3 * second + k] - x[edge.a]);
  return {farSide < 0 ? turn : -turn, width};
}

void TriangleMeshShape::setEdgeShapes(Geometry& geometry,
                                      std::span<const std::pair<Real, Real>> turnAndWidth) {
  const Real infinity = std::numeric_limits<Real>::infinity();
  for (std::size_t e = 0; e < geometry.edges.size(); ++e) {
    MeshEdge& edge = geometry.edges[e];
    const auto [turn, width] = turnAndWidth[e];
    // A closed mesh's concave edge lies below the faces beside it; an open mesh is a shell whose
    // both sides are outside, so either turn is convex from one of them.
    const Real convexTurn = geometry.closed ? std::max<Real>(turn, 0) : std::abs(turn);
    edge.ridgeSlope = std::isinf(convexTurn) ? infinity : std::tan(convexTurn / 2);
    edge.curvature = std::isinf(convexTurn) ? infinity : edge.ridgeSlope / width;
    geometry.maxRidgeSlope = std::max(geometry.maxRidgeSlope, edge.ridgeSlope);
    geometry.maxCurvature = std::max(geometry.maxCurvature, edge.curvature);
  }
  // A vertex whose faces fold back on it, or whose normals cancel, peaks without bound.
  geometry.vertexSlopes.assign(geometry.vertices.size(), 0);
  for (std::size_t t = 0; t < geometry.faceNormals.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Index v = geometry.indices[3 * t + k];
      const Real cosine = geometry.vertexNormals[v].dot(geometry.faceNormals[t]);
      const Real slope = cosine > 1e-3 ? std::sqrt(std::max<Real>(0, 1 - cosine * cosine)) / cosine
                                       : infinity;
      geometry.vertexSlopes[v] = std::max(geometry.vertexSlopes[v], slope);
      geometry.maxVertexSlope = std::max(geometry.maxVertexSlope, slope);
    }
  }
}

void TriangleMeshShape::worldVertices(std::span<Vec3> vertices) const {
  for (std::size_t v = 0; v < m_geometry->vertices.size() && v < vertices.size(); ++v) {
    vertices[v] = m_motion.pose.toWorld(m_geometry->vertices[v]);
  }
}

Status TriangleMeshShape::setMotion(const RigidMotion& motion) {
  RigidMotion checked = motion;
  if (Status status = validateMotion(checked, "TriangleMeshShape"); !status) return status;
  m_motion = checked;
  return Status::success();
}

Index TriangleMeshShape::closestTriangle(const Vec3& local, Real maxSquared) const {
  const std::vector<Bvh::Node>& nodes = m_geometry->bvh.nodes();
  // Best-first descent with a fixed stack (one pending sibling per level).
  Real bestSquared = maxSquared;
  Index bestTriangle = kInvalidIndex;
  Index stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Bvh::Node& node = nodes[stack[--top]];
    if (node.bounds.squaredDistanceTo(local) >= bestSquared) continue;
    if (node.isLeaf()) {
      for (Index t : m_geometry->bvh.leafTriangles(node)) {
        const Vec3* corner = &m_geometry->corners[3 * t];
        // The distance to the triangle's plane bounds the distance to the triangle from below.
        const Real plane = m_geometry->faceNormals[t].dot(local - corner[0]);
        if (plane * plane >= bestSquared) continue;
        const Real squared = squaredDistanceToTriangle(local, corner[0], corner[1], corner[2]);
        // Strictly closer only: among equal distances the first one found (a fixed order) wins.
        if (squared < bestSquared) {
          bestSquared = squared;
          bestTriangle = t;
        }
      }
    } else {
      const Real left = nodes[node.first].bounds.squaredDistanceTo(local);
      const Real right = nodes[node.first + 1].bounds.squaredDistanceTo(local);
      // The nearer child is pushed last, so it is searched first.
      if (left <= right) {
        stack[top++] = node.first + 1;
        stack[top++] = node.first;
      } else {
        stack[top++] = node.first;
        stack[top++] = node.first + 1;
      }
    }
  }
  return bestTriangle;
}

ShapeContact TriangleMeshShape::queryPoint(const Vec3& point) const {
  const Vec3 local = m_motion.pose.toLocal(point);
  return contactWith(local, closestTriangle(local, std::numeric_limits<Real>::infinity()));
}

std::optional<ShapeContact> TriangleMeshShape::queryPointWithin(const Vec3& point,
                                                                Real maxDistance) const {
  const Vec3 local = m_motion.pose.toLocal(point);
  const Index triangle = closestTriangle(local, maxDistance * maxDistance);
  if (triangle == kInvalidIndex) return std::nullopt;
  const ShapeContact contact = contactWith(local, triangle);
  if (!(std::abs(contact.distance) < maxDistance)) return std::nullopt;
  return contact;
}

std::optional<ShapeContact> TriangleMeshShape::queryPointBelow(const Vec3& point,
                                                               Real maxDistance) const {
  const Vec3 local = m_motion.pose.toLocal(point);
  // The search reaches a little past maxDistance, so that the distance compared is always
  // contactWith()'s, as queryPoint() reports it, not the search's squared one.
  const Real reach = maxDistance * (1 + 1e-9);
  Index triangle = closestTriangle(local, reach * reach);
  // Nothing that near: outside by at least maxDistance, or deep inside a closed mesh (only in
  // its box).
  if (triangle == kInvalidIndex) {
    if (!m_geometry->closed || !m_geometry->bvh.bounds().contains(local)) return std::nullopt;
    triangle = closestTriangle(local, std::numeric_limits<Real>::infinity());
  }
  const ShapeContact contact = contactWith(local, triangle);
  if (!(contact.distance < maxDistance)) return std::nullopt;
  return contact;
}

ShapeContact TriangleMeshShape::contactWith(const Vec3& local, Index triangle) const {
  const Vec3* corner = &m_geometry->corners[3 * triangle];
  const TriangleClosestPoint best = closestPointOnTriangle(local, corner[0], corner[1], corner[2]);
  const Vec3 offset = local - best.point;
  if (!m_geometry->closed) {
    // A two-sided shell: the unsigned distance, the normal towards the side the point is on.
    const Vec3 normal = best.distance > 0 ? Vec3(offset / best.distance) : m_geometry->faceNormals[triangle];
    return detail::worldContact(m_motion, best.distance, normal, best.point);
  }

  // Pseudo-normal of the closest feature: vertex (one weight is 1), edge (one weight is 0), face.
  const Vec3& w = best.barycentric;
  Vec3 pseudoNormal = m_geometry->faceNormals[triangle];
  for (Index k = 0; k < 3; ++k) {
    if (w[k] == 1) {
      pseudoNormal = m_geometry->vertexNormals[m_geometry->indices[3 * triangle + k]];
      break;
    }
    if (w[k] == 0) {
      // The edge opposite corner k runs from corner k+1 to corner k+2: edge slot (k + 1) % 3.
      pseudoNormal = m_geometry->edgeNormals[3 * triangle + (k + 1) % 3];
    }
  }
  const Real side = offset.dot(pseudoNormal) < 0 ? -1.0 : 1.0;
  const Vec3 normal = best.distance > 0 ? Vec3(side * offset / best.distance) : pseudoNormal;
  return detail::worldContact(m_motion, side * best.distance, normal, best.point);
}

std::optional<Real> TriangleMeshShape::firstCrossing(const Vec3& start, const Vec3& end) const {
  const Vec3 a = m_motion.pose.toLocal(start);
  const Vec3 travel = m_motion.pose.toLocal(end) - a;
  const std::vector<Bvh::Node>& nodes = m_geometry->bvh.nodes();
  Real first = std::numeric_limits<Real>::infinity();
  Index stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Bvh::Node& node = nodes[stack[--top]];
    if (!segmentMeetsBox(a, travel, node.bounds)) continue;
    if (!node.isLeaf()) {
      stack[top++] = node.first;
      stack[top++] = node.first + 1;
      continue;
    }
    for (Index t : m_geometry->bvh.leafTriangles(node)) {
      const Vec3* corner = &m_geometry->corners[3 * t];
      const SegmentTriangleClosestPoints hit = closestPointsOnSegmentAndTriangle(
          a, a + travel, corner[0], corner[1], corner[2]);
      if (hit.distance == 0) first = std::min(first, hit.segmentParameter);
    }
  }
  if (first > 1) return std::nullopt;
  return first;
}

Aabb TriangleMeshShape::bounds() const {
  const Aabb local = m_geometry->bvh.bounds();
  Aabb box;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 x((corner & 1) ? local.max.x() : local.min.x(),
                 (corner & 2) ? local.max.y() : local.min.y(),
                 (corner & 4) ? local.max.z() : local.min.z());
    box.expand(m_motion.pose.toWorld(x));
  }
  return box;
}

}  // namespace weft
