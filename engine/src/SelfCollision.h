// SelfCollision: keeps a cloth from passing through itself, in the manner of Bridson, Fedkiw &
// Anderson 2002. The response (proximity repulsion and friction, swept impulses, rigid impact
// zones, and the care for colliders) is ContactResolver's; this class gives it the cloth's own
// features and a broad phase over two BVHs (proximity and swept), built from the rest shape and
// refit every call (keeping the boxes of parts that did not move, see Bvh::setRefitMargin),
// queried for self pairs.
#pragma once

#include "ContactResolver.h"

#include <weft/collision/Bvh.h>
#include <weft/engine/ClothModel.h>
#include <weft/threading/PerWorker.h>
#include <weft/threading/TaskSystem.h>

#include <memory>
#include <vector>

namespace weft {

/// The edge table of a model (vertex ids of every edge) and the three edge ids of every
/// triangle, in the model's triangle order.
void buildEdgeTables(const ClothModel& model, std::vector<std::array<Index, 2>>& edges,
                     std::vector<std::array<Index, 3>>& triangleEdges);

class SelfCollision final : public ContactResolver {
 public:
  /// Builds the BVH and the edge tables of the model. BVH refits and queries and the exact tests
  /// run on `tasks` (null: serial), with the same results either way.
  explicit SelfCollision(const ClothModel& model, TaskSystem* tasks = nullptr);

  /// Adjusts the step x₀ → x₁ (positions) and v (velocities, set to the average velocity of the
  /// corrected step) so that the cloth neither ends closer than `thickness` to itself where it
  /// can be pushed apart nor passes through itself. `inverseMasses` are 0 for pinned vertices.
  /// Corrected vertices are kept out of `colliders` (posed at the end of the step).
  SelfCollisionReport resolve(const Vec3Array& start, Real h, Real thickness, Real friction,
                              const std::vector<Real>& inverseMasses, Vec3Array& x, Vec3Array& v,
                              std::span<const ColliderFrame> colliders = {});

  /// The pairs of the cloth closer than `thickness` at `start` (ContactResolver::
  /// findProximityPairs), kept for the next resolve() of the same start.
  void findProximityPairs(const Vec3Array& start, Real thickness, Real friction,
                          std::vector<SeparationHold>& pairs) {
    const ContactOwner owner{thickness, friction};
    ContactResolver::findProximityPairs(start, std::span<const ContactOwner>(&owner, 1), pairs);
  }

  /// Lets the BVHs keep the boxes of parts that moved less than `motion` (m) since their last
  /// refit (Bvh::setRefitMargin; the queries, hence the results, do not change). Negative:
  /// refit every box every time.
  void setRefitSkipping(Real motion);
  /// BVH nodes recomputed and kept by the refits since the last call; resets the counts.
  Bvh::RefitCounts takeRefitCounts() {
    const Bvh::RefitCounts counts = m_refitCounts;
    m_refitCounts = {};
    return counts;
  }

 private:
  void findTrianglePairs(const Vec3Array& from, const Vec3Array& to, Real inflate, bool proximity,
                         std::vector<TrianglePair>& pairs) override;
  void findTrianglePairsTouching(const Vec3Array& from, const Vec3Array& to, Real inflate,
                                 const std::vector<char>& marked,
                                 std::vector<TrianglePair>& pairs) override;

  // Two trees over the same triangles: one refit for the proximity pass (static boxes inflated by
  // the thickness), one for the swept passes (inflated by ~2 µm). With one tree the two
  // inflations alternate, so a kept box would have to be a thickness looser than either needs,
  // and the looser pruning cost more in the queries than the skipped refits saved (measured on
  // a folded strip: +5 % per frame). Each tree refits consistently, so its margin stays small.
  Bvh m_bvh;       // proximity
  Bvh m_sweptBvh;  // continuous (swept) tests
  Bvh::RefitCounts m_refitCounts;  // summed over refits since takeRefitCounts()
  std::unique_ptr<PerWorker<std::vector<TrianglePair>>> m_workerPairs;  // with m_tasks
  std::vector<Index> m_boxHits;  // findTrianglePairsTouching: triangles one box query found
};

}  // namespace weft
