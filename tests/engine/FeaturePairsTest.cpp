// FeaturePairs, the self-collision's broad phase, against brute force on a sheet folded onto
// itself and moving: every vertex–triangle and edge–edge pair that comes within the margin at
// some sampled time of the step is reported, each once, and 1 and 2 threads report the same
// lists in the same order. The brute force also counts the pairs no pair of their triangles
// sharing no vertex reaches (a corner vertex against the triangle beside its only one), which
// FeaturePairs lists from the mesh: the sheet must hold some within the margin. Such a pair
// within the pairs' reach at rest is left out by design (a neighbour in the material).
#include "contact/FeaturePairs.h"

#include <weft/collision/Proximity.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

namespace weft {
namespace {

constexpr Index kSide = 16;         // vertices along each side of the sheet
constexpr Real kSpacing = 0.01;     // m
constexpr Real kMargin = 0.006;     // m, the reach asked of find()
constexpr int kSamples = 20;        // times sampled along the step

// A square sheet folded along its middle column so its right half lies 4 mm above its left
// half, as the contact space of one cloth that collides with itself; start and end positions
// with the top layer coming down 3 mm and every vertex jittered by up to 2 mm.
struct FoldedSheet {
  ContactSpace space;
  Vec3Array from, to;

  FoldedSheet() {
    const Real fold = kSpacing * Real(kSide / 2);
    std::mt19937 random(11);
    std::uniform_real_distribution<Real> jitter(-0.002, 0.002);
    for (Index row = 0; row < kSide; ++row) {
      for (Index column = 0; column < kSide; ++column) {
        const Real x = kSpacing * Real(column), y = kSpacing * Real(row);
        space.rest.emplace_back(x, y, 0);
        const bool top = x > fold;
        const Vec3 start(top ? 2 * fold - x : x, y, top ? 0.004 * (x - fold) / kSpacing : 0);
        const Vec3 move(jitter(random), jitter(random), (top ? -0.003 : 0) + jitter(random));
        from.push_back(start);
        to.push_back(start + move);
      }
    }
    space.x = to;
    space.startX = from;
    space.owner.assign(from.size(), 0);
    space.owners.push_back(ContactOwner{});
    std::set<std::array<Index, 2>> edgeSet;
    for (Index row = 0; row + 1 < kSide; ++row) {
      for (Index column = 0; column + 1 < kSide; ++column) {
        const Index a = row * kSide + column, b = a + 1, c = a + kSide, d = c + 1;
        for (const std::array<Index, 3>& triangle : {std::array<Index, 3>{a, b, d}, {a, d, c}}) {
          space.triangles.push_back(triangle);
          for (int k = 0; k < 3; ++k) {
            edgeSet.insert({std::min(triangle[k], triangle[(k + 1) % 3]),
                            std::max(triangle[k], triangle[(k + 1) % 3])});
          }
        }
      }
    }
    space.edges.assign(edgeSet.begin(), edgeSet.end());
    for (const auto& triangle : space.triangles) {
      std::array<Index, 3> edges{};
      for (int k = 0; k < 3; ++k) {
        const std::array<Index, 2> edge{std::min(triangle[k], triangle[(k + 1) % 3]),
                                        std::max(triangle[k], triangle[(k + 1) % 3])};
        edges[k] = Index(std::lower_bound(space.edges.begin(), space.edges.end(), edge) -
                         space.edges.begin());
      }
      space.triangleEdges.push_back(edges);
    }
  }

  Vec3 at(Index vertex, Real t) const { return from[vertex] + t * (to[vertex] - from[vertex]); }
};

bool comesWithinMargin(auto&& distanceAt) {
  for (int s = 0; s <= kSamples; ++s) {
    if (distanceAt(Real(s) / kSamples) < kMargin) return true;
  }
  return false;
}

TEST(FeaturePairs, EveryFeaturePairThatComesWithinTheMarginIsReportedOnce) {
  const FoldedSheet sheet;
  const ContactSpace& space = sheet.space;
  FeaturePairs features;
  features.build(space, nullptr);
  features.find(space, sheet.from, sheet.to, kMargin);
  const auto& vertexTriangle = features.vertexTriangle();
  const auto& edgeEdge = features.edgeEdge();
  const std::set<std::array<Index, 2>> reportedVt(vertexTriangle.begin(), vertexTriangle.end());
  const std::set<std::array<Index, 2>> reportedEe(edgeEdge.begin(), edgeEdge.end());
  EXPECT_EQ(reportedVt.size(), vertexTriangle.size()) << "a vertex–triangle pair twice";
  EXPECT_EQ(reportedEe.size(), edgeEdge.size()) << "an edge–edge pair twice";

  // Triangles around each vertex and each edge, to tell whether a pair of the features'
  // triangles that shares no vertex exists.
  std::vector<std::vector<Index>> aroundVertex(space.vertexCount()), aroundEdge(space.edges.size());
  for (Index t = 0; t < Index(space.triangles.size()); ++t) {
    for (int k = 0; k < 3; ++k) {
      aroundVertex[space.triangles[t][k]].push_back(t);
      aroundEdge[space.triangleEdges[t][k]].push_back(t);
    }
  }
  const auto reachable = [&](const std::vector<Index>& first, const std::vector<Index>& second) {
    for (Index a : first) {
      for (Index b : second) {
        if (!trianglesShareVertex(space.triangles[a], space.triangles[b])) return true;
      }
    }
    return false;
  };
  Index nearVt = 0, nearEe = 0, neighbours = 0;
  for (Index vertex = 0; vertex < space.vertexCount(); ++vertex) {
    for (Index t = 0; t < Index(space.triangles.size()); ++t) {
      const auto& c = space.triangles[t];
      if (vertex == c[0] || vertex == c[1] || vertex == c[2]) continue;
      const bool near = comesWithinMargin([&](Real time) {
        return closestPointOnTriangle(sheet.at(vertex, time), sheet.at(c[0], time),
                                      sheet.at(c[1], time), sheet.at(c[2], time)).distance;
      });
      if (!near) continue;
      ++nearVt;
      if (!reachable(aroundVertex[vertex], {t})) {
        // A neighbour pair within the pairs' reach at rest is left out by design.
        const Real rest = closestPointOnTriangle(space.rest[vertex], space.rest[c[0]],
                                                 space.rest[c[1]], space.rest[c[2]]).distance;
        if (rest < kPairReach * space.pairThickness(vertex, c[0])) continue;
        ++neighbours;
      }
      EXPECT_TRUE(reportedVt.count({vertex, t})) << "vertex " << vertex << ", triangle " << t;
    }
  }
  for (Index a = 0; a < Index(space.edges.size()); ++a) {
    for (Index b = a + 1; b < Index(space.edges.size()); ++b) {
      const auto& p = space.edges[a];
      const auto& q = space.edges[b];
      if (p[0] == q[0] || p[0] == q[1] || p[1] == q[0] || p[1] == q[1]) continue;
      const bool near = comesWithinMargin([&](Real time) {
        return closestPointsOnSegments(sheet.at(p[0], time), sheet.at(p[1], time),
                                       sheet.at(q[0], time), sheet.at(q[1], time)).distance;
      });
      if (!near) continue;
      ++nearEe;
      if (!reachable(aroundEdge[a], aroundEdge[b])) {
        const Real rest = closestPointsOnSegments(space.rest[p[0]], space.rest[p[1]],
                                                  space.rest[q[0]], space.rest[q[1]]).distance;
        if (rest < kPairReach * space.pairThickness(p[0], q[0])) continue;
        ++neighbours;
      }
      EXPECT_TRUE(reportedEe.count({a, b})) << "edges " << a << " and " << b;
    }
  }
  // The fold brings the layers within the margin over most of the sheet.
  EXPECT_GT(nearVt, 200u);
  EXPECT_GT(nearEe, 200u);
  EXPECT_GT(neighbours, 0u);
}

TEST(FeaturePairs, OneAndTwoThreadsReportTheSameListsInTheSameOrder) {
  const FoldedSheet sheet;
  FeaturePairs serial;
  serial.build(sheet.space, nullptr);
  serial.find(sheet.space, sheet.from, sheet.to, kMargin);
  ASSERT_FALSE(serial.vertexTriangle().empty());
  for (int threads : {1, 2}) {
    TaskSystem tasks(TaskSystemSettings{threads});
    FeaturePairs parallel;
    parallel.build(sheet.space, &tasks);
    for (int repeat = 0; repeat < 2; ++repeat) {
      parallel.find(sheet.space, sheet.from, sheet.to, kMargin);
      EXPECT_EQ(parallel.vertexTriangle(), serial.vertexTriangle()) << threads << " threads";
      EXPECT_EQ(parallel.edgeEdge(), serial.edgeEdge()) << threads << " threads";
    }
  }
}

}  // namespace
}  // namespace weft
