// ContactResolver: the collision response of Bridson, Fedkiw & Anderson 2002 ("Robust treatment
// of collisions, contact and friction for cloth animation") over one vertex index space that may
// hold one cloth (SelfCollision) or several (ClothClothCollision).
//
// It runs after the integrator, on the step's start positions x₀ and the candidate average
// velocity v̄ = (x₁ − x₀)/h the integrator produced, and changes only v̄:
//
//  1. Proximity (BFA02 §7.2): vertex–triangle and edge–edge pairs closer than the thickness at x₀
//     get an inelastic impulse (no approach) plus a repulsion that pushes them apart by a tenth
//     of the overlap per step, and Coulomb friction on the relative tangential velocity.
//  2. Continuous detection (§7.1): the swept motion x₀ → x₀ + h v̄ of every candidate pair from
//     the broad phase (boxes swept over the step) is tested for the first time of coplanarity;
//     each hit gets an impulse that leaves the pair separating. Repeated a bounded number of
//     passes.
//  3. Fail-safe (§7.3): pairs still colliding merge into rigid impact zones whose vertices move
//     with one rigid motion (momentum and angular momentum kept), repeated until clean; if even
//     that does not clear them, the zone's vertices keep their start positions (v̄ = 0), which
//     cannot cross since x₀ is free of crossings. So no crossing survives a step. A zone is a
//     set of vertices of the index space, so it may span several cloths.
//
// Impulses are shared among the four vertices of a pair by their barycentric weights w and
// inverse masses (pinned vertices have none): Δv_i = w_i λ n / m_i with λ chosen so that the
// relative normal velocity changes by exactly the asked amount.
//
// Threads and determinism. The exact tests (closest points for proximity, cubic roots for the
// swept tests) are most of the work and depend only on x₀ and on the v̄ of the pass, not on the
// impulses of the same pass: they run in parallel over fixed blocks of feature pairs, each
// worker collecting (pair index, contact) records, which are then put back in pair order. The
// impulses are applied one after the other in that order (Gauss–Seidel), serially: they are
// cheap, and applying them in parallel (colouring, or Jacobi sums) would change the result or
// the method. So the result is bitwise the same on any number of threads.
//
// Colliders. An impulse between two features may push a vertex into a collider (a fold
// pressed onto the floor by the layer above, a layer of one cloth onto the sphere by another),
// and a collider response run before this one would not see it. So, when colliders are given
// (setColliders): (a) a vertex that ends within 1.5 thicknesses of a collider is "held" and
// counts as 1000× heavier in the impulses, so the free side of a pair takes practically all of
// it (heavy rather than immovable, so that a pair of two held vertices still shares it); (b)
// after every round of impulses, a corrected vertex whose step now ends within the thickness of
// a collider is put back on the thickness along the collider's normal (constrainVelocities);
// (c) the proximity impulses are swept a few times, so that what the clamp took from one side
// of a pair goes to the other. The last-resort freeze keeps x₀, which was outside.
//
// Resolving one step again. Cloth::limitStrainInContact resolves the same step (same x₀) up to
// six more times after the strain limiter moved some vertices. For SelfCollision (whose broad
// phase reads only its arguments: setBroadPhaseIsPure) such a resolve reuses the proximity
// contacts (they depend on x₀ only) and runs the swept tests only over feature pairs with a
// vertex whose end differs, bit for bit, from the last swept test of that x₀ or that was in one
// of its contacts: every other pair would test exactly as then, negative. Same contacts in the
// same order, so the same bits; on the curtain this took the rounds' self-collision passes from
// ~1.6 ms to ~0.2 ms during the sphere's push (one thread, shared machine).
//
// Owners. Every vertex belongs to an owner (a cloth) with its own thickness and friction. A pair
// uses the larger thickness of its two owners and the geometric mean of their frictions (one
// owner: its own values, bit for bit). Features closer than the thickness in the rest shape are
// neighbours in the material and never repel; that test is made only for pairs of one owner,
// since the rest shapes of two cloths say nothing about each other.
#pragma once

#include "ColliderResponse.h"
#include "StrainLimiting.h"

#include <weft/Math.h>
#include <weft/collision/Bvh.h>
#include <weft/threading/PerWorker.h>
#include <weft/threading/TaskSystem.h>

#include <array>
#include <memory>
#include <span>
#include <vector>

namespace weft {

/// What one resolve() did.
struct SelfCollisionReport {
  Index proximityContacts = 0;  ///< pairs closer than the thickness at the step start
  Index impacts = 0;            ///< swept collisions resolved by impulses
  Index impactZones = 0;        ///< rigid impact zones formed (fail-safe)
  Index frozenVertices = 0;     ///< vertices held at their start (last resort)
};

/// Thickness and friction of one owner (a cloth) of the index space.
struct ContactOwner {
  Real thickness = 0.003;  ///< m, contact distance kept between features
  Real friction = 0.3;     ///< Coulomb coefficient
};

/// How resolve() runs.
struct ContactOptions {
  /// Run the proximity stage (off for a second pass over a step whose proximity was handled).
  bool proximity = true;
  /// How a corrected vertex's velocity is set: true, v = the corrected average velocity (exact
  /// for one backward-Euler step, x₁ = x₀ + h v₁); false, v += the change of the average
  /// velocity (a step made of several substeps, whose end velocity is not its average).
  bool velocityIsAverage = true;
};

class ContactResolver {
 public:
  virtual ~ContactResolver() = default;
  ContactResolver(const ContactResolver&) = delete;
  ContactResolver& operator=(const ContactResolver&) = delete;

  /// Adjusts the step x₀ = `start` → x₁ = `x` (and the velocities `v`) so that no two features
  /// end closer than their thickness where they can be pushed apart and no feature passes
  /// through another. `inverseMasses` are 0 for pinned vertices; `owners` is indexed by the
  /// owner ids given to setTopology().
  SelfCollisionReport resolve(const Vec3Array& start, Real h, std::span<const ContactOwner> owners,
                              const std::vector<Real>& inverseMasses, const ContactOptions& options,
                              Vec3Array& x, Vec3Array& v);

  /// 1 for every vertex whose velocity the last resolve() changed.
  const std::vector<char>& touched() const { return m_touched; }

  /// The pairs the last resolve() found in contact (proximity at the step start, then the swept
  /// hits of the impulse passes, in that order), each with the separation along its normal it
  /// left them at, capped at the pair's thickness: what the strain limiter run after it must not
  /// undo (StrainLimiter::applyInContact). Pairs of the impact zones are not included: the zones
  /// moved them rigidly.
  /// Recorded only after setRecordSeparations(true) (off by default: nothing to pay for a
  /// cloth whose limiter holds no self-contacts).
  const std::vector<SeparationHold>& separationHolds() const { return m_separationHolds; }
  void setRecordSeparations(bool record) { m_recordSeparations = record; }

  /// The pairs closer than their thickness at `start` (the proximity stage's contacts, which a
  /// resolve() from the same start repels), as {vertices, weights, normal, thickness} in pair
  /// order, into `pairs` (cleared first). With a pure broad phase (setBroadPhaseIsPure) they are
  /// kept, so the next resolve() of that start reuses them instead of searching again: asked at
  /// a step's start, before the solve, they cost nothing more (Cloth: the implicit solve's
  /// self-contact terms, SolverSettings::selfContactStiffness).
  void findProximityPairs(const Vec3Array& start, std::span<const ContactOwner> owners,
                          std::vector<SeparationHold>& pairs);

  /// Colliders (posed at the end of the step) the next resolve() keeps corrected vertices out
  /// of; empty: none. The span must stay valid during resolve().
  void setColliders(std::span<const ColliderFrame> colliders) { m_colliders = colliders; }

 protected:
  explicit ContactResolver(TaskSystem* tasks);

  /// Sets the features: triangles and edges as vertex ids of the index space, the edge ids of
  /// every triangle, the rest positions and every vertex's owner.
  void setTopology(std::vector<std::array<Index, 3>> triangles,
                   std::vector<std::array<Index, 3>> triangleEdges,
                   std::vector<std::array<Index, 2>> edges, Vec3Array rest,
                   std::vector<Index> owners);

  /// Broad phase: clears `pairs`, then writes the pairs of triangles (ids of the index space,
  /// first < second, sharing no vertex) whose boxes over `from` → `to`, inflated by `inflate`,
  /// overlap, sorted. `proximity` says which stage asks (a subclass may restrict that stage to
  /// some pairs).
  virtual void findTrianglePairs(const Vec3Array& from, const Vec3Array& to, Real inflate,
                                 bool proximity, std::vector<TrianglePair>& pairs) = 0;
  /// The swept stage's findTrianglePairs restricted to pairs with a triangle whose flag in
  /// `marked` (per triangle) is set: clears `pairs`, then writes, sorted and each once, at least
  /// every such pair findTrianglePairs(from, to, inflate, false) would write (more is allowed: a
  /// pair whose boxes do not overlap yields no feature pair). This one filters the full list.
  virtual void findTrianglePairsTouching(const Vec3Array& from, const Vec3Array& to, Real inflate,
                                         const std::vector<char>& marked,
                                         std::vector<TrianglePair>& pairs);

  /// For a subclass whose broad phase (findTrianglePairs) depends on nothing but its arguments:
  /// resolve() may then carry what it learnt about one step into the next resolve() of the same
  /// step start (bit for bit; the rounds of Cloth::limitStrainInContact resolve the same step
  /// again after the limiter moved some vertices), with the same results as without:
  ///  - the proximity contacts, found from x₀, the rest shape and the owners only, are kept and
  ///    reused while x₀ and the owners are unchanged;
  ///  - the end positions of the last swept test are kept as a certificate, with the vertices
  ///    of the contacts it found: a feature pair of none of those vertices whose four vertices
  ///    have bit for bit the same start and end as then tests negative now too (it did then), so
  ///    the later swept tests of the same start (the next impulse passes, the impact zones, the
  ///    next resolve()) run only over pairs with a vertex whose end differs or that was in a
  ///    contact (findTrianglePairsTouching). The contacts found are the same, in the same order.
  void setBroadPhaseIsPure(bool pure) {
    m_broadPhaseIsPure = pure;
    m_proximityCached = false;
    m_certificateValid = false;
  }

  TaskSystem* m_tasks = nullptr;

 private:
  // A pair of features as four vertices with weights: vertex–triangle (p; a, b, c) has
  // w = (1, −b₀, −b₁, −b₂); edge–edge (p0, p1; q0, q1) has w = (1 − s, s, −(1 − u), −u). The
  // relative velocity is Σ w_i v_i, positive along the normal when separating.
  struct Contact {
    std::array<Index, 4> vertices;
    std::array<Real, 4> weights;
    Vec3 normal;
    Real gap = 0;        // m, distance at the step start (proximity only)
    Real thickness = 0;  // m, of the pair
    Real friction = 0;   // of the pair
  };
  // A contact found by a worker, with the index of its feature pair (for putting them in order).
  struct FoundContact {
    Index pair;
    Contact contact;
  };

  // Vertex–triangle and edge–edge pairs of the candidate triangle pairs whose own boxes (over
  // positions `from` and `to`, one side inflated by `margin`) overlap; each once, in the order
  // of the triangle pairs.
  // With `dirty` (per vertex), only the feature pairs with a dirty vertex.
  void collectFeaturePairs(const Vec3Array& from, const Vec3Array& to, Real margin,
                           const std::vector<char>* dirty = nullptr);
  inline bool sharesVertex(Index firstTriangle, Index secondTriangle) const;
  // Runs test(pairIndex, contact) -> bool over every feature pair (vertex–triangle first, then
  // edge–edge) in parallel and leaves the contacts it accepted in m_contacts, in pair order.
  template <class Test>
  void findContacts(Test&& test);
  bool findImpacts(const Vec3Array& start, Real h);
  void applyImpulse(const Contact& contact, Real targetNormalSpeed,
                    const std::vector<Real>& inverseMasses);
  void rigidifyZones(const Vec3Array& start, const std::vector<Real>& inverseMasses);
  void pairParameters(Index first, Index second, Real& thickness, Real& friction) const;
  // The inverse mass impulses use: scaled down for vertices a collider holds (see above).
  Real impulseInverseMass(Index vertex, const std::vector<Real>& inverseMasses);
  // After a round of impulses: corrected vertices whose step ends within the thickness of a
  // collider go back onto it.
  void clampToColliders(const Vec3Array& start, Real h);
  // Appends the pairs of `contacts` to m_separationHolds (their separations are set at the end
  // of resolve()).
  void holdContacts(const std::vector<Contact>& contacts);
  // The proximity contacts of `start`: found now (into m_contacts), or kept from an earlier call of
  // the same start when the broad phase is pure.
  const std::vector<Contact>& proximityContacts(const Vec3Array& start,
                                                std::span<const ContactOwner> owners);
  // The proximity stage's detection: its contacts into m_contacts.
  void findProximityContacts(const Vec3Array& start, Real maxThickness);
  // True when the proximity contacts kept from an earlier resolve() are those of `start` and
  // `owners` (see setBroadPhaseIsPure).
  bool proximityCacheMatches(const Vec3Array& start, std::span<const ContactOwner> owners) const;

  std::vector<std::array<Index, 3>> m_triangles;      // vertex ids of each triangle
  std::vector<std::array<Index, 3>> m_triangleEdges;  // edge ids of each triangle
  std::vector<std::array<Index, 2>> m_edges;          // vertex ids of each edge
  Vec3Array m_rest;  // rest positions: features closer than the thickness at rest never repel
  std::vector<Index> m_owner;  // owner of every vertex
  std::vector<Index> m_vertexTriangleBegin, m_vertexTriangles;  // triangles around each vertex
  std::vector<std::array<Index, 2>> m_edgeTriangles;  // triangles of each edge (kInvalidIndex: none)
  std::vector<Aabb> m_vertexBoxes;                    // each vertex's box over the step
  std::vector<Aabb> m_triangleBoxes, m_edgeBoxes;     // each triangle's and edge's, likewise
  struct BlockFeatures {
    std::vector<std::array<Index, 2>> vertexTriangle, edgeEdge;
  };
  std::vector<BlockFeatures> m_blockFeatures;  // per block of triangle pairs
  std::span<const ContactOwner> m_owners;  // of the resolve() under way
  std::span<const ColliderFrame> m_colliders;
  const Vec3Array* m_stepEnd = nullptr;  // x₁ as given to the resolve() under way
  std::vector<signed char> m_held;       // per vertex: −1 not yet known, 0 free, 1 held
  std::unique_ptr<PerWorker<std::vector<FoundContact>>> m_workerContacts;  // with m_tasks
  Vec3Array m_velocity;  // v̄ being corrected
  Vec3Array m_end;       // x₀ + h v̄
  std::vector<TrianglePair> m_trianglePairs;
  std::vector<std::array<Index, 2>> m_vertexTriangle;  // (vertex, triangle), each once
  std::vector<std::array<Index, 2>> m_edgeEdge;        // (edge, edge), each once
  std::vector<FoundContact> m_found;
  std::vector<Contact> m_contacts;
  std::vector<Index> m_zoneParent;  // union–find over vertices for impact zones
  std::vector<char> m_inZone;       // 1 for vertices some impact zone holds
  std::vector<char> m_touched;      // 1 for vertices whose velocity this resolve changed
  std::vector<SeparationHold> m_separationHolds;  // see separationHolds()
  bool m_recordSeparations = false;
  // Proximity contacts kept for reuse (setBroadPhaseIsPure), with the step start and owners they
  // were found for.
  bool m_broadPhaseIsPure = false;
  bool m_proximityCached = false;
  Vec3Array m_proximityStart;
  std::vector<ContactOwner> m_proximityOwners;
  std::vector<Contact> m_proximityContacts;
  // The swept certificate (setBroadPhaseIsPure): the step start and end positions of the last
  // swept test, and 1 for the vertices of the contacts it found; m_certificateUsable: valid for
  // the resolve() under way.
  bool m_certificateValid = false;
  bool m_certificateUsable = false;
  Vec3Array m_certificateStart, m_certificateEnd;
  std::vector<char> m_certificateForced;
  std::vector<char> m_dirtyVertex, m_dirtyTriangle;  // end differs from the certificate's
};

}  // namespace weft
