// ColliderResponse: cloth against kinematic colliders (plane, sphere, capsule, box, mesh).
//
// Two mechanisms, each where it is the better tool:
//
//  1. Before an implicit step, constraints in the solve (Baraff & Witkin 1998, §5.3): a free vertex
//     whose predicted position x + h v lies within the contact thickness of a collider (at the
//     collider's pose at the end of the step), or rests on it (up to kPressedShell beyond), is
//     constrained along the contact normal n so that the step ends exactly at the thickness:
//     n·Δv = (thickness − d(x + h v)) / h. The solver then carries the contact force through the
//     cloth in the same solve, so resting contact does not jitter and a sphere pushing into a
//     curtain moves the whole curtain. A constraint may only push: the solve measures each one's
//     impulse (A Δv − b)·n and releases those that pull, then solves again (ImplicitEuler).
//  2. After every step of every integrator, a velocity-level pass in the manner of Bridson,
//     Fedkiw & Anderson 2002: a continuous test of each vertex's motion relative to each collider
//     (sphere tracing along the segment in the collider's frame, exact for the distance functions
//     the shapes return) catches vertices a fast collider would otherwise pass through; any vertex
//     within the thickness or inside, or pressed on by the solve, is put on the surface plus
//     thickness, its relative normal velocity is made non-negative (inelastic), and Coulomb
//     friction removes relative tangential velocity in proportion to the normal impulse J, the
//     solve's and this pass's: |Δv_t| ≤ μ J (coulombFriction: a contact within the cone sticks,
//     one outside it loses μ J). With `positionStep` h friction moves the position too.
//
// Why each piece (measured 2026-11-23; a 30 cm cloth on a plane tilted by θ, μ 0.3, 3 s of 1/60 s
// frames, no air drag; FrictionTest asserts it):
//  - Creep. Friction on velocities alone lets a contact that sticks move h v_t along the surface
//    in the step anyway (the solve's x = x₀ + h v is before friction): h² a_t a step whatever μ.
//    A point on a 10° incline crept 3.5 cm in 5 s of 1/240 s steps, and a cloth draped over a
//    sphere slid off it within 2–5 s (ColliderTest). resolve()'s `positionStep` (Cloth passes the
//    substep h) makes it x = x₀ + h v with the velocity after friction, along the surface, for a
//    contact that began the step on the body; one that met it in the step already ends where its
//    path relative to the body slid on from the hit (shifted as well, the sheet the stress
//    suite's 250 m/s sphere hits tore: max strain 9.1 against 0.108).
//  - The bound. The normal velocity change of the step, (v − v₀)·n, taken for J before, is not
//    the contact's impulse: a constraint in the solve cancels the forces it resists, so a cloth
//    pressed on a collider shows none, and forces pulling a vertex off a surface showed up as
//    "impulse". Cloth passes `solveImpulses` instead (DynamicSystem::receiveContactImpulses).
//    With the old bound the cloth slid 12 cm at 10°, 4.2 m at 15° (tan 15° = 0.27 < μ) and
//    12.3 m at 25° (Coulomb: 6.7 m, so μ_eff ≈ 0.1).
//  - Pressed vertices. A vertex the solve constrained ends at the thickness, where round-off
//    put some a hair outside: counted as clear they took no friction (a column of the cloth slid
//    0.22 mm a frame at 5° while the rest stuck, and the strain grew to 2 %).
//  - The pressed shell. Left to round-off (d < thickness exactly), some resting vertices were
//    constrained and their neighbours not, and the constrained ones carried their neighbours'
//    weight into their impulse (up to 5×: 0.85 m/s against h g cos θ = 0.148 on the sliding
//    cloth at 25°), so friction was uneven: 7.8 cm of creep and 3.8 % strain at 15°, 3.9 m
//    instead of 6.7 at 25°. Constraining every resting vertex gives each exactly its weight
//    (0.1482 m/s on all 121), and the cloth sticks at 10° and 15° and slides 6.76 m at 25° (μ 0:
//    18.97 m against 18.76). It needs the release above: without it the shell glued a sheet to
//    the floor (ColliderSliding: pulled up 1.5 m, strain 29).
//  - The graze. constrain() extrapolates the tangent plane where a vertex's path first came near
//    the body only when the path goes in (the end inside, on the far side, or the middle inside):
//    over a curved body that plane overshoots. A sheet vertex on top of the 15 cm withdrawing
//    sphere (ColliderSliding), which moved 6.7 cm sideways in the step, ended 1.7 cm clear but
//    was constrained 0.5 mm inside, and the solve held it against the sheet's tension with an
//    impulse of 36 m/s.
// Scenes: the drape rests on the sphere for 700 frames (its centre 1.1 cm from the pole where it
// landed, no drift from frame 100 on; before, it slid off by frame ~250). The spinning sphere
// (ColliderTest) drags the cloth to 0.079 (ratio to frictionless: 90x) against 0.158: the cloth
// lands and sticks in folds that stand up to 2.5 cm off the sphere, and the vertices within 1 cm
// of it turn at 0.38 of omega against 0.77 (0.224 and 0.76 without the pressed shell): not
// analysed to the end. Without the position step it is 0.17 and the vertices within 1.05
// thicknesses of the sphere turn at 0.78 of omega at frame 119 (0.52 with it). With it many hover
// just off the sphere, beyond the pressed shell (frame 119: 39 within 1.001 thicknesses and 105
// within 1.05, against 163 and 169): a shift along the tangent leaves a curved body by s²/2R.
// Putting the shifted vertex back at its distance raised those to 88 and 104 but the drag only to
// 0.083 (and moved the curtain's hash), so it is not the cause and is not in. The corner-crumple
// piles stand taller (tests/README.md, "friction and the piles", which says what those tests assert now): measured,
// the position step and the pressed shell each raise them, because the floor now holds. Without
// the position step the corner the cloth lands on creeps h² a_t a step and the sheet topples flat
// (3 mm) with few self-contacts; without the shell 99 % of the resting vertex-steps of the drops
// were free in the solve and ended it 3.7 mm below the thickness on average (inside the floor)
// before the response put them back: the solve saw the floor give way under the cloth. A settled
// 18 cm pile collapses to 6 mm when its floor is made frictionless and stays at μ 0.17: Coulomb's
// friction holds it.
//
// So a vertex never ends a step inside a collider, whatever the integrator. Rotation of a collider
// within one step is followed through its pose at both ends of the step (the vertex's start point
// is carried with the body), translation is linear in between.
#pragma once

#include "solver/VertexFilter.h"

#include <weft/Math.h>
#include <weft/collision/Shape.h>

#include <algorithm>
#include <optional>
#include <span>
#include <vector>

namespace weft {

/// One collider as a cloth sees it during a step.
struct ColliderFrame {
  Shape* shape = nullptr;        ///< posed at the END of the step (see setPoses)
  RigidMotion start;             ///< motion at the start of the step
  RigidMotion end;               ///< motion at the end of the step
  Real friction = 0.3;           ///< Coulomb coefficient against this cloth
};

/// Where a collider's motion puts it `dt` seconds later (constant linear and angular velocity).
RigidMotion advanceMotion(const RigidMotion& motion, Real dt);

/// Where a path first comes near a shape.
struct PathContact {
  Real s = 0;        ///< parameter along the path, 0 at its start, 1 at its end
  Vec3 point;        ///< the point of the path there
  Vec3 normal;       ///< the shape's outward normal there
  Real distance = 0; ///< m, the point's signed distance to the shape
};

/// The first point of the segment a → b (relative to the shape, i.e. a already carried with a
/// moving body) closer to the shape than `thickness`, or, for a path that starts within the
/// thickness, closer than half its start distance (so a vertex in resting contact may move in
/// the shell but not through the surface). None when the path stays clear or starts inside.
std::optional<PathContact> firstContact(const Shape& shape, const Vec3& a, const Vec3& b,
                                        Real thickness);

/// Where a vertex moving from `start` to `end` over a step ends without passing through the
/// collider (posed at the end of the step) or ending within its thickness: the path relative to
/// the body is stopped where it first meets the surface and slides on from there without its
/// inward part; what is still within the thickness goes onto it along the normal. `sweptHit`
/// tells whether the path met the surface.
Vec3 keepOutside(const ColliderFrame& collider, const Vec3& start, const Vec3& end, Real thickness,
                 bool* sweptHit = nullptr);

/// Coulomb friction on one contact: `tangential` is the velocity relative to the surface along
/// it, `normalImpulse` (m/s, ≥ 0) the normal velocity change of the step. Returns the tangential
/// velocity kept: zero when |tangential| ≤ μ · normalImpulse (it sticks), otherwise shorter by
/// μ · normalImpulse, in the same direction.
Vec3 coulombFriction(const Vec3& tangential, Real normalImpulse, Real friction);

/// Statistics of one response pass.
struct ColliderResponseReport {
  Index constrainedVertices = 0;  ///< vertices constrained in the solve
  Index contacts = 0;             ///< vertices in contact after the step
  Index sweptHits = 0;            ///< contacts found only by the continuous test
};

/// Which vertices the response left on a collider's surface, for a strain-limiting pass that
/// must not undo it (StrainLimiter::applyInContact). Sized to the vertex count by the caller.
struct ContactHolds {
  Vec3Array normals;          ///< the contact normal of a vertex on one surface, zero otherwise
  std::vector<char> fixed;    ///< 1 for a vertex on two surfaces that meet at an angle
  /// Forgets every hold (no allocation once sized).
  void clear() {
    std::fill(normals.begin(), normals.end(), Vec3::Zero());
    std::fill(fixed.begin(), fixed.end(), char(0));
  }
};

class ColliderResponse {
 public:
  /// Constrains vertices predicted to end within `thickness` of a collider (implicit solve).
  /// `pinned[i]` vertices are left alone. Returns the number constrained; their indices are kept
  /// so that the next call frees them first.
  Index constrain(std::span<const ColliderFrame> colliders, const Vec3Array& x, const Vec3Array& v,
                  Real h, Real thickness, const std::vector<char>& pinned, VertexFilter& filter);
  /// Frees the constraints constrain() set.
  void release(VertexFilter& filter);

  /// After a step from xStart to (x, v): continuous test, projection, inelastic normal velocity
  /// and friction. `vStart` is the velocity before the step (for the normal velocity change).
  /// With `holds`, every vertex it leaves in contact is recorded there (not cleared first).
  /// `friction` false runs the pass again after a first one without taking friction twice: it
  /// only projects and makes the normal velocity non-negative. `positionStep` (s) > 0 moves a
  /// contact's position by positionStep times friction's velocity change, along the surface
  /// (see the note at the top); 0 changes velocities only. `solveImpulses` (m/s by vertex, the
  /// normal velocity change the implicit solve's contact constraint gave) bounds friction with
  /// the pass's own normal change; empty: the step's normal velocity change (v − vStart)·n is
  /// taken instead (what ClothClothCollision's collider pass still does).
  ColliderResponseReport resolve(std::span<const ColliderFrame> colliders, const Vec3Array& xStart,
                                 const Vec3Array& vStart, Real thickness,
                                 const std::vector<char>& pinned, Vec3Array& x, Vec3Array& v,
                                 ContactHolds* holds = nullptr, bool friction = true,
                                 Real positionStep = 0,
                                 std::span<const Real> solveImpulses = {}) const;

 private:
  std::vector<Index> m_constrained;
};

}  // namespace weft
