// ClothClothCollision: contact between different cloths of one World, with the response of
// Bridson, Fedkiw & Anderson 2002 (ContactResolver) over the vertices of several cloths at once.
//
// Design note
// -----------
// When. Each cloth is integrated on its own, with its own number of substeps, and resolves its
// self-collisions and colliders per substep. Contact between cloths is resolved once per frame,
// after every cloth has stepped: the frame x₀ → x₁ of every cloth is treated as one step of
// length frameDt with average velocity v̄ = (x₁ − x₀)/frameDt, and the BFA02 pipeline runs on it
// (proximity at x₀, swept tests along x₀ → x₁, impulses, impact zones, freezing). A corrected
// vertex gets v += Δv̄, so a cloth stepped with several substeps keeps its end velocity's shape.
// Rejected: forcing a common substep schedule on cloths whose bounds overlap, and resolving
// between them every substep. It is closer to the substep paths, but it ties the integration of
// cloths together (one cloth's substep count would change another's result and cost), and
// needs Cloth to run its frame one substep at a time from outside. With the default
// implicit integrator a frame is one substep, and the two are the same.
//
// Why the whole chord is checked, self pairs included. A correction moves x₁ of some vertices.
// x₀ and the substep path of each cloth were free of self-crossings, but the new chord
// x₀ → x₁' is not known to be, so the swept tests (not the proximity, done per substep) cover
// the self pairs of every cloth in contact too. A zone may then hold vertices of two cloths:
// it moves them with one rigid motion. Since x₀ of all of them is free of crossings (the
// previous frame ended clean) and the chord ends with no swept hit, x₁ is free of crossings too:
// zero intersecting pairs between and within the cloths at every frame end.
//
// Colliders. A corrected vertex may be pushed into a collider (a layer pressed into the floor
// by the one above). Each cloth's collider response (ColliderResponse) runs again on the
// corrected vertices only, over the frame (collider motion from the frame start to its end);
// if it moved any of them, the swept tests run once more on the new chord (no proximity), up to
// three rounds. Inside the resolver, vertices held by a collider count as heavy and corrected
// vertices are clamped out of the colliders after every round of impulses (ContactResolver.h,
// "Colliders"), so the swept stage rarely pushes anything back in. The last word is the swept
// stage: no crossing between cloths survives, guaranteed; that no vertex ends inside a collider
// is what the clamp and the rounds achieve in the tested scenes, not a proof (an impact zone's
// rigid motion, for one, ignores colliders).
//
// Cost. Nothing when no two participating cloths have overlapping swept bounds (one pass over
// the vertices per cloth). Otherwise per-cloth BVHs (built once from the rest shape when the set
// of cloths changes, refit per call) give the cross pairs (Bvh::queryPairs, for the pairs of
// cloths whose bounds overlap) and the self pairs of the cloths in contact.
//
// Strain limiting in contact. The resolver shares every impulse by mass, so under a much
// heavier cloth (a dense pad on a light sheet) the light one takes almost all of each
// correction, and its own limiter, run before this pass and blind to the other cloth, cannot
// lift the weight: a 0.22 kg pad on a 37 g sheet pinned at its corners stretched it to strain
// 16.6 (ClothClothStrainTest). So the pass runs one strain limiter over the index space of the
// cloths in contact (StrainLimiter::applyInContact) with the pairs it found held one-sided
// (`separations`: every movable vertex of a pair counts as heavy as its heaviest, so lifting the
// sheet lifts the pad), then the swept pass again (the last word), a few rounds,
// as Cloth::limitStrainInContact does within one cloth. The pairs found in any pass of the frame
// stay held for the rest of it: a swept hit held only in the next round was pushed through again
// in the one after, and a hit in the last round stretched the sheet to 0.20 in 2 of 240 frames.
// Which pairs: every pair between two cloths, whatever their masses, and the self pairs (swept
// stage) of very different masses as Cloth holds them (kHeldContactMassRatio). Cloth's per-vertex
// mass ratio does not fit two cloths: a pad's border and corner vertices carry a half and a
// sixth of an interior one's mass, so under a pad 30 times as dense as the sheet most pairs fell
// below the ratio and the sheet reached 0.11–0.49 (0.14–0.23 at 3 times as dense, where no pair
// passes it; 8.7–12.9 and 0.14–0.23 with no limiter here); holding every pair between the
// cloths, 0.101 from 3 to 300 times (these figures: 6 placements of the pad, 240 frames, with
// the rounds then running the proximity stage too; the tests' cases, 0.101, are of this code).
// Where nothing is over the limit the limiter moves nothing (a pad as dense as the sheet: the
// same largest strains, 0.046–0.070, as without it). The
// folds Cloth's self-contacts keep caught when all are held (stress scene 10) are within one
// cloth, where the rule is unchanged.
// One limiter over all the members rather than each cloth's own with the other side fixed: a
// held pair must move both sides (the sheet's limiter with the pad fixed could not lift it, nor
// the pad's, which is not stretched). Each member keeps its own limit: its rest lengths are
// scaled by (1 + its limit) / (1 + the smallest limit), which the joint limiter runs with (its
// stopping tolerance scales by the same factor, a few percent). Members whose bounds touch no
// other have no weight there, cloths without a limit no edges; the collider normals and fixed
// vertices are those each cloth's last substep left (Cloth::contactHolds). Cost: rounds run in
// frames where an edge of the cloths in contact is over its limit; scenes/data/two-layers.json
// (silk on cotton, 2.5 times the mass per area) went from max strain 0.304 to 0.101, at 16.1 ms
// per frame at the median against 17.3 before (one thread, shared machine; the swept stage of
// the rounds reuses the first pass's work, see resolveFrame).
//
// Determinism. Members are kept in world slot order; the index space concatenates them in that
// order; all pairs are sorted; the resolver is deterministic (ContactResolver.h).
#pragma once

#include "ColliderResponse.h"
#include "ContactResolver.h"

#include <weft/collision/Bvh.h>
#include <weft/engine/World.h>
#include <weft/threading/PerWorker.h>

#include <memory>
#include <span>
#include <vector>

namespace weft {

class Cloth;

class ClothClothCollision final : public ContactResolver {
 public:
  explicit ClothClothCollision(TaskSystem* tasks);

  /// Starts the list of cloths taking part this frame (those with
  /// ClothSettings::collideWithOtherCloths), to be given in world slot order by addCloth().
  void beginFrame() { m_next.clear(); }
  void addCloth(ClothId id, Cloth* cloth) { m_next.push_back({id, cloth}); }

  /// Resolves contact between the cloths added since beginFrame() over the frame they have just
  /// stepped, against `colliders` (posed at the frame end, motions from the frame start). Builds
  /// its tables again when the set of cloths changed (allocates then only).
  SelfCollisionReport resolveFrame(Real frameDt, std::span<const ColliderFrame> colliders);

 private:
  struct Member {
    ClothId id;
    Cloth* cloth = nullptr;
  };

  void rebuild();
  void findTrianglePairs(const Vec3Array& from, const Vec3Array& to, Real inflate, bool proximity,
                         std::vector<TrianglePair>& pairs) override;
  // Copies the index space's corrected vertices back into the cloths; true when any changed.
  bool writeBack();
  // Runs each cloth's collider response on its vertices corrected so far; true when it moved any.
  bool resolveColliders(std::span<const ColliderFrame> colliders);
  // After a resolve(): writes it back, then the rounds of collider response and swept tests.
  void settleColliders(Real frameDt, std::span<const ColliderFrame> colliders,
                       SelfCollisionReport& report);
  // Appends the last resolve()'s pairs to hold (see the design note) to m_heldContacts (emptied
  // first when `restart`).
  void collectHeldContacts(bool restart);
  // The strain limiter over the members in contact with m_heldContacts held, then the pass
  // again, a few rounds (see the design note); nothing when no pair is held.
  void limitStrainInContact(Real frameDt, std::span<const ColliderFrame> colliders,
                            SelfCollisionReport& report);
  // Copies the vertices the strain limiter moved back into the cloths; true when any moved.
  bool writeBackLimited();

  std::vector<Member> m_next;     // this frame's participants
  std::vector<Member> m_members;  // the participants the tables were built for
  std::vector<Bvh> m_bvhs;        // one per member, rest shape
  std::vector<Index> m_vertexOffset, m_triangleOffset;  // per member, then the totals
  std::vector<char> m_active;     // per member: its swept bounds overlap another member's
  std::vector<Aabb> m_bounds;     // per member: swept over the frame, inflated by the thickness
  std::vector<std::array<Index, 2>> m_overlaps;  // member pairs (c < d) with overlapping bounds
  std::vector<ContactOwner> m_owners;            // per member
  std::unique_ptr<PerWorker<std::vector<TrianglePair>>> m_workerPairs;
  std::vector<TrianglePair> m_memberPairs;  // one query's pairs, in member triangle ids
  Vec3Array m_start, m_x, m_v;                // index space: frame start, end, end velocity
  std::vector<Real> m_inverseMasses;          // index space, 0 for pinned vertices
  std::vector<char> m_corrected;              // index space: changed by any pass this frame
  std::vector<char> m_skip;                   // one cloth: pinned or not corrected
  Vec3Array m_before;                         // one cloth: positions before the collider pass
  std::vector<ColliderFrame> m_colliders;     // one cloth's view of the colliders
  ColliderResponse m_colliderResponse;
  // Strain limiting in contact: one limiter over the members' edges (none when no member has a
  // limit), its settings, and per vertex of the index space the inverse masses (0 for pinned,
  // fixed on colliders, or of members not in contact) and collider normals it sees.
  std::unique_ptr<StrainLimiter> m_strainLimiter;
  StrainLimitSettings m_strainLimitSettings;
  std::vector<Real> m_limitInverseMasses;
  Vec3Array m_limitNormals;
  std::vector<SeparationHold> m_heldContacts;  // this frame's pairs held (see the design note)
  std::vector<Index> m_vertexMember;           // index space: the member a vertex belongs to
};

}  // namespace weft
