// ContactDetector: finds the contacts of one substep, for every cloth of the contact space at once.
//
// Two passes. Before the implicit solve, the predicted motion x₀ + h v₀ of every vertex is traced
// against the colliders (relative to each body, from the start point carried with it): a vertex
// predicted to end within the contact shell is constrained in the solve along the contact normal
// so that the step ends at the thickness (Baraff & Witkin 1998, §5.3), and the corners of faces
// resting on a body by their interior (a towel on a rod) likewise. After the solve, the solved
// motion x₀ → x₁ gives the ContactSet the projector enforces:
//  - vertex–collider: vertices whose path or end comes within the thickness plus a margin of a
//    collider (the projector evaluates each at its current position, so the margin lets it follow
//    a vertex the projection moves towards the body);
//  - face–collider: faces whose path reaches a core of a body thinner than the triangles
//    (FaceCores.h);
//  - squeezes: where two bodies close on a vertex, or a core and another body on a face, to less
//    than the distances its contacts keep, those shrink to share the room between the bodies
//    (half each for a vertex), and the cloth is held between them (StepStatus::Squeezed);
//  - vertex–face and edge–edge pairs, within a cloth and between cloths: one broad phase over
//    the swept boxes (FeaturePairs), the closest points at both ends, a pair closer than its
//    thickness at either end being a contact (Bridson, Fedkiw & Anderson 2002, §7.2). The weights
//    and normal are those of the nearer end, oriented to the side the pair started on, which x₀
//    (free of crossings) tells. Features closer than the thickness in the rest shape of one cloth
//    are neighbours in the material and never a contact.
// The collider queries (per vertex, per face) and the exact pair tests run in parallel over fixed
// blocks; contacts are listed in vertex, face and pair order, so the set is the same on any thread
// count.
#pragma once

#include "contact/ColliderFrame.h"
#include "contact/ContactSet.h"
#include "contact/ContactSpace.h"
#include "contact/FeaturePairs.h"
#include "contact/OrderedPairFilter.h"

#include <weft/collision/Proximity.h>
#include <weft/threading/PerWorker.h>
#include <weft/threading/TaskSystem.h>

#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace weft {

/// A pair that starts a substep closer than its thickness is asked back this fraction of the way
/// to it in the substep (Bridson, Fedkiw & Anderson 2002's repulsion rate), by the projection and
/// by the solve's penalty alike.
inline constexpr Real kRepulsionRate = 0.1;

/// A constraint of the implicit solve: the velocity change of `vertex` along `normal` is fixed
/// to `normalChange` (m/s), so that its predicted motion ends at the contact distance.
struct SolveConstraint {
  Index vertex = 0;  ///< of the contact space
  Vec3 normal = Vec3::Zero();
  Real normalChange = 0;
  Index collider = kInvalidIndex;  ///< the collider, or kFaceCornerConstraint
};

/// SolveConstraint::collider of a face corner's constraint, and the per-vertex marker detect()
/// reads for it.
inline constexpr Index kFaceCornerConstraint = kInvalidIndex - 1;

/// A face point resting on a core at the end of a substep, whose corners the next solve holds.
struct FaceSupport {
  std::array<Index, 3> corners{};
  Vec3 barycentric = Vec3::Zero();
  Vec3 normal = Vec3::Zero();  ///< world, from the core to the face
  Real level = 0;              ///< m: the face point must keep normal · point ≥ level
};

/// What detection found, for the step's statistics.
struct DetectionCounts {
  Index colliderPairsTested = 0;   ///< vertex sets tested against a collider's box hit
  Index colliderPairsSkipped = 0;  ///< colliders whose box missed the cloth's
  Index squeezedVertices = 0;      ///< vertices between two colliders with too little room
};

class ContactDetector {
 public:
  /// Builds the broad-phase tables of `space` (when its cloths change).
  void build(const ContactSpace& space, TaskSystem* tasks);
  /// `skip`: WorldSettings::skipUnneededStages; off, every collider is tested, near or not.
  void setSkipping(bool skip) { m_skip = skip; }
  /// Leaves of the broad phase keep their boxes while their triangles move less than this (m).
  void setRefitMargin(Real margin) { m_features.setRefitMargin(margin); }
  /// The solve's constraints for the predicted motion x₀ + h v₀ (space.startX, startV) against
  /// `colliders`, and for the corners of `supports` (faces resting on a body), into `out`
  /// (cleared first), by vertex.
  void constrain(const ContactSpace& space, std::span<const ColliderFrame> colliders, Real h,
                 std::span<const FaceSupport> supports, std::vector<SolveConstraint>& out,
                 DetectionCounts& counts);
  /// The contacts of the solved motion space.startX → space.x into `set` (cleared first).
  /// `solveImpulses` (m/s per vertex) and `constrainedCollider` (per vertex: the collider,
  /// kFaceCornerConstraint, or kInvalidIndex: none) say what the solve's constraints did. `pairs`: detect cloth pairs (false when no
  /// cloth can touch itself or another this substep). `margin` (m): how far beyond its thickness
  /// a vertex may be from a collider and still be a contact.
  void detect(const ContactSpace& space, std::span<const ColliderFrame> colliders,
              std::span<const Real> solveImpulses, std::span<const Index> constrainedCollider,
              bool pairs, Real margin, ContactSet& set, DetectionCounts& counts);

  /// The feature pairs of the last detect() (over x₀ → x with pairMargin()).
  const FeaturePairs& featurePairs() const { return m_features; }
  Real pairMargin() const { return m_pairMargin; }

  /// Broad-phase nodes refit and kept since the last call.
  Bvh::RefitCounts takeRefitCounts() { return m_features.takeRefitCounts(); }

 private:
  void detectColliderVertices(const ContactSpace& space, std::span<const ColliderFrame> colliders,
                              std::span<const Real> solveImpulses,
                              std::span<const Index> constrainedCollider, Real margin,
                              ContactSet& set, DetectionCounts& counts);
  void detectColliderFaces(const ContactSpace& space, std::span<const ColliderFrame> colliders,
                           std::span<const Real> solveImpulses,
                           std::span<const Index> constrainedCollider, Real margin,
                           ContactSet& set);
  // The room (m) between the body of contact `from` (`surfaceNormal`: its normal at the point
  // nearest vertex position `x`) and that of `to`, across from that point; infinite when `to`'s
  // surface there does not face it back.
  static Real roomAcross(std::span<const ColliderFrame> colliders, const Vec3& x,
                         const Contact& from, const Vec3& surfaceNormal, const Contact& to);
  // Where another body faces the face of contact `face` back across it, nearer the core point
  // (`corePoint` and `normal`, core to face, world) than the core's reach and the `thickness` its
  // corners keep: shortens the reach, and the corners' separations from both bodies, to fit.
  void squeezeFace(std::span<const ColliderFrame> colliders, const Contact& face,
                   const Vec3& corePoint, const Vec3& normal, Real thickness,
                   ContactSet& set) const;
  void detectPairs(const ContactSpace& space, ContactSet& set);
  // What a vertex's solved end and path show of one collider (detectColliderVertices()).
  struct VertexQuery {
    std::optional<ShapeContact> end;  // the end's contact; none: no contact
    std::optional<PathContact> hit;   // where the path met the body, for an end beyond the margin
    bool resting = false;             // the start pressed on the body
  };
  // Vertex i's contact with `collider`: its end within thickness + `margin` or its path hitting.
  static VertexQuery queryVertex(const ContactSpace& space, const ColliderFrame& collider,
                                 Real margin, Index i);
  // A core of a collider that a face may touch (detectColliderFaces()).
  struct FaceCandidate {
    Index face;
    FaceCore core;                       // body frame
    SegmentTriangleClosestPoints before;  // core to the face at its start: the side it came from
  };
  // One fixed block of faces: what it found and its scratch.
  struct FaceBlock {
    std::vector<FaceCandidate> found;
    std::vector<FaceCore> cores;
    std::vector<Index> triangles, edges;
  };
  // Appends to block.found the cores of `collider` that face `face` may touch over the substep.
  // `body`: the collider's world box.
  void findFaceCores(const ContactSpace& space, const ColliderFrame& collider, const Aabb& body,
                     Real margin, Index face, FaceBlock& block) const;
  // A vertex's deepest contact with a collider for the solve (constrain()).
  struct DeepestContact {
    Vec3 normal = Vec3::Zero();
    Real depth = 0;                  // m, signed distance at the predicted end
    Index collider = kInvalidIndex;  // none: no contact
  };
  // Vertex i's deepest contact over the near colliders at its predicted end, m_predicted[i].
  DeepestContact deepestContact(const ContactSpace& space,
                                std::span<const ColliderFrame> colliders, Index i) const;
  // fn(begin, end) for each fixed block [k·grain, min((k+1)·grain, count)), on the tasks when
  // there are any, in order on the caller otherwise: for the per-vertex and per-face collider
  // queries, each block writing only its own slots.
  template <class Fn>
  void forEachBlock(Index count, Index grain, Fn&& fn);
  // The colliders whose box comes near the cloth's motion, into m_near; counts both kinds.
  void selectNear(const ContactSpace& space, std::span<const ColliderFrame> colliders,
                  const Vec3Array& end, Real margin, DetectionCounts& counts);

  TaskSystem* m_tasks = nullptr;
  bool m_skip = true;
  Real m_pairMargin = 0;  // of the last detectPairs()
  FeaturePairs m_features;
  std::vector<Index> m_near;  // colliders near the cloth this pass
  std::vector<std::size_t> m_vertexContacts;  // per vertex + 1: its first collider contact
  std::vector<Vec3> m_surfaceNormals;  // the current vertex's contacts: the bodies' normals at it
  OrderedPairFilter<Contact> m_pairFilter;
  std::vector<FaceBlock> m_faceBlocks;  // per fixed block of faces, detectColliderFaces()
  Vec3Array m_predicted;            // x₀ + h v₀, constrain()
  std::vector<char> m_constrained;  // per vertex: constrained by constrain() already
  std::vector<DeepestContact> m_deepest;  // per vertex, constrain()
  std::vector<VertexQuery> m_vertexQueries;  // per vertex × near collider, detect()
};

}  // namespace weft
