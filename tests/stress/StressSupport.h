// Shared checks of the stress suite. Every scene must pass five conditions:
//
//   finite        every position and velocity finite after every frame
//   intersections the collision module's exact counter (SelfIntersectionCounter) finds no
//                 intersecting triangle pair, after every frame (or every `intersectionEvery`-th)
//   strain        the largest edge stretch (StepStats::maxStrain, l / l_rest − 1) at the end of
//                 every frame stays within the material's strain limit + 1 % (absolute: 0.10 +
//                 0.01 for cotton, whose ClothMaterial::strainLimit is 0.10)
//   solver cap    the PCG hits cgMaxIterations (StepStatus::SolverNotConverged) in < 1 % of frames
//   health        no frame rolled back (StepStatus::RolledBack: the health monitor undid the
//                 frame, so the cloth reports its start-of-frame state and every other check
//                 would see a frozen, finite cloth), and no frame retried with a smaller step
//                 (StepStatus::RetriedWithSmallerStep) beyond the bound a scene declares with
//                 its reason (StressMonitor::allowRetries; none by default)
//
// "The material's limit" is ClothMaterial::strainLimit, which the engine's strain limiter
// enforces after every solve (engine/src/StrainLimiting.h); cotton's is 0.10, the end of woven
// cotton's low-strain regime (its 260 N/m is the slope there) and Provot's classic threshold.
// The limiter runs after the solve and again after the collision passes (collider contacts held
// along their normals, a few rounds), but the collisions keep the last word, so a frame can
// still end above the limit where a contact (a self-contact above all) moved vertices after the
// last round: the monitor also
// records the edges the limiter itself left over the limit (StepStats::strainLimitEdgesOver), to
// tell the two apart. Scenes whose set-up forces more strain than that (random or collapsed
// starts, a teleport) measure it once the forcing is over; each says from when. Scenes that
// cannot meet a condition say so and record the measured value instead of asserting it (see the
// scene's comment), and nothing is tuned to pass. Whatever a scene defers or marks, every frame
// that ends past the limit + 1 % must carry StepStatus::StrainLimitExceeded: an unflagged excess
// is a failure of every scene.
#pragma once

#include "golden/GoldenHashes.h"

#include <weft/collision/SelfIntersectionCounter.h>
#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

namespace weft::stress {

/// Strain (l / l_rest − 1) up to which the cotton material's numbers hold, and its
/// ClothMaterial::strainLimit; see above.
inline constexpr Real kCottonStrainLimit = 0.10;
/// Absolute tolerance on the strain limit: "+ 1 %", the engine's own slack before it reports
/// StepStatus::StrainLimitExceeded.
inline constexpr Real kStrainTolerance = kStrainLimitSlack;
/// Largest fraction of frames allowed to hit the PCG's iteration cap.
inline constexpr Real kMaxCapFraction = 0.01;

/// A horizontal square grid of `vertices` × `vertices` over `size` m at height y, front face +y.
inline std::shared_ptr<const ClothModel> horizontalSquare(Index vertices, Real size, Real y) {
  GridSettings grid;
  grid.columns = grid.rows = vertices;
  grid.width = grid.height = size;
  grid.origin = Vec3(-size / 2, y, size / 2);
  grid.widthAxis = Vec3(1, 0, 0);
  grid.heightAxis = Vec3(0, 0, -1);
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

/// Watches the cloths of one world frame by frame and collects the five conditions.
class StressMonitor {
 public:
  /// `intersectionEvery`: count intersecting pairs after every n-th frame (1 = every frame).
  explicit StressMonitor(const World& world, int intersectionEvery = 1)
      : m_world(world), m_every(std::max(1, intersectionEvery)) {}

  /// Adds a cloth to watch (its model gives the triangles for the intersection counter).
  void watch(ClothId cloth, const ClothModel& model) {
    m_cloths.push_back(cloth);
    m_counters.push_back(
        SelfIntersectionCounter::create(model.indices(), model.restPositions()).value());
  }

  /// Declares that up to `bound` frames of this scene may be retried with a smaller step, and
  /// why its physics needs it (one line, printed with the report). Without it, none may be.
  void allowRetries(int bound, const char* reason) {
    m_allowedRetries = bound;
    m_retryReason = reason;
  }

  /// From now on StepStats::maxStrain counts toward the strain condition (before: forced strain
  /// of the scene's set-up). Watching starts measuring at once unless this is deferred.
  void deferStrain() { m_measureStrain = false; }
  void measureStrainFromNow() { m_measureStrain = true; }

  /// Records one frame's outcome; returns false (and records it) if the state went non-finite.
  bool afterFrame(StepStatus status) {
    ++m_frames;
    if (hasFlag(status, StepStatus::SolverNotConverged)) ++m_capHits;
    if (hasFlag(status, StepStatus::RolledBack) && m_rolledBack++ == 0) m_firstRolledBack = m_frames;
    if (hasFlag(status, StepStatus::RetriedWithSmallerStep) && m_retried++ == 0) m_firstRetried = m_frames;
    m_limiterLeftOver += m_world.stats().strainLimitEdgesOver;
    if (m_measureStrain) m_maxStrain = std::max(m_maxStrain, m_world.stats().maxStrain);
    m_peakStrain = std::max(m_peakStrain, m_world.stats().maxStrain);
    if (!hasFlag(status, StepStatus::StrainLimitExceeded)) {
      m_unflaggedStrain = std::max(m_unflaggedStrain, m_world.stats().maxStrain);
    }
    bool finite = true;
    for (ClothId cloth : m_cloths) {
      for (const Vec3& x : m_world.positions(cloth).value()) finite = finite && x.allFinite();
      for (const Vec3& v : m_world.velocities(cloth).value()) finite = finite && v.allFinite();
    }
    if (!finite) ++m_nonFiniteFrames;
    if (finite && m_frames % m_every == 0) {
      for (std::size_t k = 0; k < m_cloths.size(); ++k) {
        const Index count = m_counters[k].count(m_world.positions(m_cloths[k]).value());
        m_maxIntersections = std::max(m_maxIntersections, count);
        if (count > 0 && m_firstIntersectingFrame < 0) m_firstIntersectingFrame = m_frames;
      }
      ++m_intersectionChecks;
    }
    return finite;
  }

  /// Intersecting pairs at the current positions (all watched cloths), outside the cadence.
  Index intersectionsNow() {
    Index total = 0;
    for (std::size_t k = 0; k < m_cloths.size(); ++k) {
      total += m_counters[k].count(m_world.positions(m_cloths[k]).value());
    }
    return total;
  }

  /// The health condition alone (part of expectPasses): no frame rolled back, retries within
  /// the declared bound.
  void expectHealthy(const std::string& name) const {
    EXPECT_EQ(m_rolledBack, 0) << name << ": " << m_rolledBack << " frames rolled back by the "
                               << "health monitor (the first after frame " << m_firstRolledBack << ")";
    EXPECT_LE(m_retried, m_allowedRetries)
        << name << ": " << m_retried << " frames retried with a smaller step (the first after "
        << "frame " << m_firstRetried << "); allowed " << m_allowedRetries
        << (m_retryReason ? std::string(": ") + m_retryReason : std::string());
  }

  int frames() const { return m_frames; }
  int capHits() const { return m_capHits; }
  int rolledBack() const { return m_rolledBack; }
  /// Edges the strain limiter left over limit + 0.001, summed over frames and substeps.
  std::uint64_t limiterLeftOver() const { return m_limiterLeftOver; }
  int retried() const { return m_retried; }
  Real maxStrain() const { return m_maxStrain; }
  Real peakStrain() const { return m_peakStrain; }  ///< including deferred frames
  Index maxIntersections() const { return m_maxIntersections; }
  Real capFraction() const { return m_frames ? Real(m_capHits) / m_frames : 0; }

  /// Prints and records the figures under `name`, and checks the world's state against its
  /// golden hash "stress/<name>" (tests/golden/GoldenHashes.h): every scene reports, so every
  /// scene and every draw of a parameterised one is pinned.
  void report(const std::string& name) const {
    test::expectGoldenHash("stress/" + name, m_world.stateHash());
    std::printf("[stress] %-40s frames %5d  max strain %.4f (peak %.4f)  intersections %u "
                "(checked %d times)  cap hits %d (%.2f %%)  retried %d  rolled back %d  edges the "
                "strain limiter left over %llu\n",
                name.c_str(), m_frames, m_maxStrain, m_peakStrain, m_maxIntersections,
                m_intersectionChecks, m_capHits, 100 * capFraction(), m_retried, m_rolledBack,
                static_cast<unsigned long long>(m_limiterLeftOver));
    ::testing::Test::RecordProperty(name + "_max_strain", std::to_string(m_maxStrain));
    ::testing::Test::RecordProperty(name + "_intersections", std::to_string(m_maxIntersections));
    ::testing::Test::RecordProperty(name + "_cap_fraction", std::to_string(capFraction()));
  }

  /// A condition the engine is known to fail in a scene: measured and printed, not asserted,
  /// and the test ends SKIPPED with the reason, so it stays visible (ctest lists skipped tests).
  enum class Condition { Strain, SolverCap, Intersections };
  struct KnownFailure {
    Condition condition;
    const char* reason;
  };

  /// The five conditions as test expectations; `strainLimit` is the material's limit. Conditions
  /// in `known` are reported instead of asserted (see KnownFailure).
  void expectPasses(const std::string& name, Real strainLimit = kCottonStrainLimit,
                    std::initializer_list<KnownFailure> known = {}) const {
    report(name);
    auto isKnown = [&](Condition condition) -> const char* {
      for (const KnownFailure& failure : known) {
        if (failure.condition == condition) return failure.reason;
      }
      return nullptr;
    };
    std::string skipped;
    auto check = [&](Condition condition, bool passed, const std::string& what) {
      if (const char* reason = isKnown(condition)) {
        std::printf("[stress] %s: KNOWN ENGINE FAILURE, not asserted: %s (%s): %s\n", name.c_str(),
                    what.c_str(), passed ? "passes now; drop the mark" : "fails", reason);
        if (!passed) skipped += what + ": " + reason + "; ";
        return;
      }
      EXPECT_TRUE(passed) << name << ": " << what;
    };
    EXPECT_EQ(m_nonFiniteFrames, 0) << name << ": frames with non-finite state";
    // Honest status, asserted in every scene: a frame past the limit says so.
    EXPECT_LE(m_unflaggedStrain, strainLimit + kStrainTolerance)
        << name << ": a frame ended at strain " << m_unflaggedStrain
        << " without StepStatus::StrainLimitExceeded";
    expectHealthy(name);
    EXPECT_GT(m_intersectionChecks, 0) << name;
    check(Condition::Intersections, m_maxIntersections == 0,
          std::to_string(m_maxIntersections) + " intersecting triangle pairs (first after frame " +
              std::to_string(m_firstIntersectingFrame) + ")");
    check(Condition::Strain, m_maxStrain <= strainLimit + kStrainTolerance,
          "max strain " + std::to_string(m_maxStrain) + " against the limit " +
              std::to_string(strainLimit) + " + 0.01");
    check(Condition::SolverCap, capFraction() < kMaxCapFraction,
          std::to_string(m_capHits) + " of " + std::to_string(m_frames) +
              " frames hit the PCG iteration cap");
    if (!skipped.empty()) {
      ::testing::Test::RecordProperty(name + "_known_failures", skipped);
      GTEST_SKIP() << "KNOWN ENGINE FAILURE in " << name << ": " << skipped;
    }
  }

 private:
  const World& m_world;
  int m_every;
  std::vector<ClothId> m_cloths;
  std::vector<SelfIntersectionCounter> m_counters;
  bool m_measureStrain = true;
  int m_frames = 0, m_capHits = 0, m_rolledBack = 0, m_retried = 0, m_nonFiniteFrames = 0;
  int m_firstRolledBack = -1, m_firstRetried = -1, m_allowedRetries = 0;
  const char* m_retryReason = nullptr;
  int m_intersectionChecks = 0, m_firstIntersectingFrame = -1;
  Real m_maxStrain = 0, m_peakStrain = 0;
  Real m_unflaggedStrain = 0;  // the largest strain of a frame not flagged StrainLimitExceeded
  Index m_maxIntersections = 0;
  std::uint64_t m_limiterLeftOver = 0;
};

}  // namespace weft::stress
