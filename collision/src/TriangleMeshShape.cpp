// Triangle-mesh collider: validation, pseudo-normals, closest-point search. See
// TriangleMeshShape.h for the design note.
#include <weft/collision/TriangleMeshShape.h>

#include <weft/collision/Proximity.h>

#include "ShapeSupport.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <utility>

namespace weft {
namespace {

std::string describeTriangle(Index t, Index a, Index b, Index c) {
  std::ostringstream text;
  text << "TriangleMeshShape: triangle " << t << " (vertices " << a << ", " << b << ", " << c
       << ")";
  return text.str();
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
  Result<Bvh> tree = Bvh::build(geometry->indices, geometry->vertices);
  if (!tree) return tree.error();
  geometry->bvh = std::move(tree).value();

  // Face normals, angle-weighted vertex normals.
  const auto& x = geometry->vertices;
  geometry->faceNormals.resize(triangleCount);
  geometry->vertexNormals.assign(x.size(), Vec3::Zero());
  for (Index t = 0; t < triangleCount; ++t) {
    const Index corner[3] = {indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]};
    const Vec3 normal = (x[corner[1]] - x[corner[0]]).cross(x[corner[2]] - x[corner[0]]).normalized();
    geometry->faceNormals[t] = normal;
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
  for (std::size_t begin = 0; begin < edgeSlots.size();) {
    std::size_t end = begin;
    Vec3 sum = Vec3::Zero();
    while (end < edgeSlots.size() && edgeSlots[end].first == edgeSlots[begin].first) {
      sum += geometry->faceNormals[edgeSlots[end].second / 3];
      ++end;
    }
    if (sum.squaredNorm() > 0) sum.normalize();
    for (std::size_t i = begin; i < end; ++i) geometry->edgeNormals[edgeSlots[i].second] = sum;
    begin = end;
  }
  shape.m_geometry = std::move(geometry);
  return shape;
}

void TriangleMeshShape::worldVertices(std::span<Vec3> vertices) const {
  const std::vector<Vec3>& local = m_geometry->vertices;
  for (std::size_t v = 0; v < local.size() && v < vertices.size(); ++v) {
    vertices[v] = m_motion.pose.toWorld(local[v]);
  }
}

Status TriangleMeshShape::setMotion(const RigidMotion& motion) {
  RigidMotion checked = motion;
  if (Status status = validateMotion(checked, "TriangleMeshShape"); !status) return status;
  m_motion = checked;
  return Status::success();
}

ShapeContact TriangleMeshShape::queryPoint(const Vec3& point) const {
  const Vec3 local = m_motion.pose.toLocal(point);
  const Geometry& mesh = *m_geometry;
  const std::vector<Bvh::Node>& nodes = mesh.bvh.nodes();

  // Best-first descent with a fixed stack (one pending sibling per level).
  Real bestSquared = std::numeric_limits<Real>::infinity();
  Index bestTriangle = kInvalidIndex;
  TriangleClosestPoint best;
  Index stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Bvh::Node& node = nodes[stack[--top]];
    if (node.bounds.squaredDistanceTo(local) >= bestSquared) continue;
    if (node.isLeaf()) {
      for (Index t : mesh.bvh.leafTriangles(node)) {
        const TriangleClosestPoint candidate = closestPointOnTriangle(
            local, mesh.vertices[mesh.indices[3 * t]], mesh.vertices[mesh.indices[3 * t + 1]],
            mesh.vertices[mesh.indices[3 * t + 2]]);
        const Real squared = candidate.distance * candidate.distance;
        // Strictly closer only: among equal distances the first one found (a fixed order) wins.
        if (squared < bestSquared) {
          bestSquared = squared;
          best = candidate;
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

  // Pseudo-normal of the closest feature: vertex (one weight is 1), edge (one weight is 0), face.
  const Vec3& w = best.barycentric;
  Vec3 pseudoNormal = mesh.faceNormals[bestTriangle];
  for (Index k = 0; k < 3; ++k) {
    if (w[k] == 1) {
      pseudoNormal = mesh.vertexNormals[mesh.indices[3 * bestTriangle + k]];
      break;
    }
    if (w[k] == 0) {
      // The edge opposite corner k runs from corner k+1 to corner k+2: edge slot (k + 1) % 3.
      pseudoNormal = mesh.edgeNormals[3 * bestTriangle + (k + 1) % 3];
    }
  }
  const Vec3 offset = local - best.point;
  const Real side = offset.dot(pseudoNormal) < 0 ? -1.0 : 1.0;
  const Vec3 normal = best.distance > 0 ? Vec3(side * offset / best.distance) : pseudoNormal;
  return detail::worldContact(m_motion, side * best.distance, normal, best.point);
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
