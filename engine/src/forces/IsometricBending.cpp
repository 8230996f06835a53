// Isometric bending stencils; see IsometricBending.h for the energy and its choices.
#include "forces/IsometricBending.h"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>

namespace weft {
namespace {

// A weight counts when it is above round-off of the largest one: weights that cancel to ~1e-17
// must not widen the matrix pattern.
constexpr Real kNegligibleWeight = 1e-12;

Vec3 areaNormal(const Vec3& x0, const Vec3& x1, const Vec3& x2) {
  return (x1 - x0).cross(x2 - x0);  // twice the area along the normal
}

}  // namespace

BendingStencils buildBendingStencils(const Vec3Array& x, const std::vector<Index>& indices,
                                     const std::vector<Edge>& edges,
                                     const std::vector<Index>& skipped) {
  const Index vertexCount = static_cast<Index>(x.size());
  const Index triangleCount = static_cast<Index>(indices.size() / 3);
  // Incident triangles and edges per vertex, in mesh order (CSR).
  std::vector<Index> triangleOffsets(vertexCount + 1, 0), edgeOffsets(vertexCount + 1, 0);
  for (Index corner : indices) ++triangleOffsets[corner + 1];
  for (const Edge& edge : edges) {
    ++edgeOffsets[edge.vertices[0] + 1];
    ++edgeOffsets[edge.vertices[1] + 1];
  }
  for (Index v = 0; v < vertexCount; ++v) {
    triangleOffsets[v + 1] += triangleOffsets[v];
    edgeOffsets[v + 1] += edgeOffsets[v];
  }
  std::vector<Index> vertexTriangles(triangleOffsets.back()), vertexEdges(edgeOffsets.back());
  {
    std::vector<Index> fill(triangleOffsets.begin(), triangleOffsets.end() - 1);
    for (Index t = 0; t < triangleCount; ++t)
      for (int k = 0; k < 3; ++k) vertexTriangles[fill[indices[3 * t + k]]++] = t;
    std::vector<Index> edgeFill(edgeOffsets.begin(), edgeOffsets.end() - 1);
    for (Index e = 0; e < Index(edges.size()); ++e)
      for (Index end : edges[e].vertices) vertexEdges[edgeFill[end]++] = e;
  }

  BendingStencils out;
  // Neighbours of the current vertex (the centre included) with the weights of the three rows
  // A_v H_uu, A_v H_vv and A_v H_uv.
  struct RingVertex {
    Index vertex;
    std::array<Real, 4> weight;  // (a, b) = (u, u), (u, v), (v, u), (v, v) at 2a + b
  };
  std::vector<RingVertex> ring;
  for (Index v = 0; v < vertexCount; ++v) {
    const Index firstTriangle = triangleOffsets[v], triangles = triangleOffsets[v + 1] - firstTriangle;
    const Index firstEdge = edgeOffsets[v], edgeCount = edgeOffsets[v + 1] - firstEdge;
    ring.clear();
    ring.push_back({v, {}});
    bool manifold = true;
    for (Index k = 0; k < edgeCount; ++k) {
      const Edge& edge = edges[vertexEdges[firstEdge + k]];
      ring.push_back({edge.vertices[0] == v ? edge.vertices[1] : edge.vertices[0], {}});
      if (edge.triangles[1] == kInvalidIndex - 1) manifold = false;
    }
    if (!manifold || triangles == 0 || std::binary_search(skipped.begin(), skipped.end(), v)) continue;
    std::sort(ring.begin() + 1, ring.end(),
              [](const RingVertex& a, const RingVertex& b) { return a.vertex < b.vertex; });
    auto weightsOf = [&ring](Index vertex) -> std::array<Real, 4>& {
      if (vertex == ring[0].vertex) return ring[0].weight;
      return std::lower_bound(ring.begin() + 1, ring.end(), vertex,
                              [](const RingVertex& a, Index b) { return a.vertex < b; })
          ->weight;
    };
    auto isBoundaryEdge = [&](Index other) {
      for (Index k = 0; k < edgeCount; ++k) {
        const Edge& edge = edges[vertexEdges[firstEdge + k]];
        if (edge.vertices[0] == other || edge.vertices[1] == other) {
          return edge.triangles[1] == kInvalidIndex;
        }
      }
      return false;
    };

    // Rest tangent frame of the vertex: the 1-ring is unfolded by projection onto it (exact
    // for a flat rest shape, where all that matters is that one frame serves every triangle).
    Vec3 normal = Vec3::Zero();
    for (Index k = 0; k < triangles; ++k) {
      const Index* t = &indices[3 * vertexTriangles[firstTriangle + k]];
      normal += areaNormal(x[t[0]], x[t[1]], x[t[2]]);
    }
    if (normal.norm() == 0) continue;
    normal.normalize();
    const Vec3 axis = std::abs(normal.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    const Vec3 e1 = normal.cross(axis).normalized(), e2 = normal.cross(e1);
    auto project = [&](Index k) { return Vec2((x[k] - x[v]).dot(e1), (x[k] - x[v]).dot(e2)); };

    // A_v H_ab = ∮ ∂_b x n_a over the barycentric cell of v (divergence theorem), with ∂_b x
    // the constant gradient G_t of each triangle: −Σ_t A_t ∂_a φ_v G_t[b] over the cell's inner
    // boundary, plus (l/2) n_a G_t[b] along each free edge at v. The closed cell makes it exact
    // zero for any affine x, so rigid motions cost nothing even at free edges.
    Real area = 0;
    bool degenerate = false;
    for (Index k = 0; k < triangles && !degenerate; ++k) {
      const Index* t = &indices[3 * vertexTriangles[firstTriangle + k]];
      const std::array<Vec2, 3> p{project(t[0]), project(t[1]), project(t[2])};
      Eigen::Matrix<Real, 2, 2> edgesInPlane;
      edgesInPlane.col(0) = p[1] - p[0];
      edgesInPlane.col(1) = p[2] - p[0];
      const Real determinant = edgesInPlane.determinant();
      const Real triangleArea = std::abs(determinant) / 2;
      if (!(triangleArea > kNegligibleWeight * edgesInPlane.squaredNorm())) {
        degenerate = true;
        break;
      }
      area += areaNormal(x[t[0]], x[t[1]], x[t[2]]).norm() / 6;
      const Eigen::Matrix<Real, 2, 2> inverse = edgesInPlane.inverse();
      std::array<Vec2, 3> gradient;  // ∇φ_k on the triangle
      gradient[1] = inverse.row(0).transpose();
      gradient[2] = inverse.row(1).transpose();
      gradient[0] = -gradient[1] - gradient[2];
      const int corner = t[0] == v ? 0 : (t[1] == v ? 1 : 2);
      for (int k2 = 0; k2 < 3; ++k2) {
        std::array<Real, 4>& w = weightsOf(t[k2]);
        for (int a = 0; a < 2; ++a)
          for (int b = 0; b < 2; ++b) w[2 * a + b] -= triangleArea * gradient[corner][a] * gradient[k2][b];
      }
      for (int side = 1; side <= 2; ++side) {
        const int other = (corner + side) % 3, third = (corner + 3 - side) % 3;
        if (!isBoundaryEdge(t[other])) continue;
        const Vec2 along = p[other] - p[corner];
        Vec2 outward(along.y(), -along.x());  // |outward| = edge length
        if (outward.dot(p[third] - p[corner]) > 0) outward = -outward;
        for (int k2 = 0; k2 < 3; ++k2) {
          std::array<Real, 4>& w = weightsOf(t[k2]);
          for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b) w[2 * a + b] += Real(0.5) * outward[a] * gradient[k2][b];
        }
      }
    }
    if (degenerate || !(area > 0)) continue;

    // Rows: H_uu, H_vv and the symmetric H_uv; |H|² = H_uu² + H_vv² + 2 H_uv².
    struct Row {
      std::array<Real, 2> pick;  // weight = pick[0]·w[first] + pick[1]·w[second]
      int first, second;
      Real energyWeight;
    };
    const std::array<Row, 3> rows{Row{{1, 0}, 0, 0, 1 / area}, Row{{1, 0}, 3, 3, 1 / area},
                                  Row{{0.5, 0.5}, 1, 2, 2 / area}};
    std::vector<StencilWeight> row;
    for (const Row& choice : rows) {
      row.clear();
      for (const RingVertex& r : ring) {
        row.push_back({r.vertex, choice.pick[0] * r.weight[choice.first] +
                                     choice.pick[1] * r.weight[choice.second]});
      }
      auto restValue = [&]() {
        Vec3 value = Vec3::Zero();
        for (std::size_t j = 1; j < row.size(); ++j) value += row[j].weight * (x[row[j].vertex] - x[v]);
        return value;
      };
      // Weights sum to zero (constants are annihilated): the centre takes minus the rest.
      auto recentre = [&]() {
        row[0].weight = 0;
        for (std::size_t j = 1; j < row.size(); ++j) row[0].weight -= row[j].weight;
      };
      recentre();
      Real magnitude = 0;  // round-off reference: Σ |w| |x_j − x_v|
      for (const StencilWeight& w : row) magnitude += std::abs(w.weight) * (x[w.vertex] - x[v]).norm();
      if (!(magnitude > 0)) continue;
      // Rest value: keep only its normal part, as the tangential one would resist rotations.
      // Flat rest shapes have none (the stencil is exact for affine maps).
      Vec3 rest = restValue();
      const Vec3 tangential = rest - rest.dot(normal) * normal;
      if (tangential.norm() > kNegligibleWeight * magnitude) {
        // Smallest correction c (Σ c_j² least) with Σ c_j P(x_j − x_v) = tangential, P the
        // projection on the rest tangent plane; then w_j −= c_j.
        Eigen::Matrix<Real, 2, Eigen::Dynamic> edgeMatrix(2, row.size() - 1);
        for (std::size_t j = 1; j < row.size(); ++j) edgeMatrix.col(j - 1) = project(row[j].vertex);
        const Eigen::Matrix<Real, 2, 2> gram = edgeMatrix * edgeMatrix.transpose();
        if (!(std::abs(gram.determinant()) > kNegligibleWeight * gram.squaredNorm())) continue;
        const Vec2 target(e1.dot(tangential), e2.dot(tangential));
        const Eigen::Matrix<Real, Eigen::Dynamic, 1> correction =
            edgeMatrix.transpose() * gram.inverse() * target;
        for (std::size_t j = 1; j < row.size(); ++j) row[j].weight -= correction(j - 1);
        recentre();
        rest = restValue();
      }
      Real restCurvature = rest.dot(normal);
      if (std::abs(restCurvature) <= kNegligibleWeight * magnitude) restCurvature = 0;

      BendingStencil stencil;
      stencil.vertex = v;
      stencil.firstWeight = static_cast<Index>(out.weights.size());
      stencil.energyWeight = choice.energyWeight;
      stencil.restCurvature = restCurvature;
      Real largest = 0;
      for (const StencilWeight& w : row) largest = std::max(largest, std::abs(w.weight));
      for (std::size_t j = 0; j < row.size(); ++j) {
        if (j == 0 || std::abs(row[j].weight) > kNegligibleWeight * largest) out.weights.push_back(row[j]);
      }
      stencil.weightCount = static_cast<Index>(out.weights.size()) - stencil.firstWeight;
      if (restCurvature != 0) {
        stencil.firstTriangle = static_cast<Index>(out.triangles.size());
        stencil.triangleCount = triangles;
        for (Index k = 0; k < triangles; ++k) out.triangles.push_back(vertexTriangles[firstTriangle + k]);
      }
      out.stencils.push_back(stencil);
    }
  }
  return out;
}

Vec3 stencilVector(const BendingStencil& stencil, std::span<const StencilWeight> weights,
                   const Vec3Array& x) {
  Vec3 value = Vec3::Zero();
  for (Index k = 0; k < stencil.weightCount; ++k) {
    const StencilWeight& w = weights[stencil.firstWeight + k];
    value += w.weight * x[w.vertex];
  }
  return value;
}

Vec3 stencilNormal(const BendingStencil& stencil, std::span<const Index> triangles,
                   const std::vector<Index>& indices, const Vec3Array& x) {
  Vec3 normal = Vec3::Zero();
  for (Index k = 0; k < stencil.triangleCount; ++k) {
    const Index* t = &indices[3 * triangles[stencil.firstTriangle + k]];
    normal += areaNormal(x[t[0]], x[t[1]], x[t[2]]);
  }
  const Real length = normal.norm();
  return length > 0 ? Vec3(normal / length) : Vec3::Zero();
}

Vec3 bendingResidual(const BendingStencil& stencil, std::span<const StencilWeight> weights,
                     std::span<const Index> triangles, const std::vector<Index>& indices,
                     const Vec3Array& x) {
  Vec3 residual = stencilVector(stencil, weights, x);
  if (stencil.restCurvature != 0) {
    residual -= stencil.restCurvature * stencilNormal(stencil, triangles, indices, x);
  }
  return residual;
}

}  // namespace weft
