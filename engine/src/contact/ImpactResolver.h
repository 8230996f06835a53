// ImpactResolver: the fail-safe with the last word in every substep (Bridson, Fedkiw & Anderson
// 2002, §7.1 and §7.3), over the contact space, so one cloth or several alike.
//
// It runs on the substep's start x₀ and the end x₁ the projection left, through the average
// velocity v̄ = (x₁ − x₀)/h, and changes only what must change:
//  1. Colliders: every vertex's path relative to each body is traced; one that passed through a
//     body or ends within its thickness is put back outside and keeps no velocity into it (a
//     body too fast or too thin for the detection's candidates). A vertex the projection
//     followed as a collider contact is traced from where the projection left it: the
//     projection moved it round the body step by step, and the straight path from x₀ may cut
//     through a body it slid round (putting it back there would undo the strain limit). Then
//     the faces of the substep's face contacts are put back at their reach from the cores
//     (converged, where the projection stopped at its tolerance): a vertex pushed out of one
//     capsule of a ring may tilt its face into the next.
//  2. Swept tests: the motion x₀ → x₀ + h v̄ of every vertex–triangle and edge–edge pair of the
//     broad phase is tested for the first time of coplanarity; each hit gets an impulse that
//     leaves the pair separating. Repeated a bounded number of passes, each testing again only
//     pairs with a vertex whose path changed or that was in a hit (the others would test exactly
//     as before).
//  3. Rigid impact zones: pairs still colliding merge into zones whose vertices move with one
//     rigid motion (linear and angular momentum kept), repeated until clean; as a last resort
//     the vertices still colliding keep their start positions, which cannot cross since x₀ is free
//     of crossings. So no crossing survives a substep.
// After every round of impulses, a corrected vertex whose path now meets a collider is put back
// out of it, and a face an impulse moved into a core back to its reach; a vertex that ends within
// 1.5 thicknesses of a collider counts 1000× heavier in the impulses, so the free side of a pair
// takes them.
//
// Impulses are shared among the four vertices of a pair by barycentric weight and inverse mass.
// The exact tests run in parallel over fixed blocks and are put back in pair order; the impulses
// are applied serially in that order: the same bits on any thread count.
#pragma once

#include "contact/ColliderFrame.h"
#include "contact/ContactSet.h"
#include "contact/ContactSpace.h"
#include "contact/FeaturePairs.h"
#include "contact/OrderedPairFilter.h"

#include <weft/threading/PerWorker.h>
#include <weft/threading/TaskSystem.h>

#include <memory>
#include <span>
#include <vector>

namespace weft {

/// The feature pairs the detection found this substep, over x₀ → `endPositions` with `margin`
/// (m): the impact stage's swept tests reuse them for the pairs whose vertices the stages between
/// moved little, and search only the others.
struct DetectedPairs {
  const FeaturePairs* features = nullptr;
  std::span<const Vec3> endPositions;
  Real margin = 0;
};

/// What one resolve() did.
struct ImpactReport {
  Index colliderCorrections = 0;  ///< vertices put back out of a collider
  Index impacts = 0;              ///< swept collisions resolved by impulses
  Index impactZones = 0;          ///< rigid impact-zone passes
  Index frozenVertices = 0;       ///< vertices held at their start (last resort)
};

class ImpactResolver {
 public:
  /// Builds the broad-phase tables (when the space's cloths change).
  void build(const ContactSpace& space, TaskSystem* tasks);
  void setRefitMargin(Real margin) { m_features.setRefitMargin(margin); }
  /// `skip`: WorldSettings::skipUnneededStages; off, every collider is traced, near or not.
  void setSkipping(bool skip) { m_skip = skip; }

  /// Corrects space.x and space.v (from space.startX over h) as the file comment says. `pairs`:
  /// run the swept tests between cloth features (false when no cloth can touch itself or
  /// another this substep).
  ImpactReport resolve(ContactSpace& space, const ContactSet& set,
                       std::span<const ColliderFrame> colliders, Real h, bool pairs,
                       const DetectedPairs& detected = {});

  Bvh::RefitCounts takeRefitCounts() { return m_features.takeRefitCounts(); }

 private:
  struct Impact {
    std::array<Index, 4> vertices{};
    std::array<Real, 4> weights{};
    Vec3 normal = Vec3::Zero();
    Real thickness = 0;
    Real friction = 0;
  };
  Index keepOutOfColliders(ContactSpace& space, const ContactSet& set,
                           std::span<const ColliderFrame> colliders);
  bool findImpacts(const ContactSpace& space, Real h);
  void applyImpulse(const Impact& impact, Real targetNormalSpeed, const ContactSpace& space);
  void rigidifyZones(const ContactSpace& space);
  Real impulseInverseMass(Index vertex, const ContactSpace& space);
  void clampToColliders(const ContactSpace& space, Real h);
  // Sweeps of the face contacts on thin bodies over positions `x` (shifts also made as velocity
  // changes × inverseStep in `v`); `touchedOnly`: faces with a corner in m_touched, which the
  // pushes extend. A corner pushed into a body stops on its surface.
  void pushFacesOut(const ContactSet& set, std::span<const Real> inverseMasses, std::span<Vec3> x,
                    std::span<Vec3> v, Real inverseStep, bool touchedOnly);
  // Marks in m_farMover the vertices whose ends moved too far from the detection's for its
  // feature pairs to hold theirs; returns how many.
  Index markFarMovers();
  // keepOutside() for `vertex` ending at `end`: traced from where the projection left it when
  // the projection followed it as a collider contact (the body at its end pose), else over the
  // substep from x₀.
  Vec3 keepVertexOutside(Index vertex, const ColliderFrame& collider, const ContactSpace& space,
                         const Vec3& end, Real thickness) const;

  TaskSystem* m_tasks = nullptr;
  bool m_skip = true;
  FeaturePairs m_features;
  DetectedPairs m_detected;  // the detection's pairs, reused for the ends that stay within reach
  std::span<const ColliderFrame> m_colliders;
  const ContactSet* m_set = nullptr;  // this substep's, for its face contacts
  std::vector<Index> m_near;                 // colliders near the cloth this substep
  OrderedPairFilter<Impact> m_pairFilter;
  std::vector<Impact> m_impacts;
  Vec3Array m_velocity;                      // v̄ being corrected
  Vec3Array m_end;                           // x₀ + h v̄
  Vec3Array m_testedEnd;                     // the ends of the last swept test
  std::vector<char> m_dirty;                 // per vertex: test its pairs again
  std::vector<char> m_farMover;              // per vertex: its pairs are searched, not reused
  std::vector<char> m_touched;               // per vertex: v̄ changed
  Vec3Array m_projected;                     // x as the projection left it
  std::vector<char> m_tracked;               // per vertex: in a collider contact of the set
  std::vector<Real> m_colliderSeparation;    // per vertex: how far it is kept from a body (m)
  Vec3Array m_beforeFaces;                   // per face corner: x before the face sweeps
  std::vector<char> m_faceCorner;            // per vertex: in m_faceCorners
  std::vector<Index> m_faceCorners;          // corners of the faces the sweeps visited
  bool m_faceContacts = false;               // the set has face contacts
  std::vector<signed char> m_held;           // per vertex: −1 unknown, 0 free, 1 held
  std::vector<Index> m_zoneParent;           // union–find over vertices
  std::vector<char> m_inZone;
  std::vector<Index> m_zoneOrder;            // zone members sorted by root
};

}  // namespace weft
