// SelfCollision: keeps a cloth from passing through itself, in the manner of Bridson, Fedkiw &
// Anderson 2002 ("Robust treatment of collisions, contact and friction for cloth animation").
//
// It runs after the integrator, on the step's start positions x₀ and the candidate average
// velocity v̄ = (x₁ − x₀)/h the integrator produced, and changes only v̄:
//
//  1. Proximity (BFA02 §7.2): vertex–triangle and edge–edge pairs closer than the thickness at x₀
//     get an inelastic impulse (no approach) plus a repulsion that pushes them apart by a tenth
//     of the overlap per step, and Coulomb friction on the relative tangential velocity.
//  2. Continuous detection (§7.1): the swept motion x₀ → x₀ + h v̄ of every candidate pair from
//     the BVH (refit to the swept boxes) is tested for the first time of coplanarity; each hit
//     gets an impulse that leaves the pair separating. Repeated a bounded number of passes.
//  3. Fail-safe (§7.3): pairs still colliding merge into rigid impact zones whose vertices move
//     with one rigid motion (momentum and angular momentum kept), repeated until clean; if even
//     that does not clear them, the zone's vertices keep their start positions (v̄ = 0), which
//     cannot cross since x₀ is free of crossings. So no crossing survives a step.
//
// Impulses are shared among the four vertices of a pair by their barycentric weights w and
// inverse masses (pinned vertices have none): Δv_i = w_i λ n / m_i with λ chosen so that the
// relative normal velocity changes by exactly the asked amount. Pairs are processed in sorted
// order, one after the other (Gauss–Seidel), so the result is deterministic.
#pragma once

#include <weft/Math.h>
#include <weft/collision/Bvh.h>
#include <weft/engine/ClothModel.h>
#include <weft/threading/PerWorker.h>
#include <weft/threading/TaskSystem.h>

#include <array>
#include <memory>
#include <vector>

namespace weft {

/// What one self-collision pass did.
struct SelfCollisionReport {
  Index proximityContacts = 0;  ///< pairs closer than the thickness at the step start
  Index impacts = 0;            ///< swept collisions resolved by impulses
  Index impactZones = 0;        ///< rigid impact zones formed (fail-safe)
  Index frozenVertices = 0;     ///< vertices held at their start (last resort)
};

class SelfCollision {
 public:
  /// Builds the BVH and the edge tables of the model. BVH refits and queries run on `tasks`
  /// (null: serial), with the same results either way.
  explicit SelfCollision(const ClothModel& model, TaskSystem* tasks = nullptr);

  /// Adjusts the step x₀ → x₁ (positions) and v (velocities, set to the average velocity of the
  /// corrected step) so that the cloth neither ends closer than `thickness` to itself where it
  /// can be pushed apart nor passes through itself. `inverseMasses` are 0 for pinned vertices.
  SelfCollisionReport resolve(const Vec3Array& start, Real h, Real thickness, Real friction,
                              const std::vector<Real>& inverseMasses, Vec3Array& x, Vec3Array& v);

 private:
  // A pair of features as four vertices with weights: vertex–triangle (p; a, b, c) has
  // w = (1, −b₀, −b₁, −b₂); edge–edge (p0, p1; q0, q1) has w = (1 − s, s, −(1 − u), −u). The
  // relative velocity is Σ w_i v_i, positive along the normal when separating.
  struct Contact {
    std::array<Index, 4> vertices;
    std::array<Real, 4> weights;
    Vec3 normal;
    Real gap = 0;  // m, distance at the step start (proximity only)
  };

  // Vertex–triangle and edge–edge pairs of the candidate triangle pairs whose own boxes (over
  // positions `from` and `to`, one side inflated by `margin`) overlap; sorted and unique.
  void collectFeaturePairs(const Vec3Array& from, const Vec3Array& to, Real margin);
  bool findImpacts(const Vec3Array& start, Real h);
  void applyImpulse(const Contact& contact, Real targetNormalSpeed, Real friction,
                    const std::vector<Real>& inverseMasses);
  void rigidifyZones(const Vec3Array& start, const std::vector<Real>& inverseMasses);
  void refitAndQuery(const Vec3Array& from, const Vec3Array& to, Real inflate);

  Vec3Array m_rest;  // rest positions: features closer than the thickness at rest never repel
  Bvh m_bvh;
  TaskSystem* m_tasks = nullptr;
  std::unique_ptr<PerWorker<std::vector<TrianglePair>>> m_workerPairs;  // with m_tasks
  std::vector<std::array<Index, 3>> m_triangleEdges;  // edge ids of each triangle
  std::vector<std::array<Index, 2>> m_edges;          // vertex ids of each edge
  Vec3Array m_velocity;                               // v̄ being corrected
  Vec3Array m_end;                                    // x₀ + h v̄
  std::vector<TrianglePair> m_trianglePairs;
  std::vector<std::array<Index, 2>> m_vertexTriangle;  // (vertex, triangle), sorted, unique
  std::vector<std::array<Index, 2>> m_edgeEdge;        // (edge, edge), sorted, unique
  std::vector<Contact> m_contacts;
  std::vector<Index> m_zoneParent;  // union–find over vertices for impact zones
  std::vector<char> m_inZone;       // 1 for vertices some impact zone holds
  std::vector<char> m_touched;      // 1 for vertices whose velocity this pass changed
};

}  // namespace weft
