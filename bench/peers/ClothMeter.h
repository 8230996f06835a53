// ClothMeter: measures one cloth the same way whichever engine moved it.
//
// The comparison with Bullet is only fair if both engines are judged by one ruler, so this class
// sees nothing but a triangle list, the flat rest positions and the current positions:
//   - strain of every mesh edge (an edge of the triangle list; Bullet's extra bending links and
//     Weft's hinges are not edges), counted as stretch only: max(0, l / l_rest − 1), as
//     StepStats::maxStrain does (compression turns into folds and is not a failure);
//   - intersecting triangle pairs by Weft's own SelfIntersectionCounter (exact triangle–triangle
//     tests; pairs that share a vertex are never counted, see its header);
//   - blow-ups: a non-finite coordinate, or an "explosion", which is an edge stretched past
//     kExplodedStrain or a vertex farther than kExplodedDistance from the origin.
// Nothing here is timed: the runners measure it outside the step they time.
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/collision/SelfIntersectionCounter.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <utility>
#include <vector>

namespace weft {

/// What a cloth did over a run, measured frame by frame.
struct ClothMeasurements {
  double maxStrain = 0;        ///< largest edge stretch of any frame
  double maxStrainBeforeGather = 0;  ///< largest edge stretch of frames 1..kGatherStartFrame
  double meanStrain = 0;       ///< mean over frames of the mean edge stretch (compression = 0)
  Index maxIntersections = 0;  ///< most intersecting triangle pairs in one frame
  Index framesWithIntersections = 0;
  Index frames = 0;            ///< frames measured
  int maxStrainFrame = 0;      ///< frame (1-based) of maxStrain
  std::array<Index, 2> maxStrainEdge{0, 0};  ///< vertices of the edge stretched most
  int firstNonFiniteFrame = -1;  ///< first frame (1-based) with a NaN or infinity, −1 if none
  int firstExplodedFrame = -1;   ///< first frame (1-based) judged exploded, −1 if none
};

/// Measures strain, intersections and blow-ups of one triangle mesh frame after frame.
class ClothMeter {
 public:
  /// An edge eleven times its rest length: past any stretchy cloth, the mesh has come apart.
  static constexpr double kExplodedStrain = 10.0;
  static constexpr double kExplodedDistance = 100.0;  ///< m from the origin (the scene is ~3 m)
  /// Frames before the rod starts gathering (4 s): settling and the sphere's push and withdrawal.
  static constexpr Index kGatherStartFrame = 240;

  /// A meter for `triangleIndices` (three per triangle) whose rest lengths come from the flat
  /// `restPositions`. Errors as SelfIntersectionCounter::create.
  static Result<ClothMeter> create(std::span<const Index> triangleIndices,
                                   std::span<const Vec3> restPositions) {
    Result<SelfIntersectionCounter> counter =
        SelfIntersectionCounter::create(triangleIndices, restPositions);
    if (!counter.ok()) return counter.error();
    ClothMeter meter(std::move(counter).value());
    // Unique undirected edges of the triangle list.
    std::vector<std::pair<Index, Index>> edges;
    for (std::size_t t = 0; t + 2 < triangleIndices.size(); t += 3) {
      for (int k = 0; k < 3; ++k) {
        const Index a = triangleIndices[t + k], b = triangleIndices[t + (k + 1) % 3];
        edges.emplace_back(std::min(a, b), std::max(a, b));
      }
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    for (const auto& [a, b] : edges) {
      meter.m_edges.push_back({a, b});
      meter.m_restLengths.push_back((restPositions[a] - restPositions[b]).norm());
    }
    return meter;
  }

  /// Measures one frame's positions (vertexCount() entries).
  void measure(std::span<const Vec3> positions) {
    ++m_result.frames;
    const int frame = int(m_result.frames);
    bool finite = true;
    double farthest = 0;
    for (const Vec3& p : positions) {
      finite = finite && p.allFinite();
      farthest = std::max(farthest, p.norm());
    }
    if (!finite) {
      if (m_result.firstNonFiniteFrame < 0) m_result.firstNonFiniteFrame = frame;
      return;  // strain and intersections of NaNs mean nothing
    }
    double frameMax = 0, frameSum = 0;
    std::size_t frameMaxEdge = 0;
    for (std::size_t e = 0; e < m_edges.size(); ++e) {
      const double length = (positions[m_edges[e][0]] - positions[m_edges[e][1]]).norm();
      const double stretch = std::max(0.0, length / m_restLengths[e] - 1);
      if (stretch > frameMax) {
        frameMax = stretch;
        frameMaxEdge = e;
      }
      frameSum += stretch;
    }
    if (m_result.frames <= kGatherStartFrame) {
      m_result.maxStrainBeforeGather = std::max(m_result.maxStrainBeforeGather, frameMax);
    }
    if (frameMax > m_result.maxStrain) {
      m_result.maxStrain = frameMax;
      m_result.maxStrainFrame = frame;
      m_result.maxStrainEdge = m_edges[frameMaxEdge];
    }
    m_strainSum += frameSum / double(m_edges.size());
    ++m_finiteFrames;
    m_result.meanStrain = m_strainSum / double(m_finiteFrames);
    if (m_result.firstExplodedFrame < 0 &&
        (frameMax > kExplodedStrain || farthest > kExplodedDistance)) {
      m_result.firstExplodedFrame = frame;
    }
    const Index pairs = m_counter.count(positions);
    m_result.maxIntersections = std::max(m_result.maxIntersections, pairs);
    m_result.framesWithIntersections += pairs > 0;
  }

  const ClothMeasurements& result() const { return m_result; }
  Index edgeCount() const { return Index(m_edges.size()); }
  Index vertexCount() const { return m_counter.vertexCount(); }

 private:
  explicit ClothMeter(SelfIntersectionCounter counter) : m_counter(std::move(counter)) {}

  SelfIntersectionCounter m_counter;
  std::vector<std::array<Index, 2>> m_edges;
  std::vector<double> m_restLengths;
  ClothMeasurements m_result;
  double m_strainSum = 0;
  Index m_finiteFrames = 0;
};

}  // namespace weft
