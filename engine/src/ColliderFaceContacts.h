// ColliderFaceContacts: keeps the faces of a cloth, not only its vertices, out of spheres,
// capsules, boxes and triangle meshes.
//
// Design note ----------- Why: ColliderResponse keeps every vertex outside every collider (plus the
// contact thickness), but a triangle is more than its corners. Where a body is thinner than the
// cloth's triangles — a capsule of 2 cm radius or a 2 cm plank under edges of 3–5 cm — the body
// passes between the vertices through a face while every vertex stays outside. Measured: a 0.5 m
// cotton square of 11 × 11 vertices dropped onto a rod of 2 cm radius, or onto a plank 2 cm square
// in section (a box or a triangle mesh), fell straight through it (ColliderFaceContactsTest); in
// stress scene 7 (three sheets pushed through a ring of capsules) the worst edges ran straight
// through a capsule of the ring, one end inside the ring and one outside, with a face at the
// capsule's core in 33–44 of the 150 frames.
//
// What: each body is reduced to cores, segments in its frame that faces keep a reach away from: a
// sphere's centre (a segment of length 0) and a capsule's axis, reach = radius − allowance (at
// least allowance / 2, for a body thinner than that); a box's twelve edges and a mesh's edges near
// the face (found in its tree per face), reach = allowance / 2 (a flat face of a body cannot pass
// between the vertices; its edges can). Cloth passes the contact thickness as the allowance. Why an
// allowance for round bodies: the vertices keep the thickness outside, and a coarse mesh over a
// curved body sags between them by l² / (8 R) (3.8 mm for 5 cm edges on the 8 cm pusher of stress
// scene 7); pushing those faces out would lift the vertices off wherever a coarse mesh lies on a
// curved body and change ordinary draping for nothing, while a face that a thin body passes through
// is caught long before the core. With it the curtain has no face contact at all (its state hash is
// unchanged). Why half of it for box edges: a face resting on a box's flat face is a thickness from
// its edges; half keeps it on its side of an edge it bends round, with room to tell the side at the
// next step.
//
// Contact points of a face and a core (facePoints), in the body's frame: over the face's interior,
// the part of the core inside the triangle's prism is a line whose height over the face is
// linear, so its two ends are the deepest points (a box edge or a capsule parallel to the face
// touches it along a line; the kernel's single closest point, on the face's edge, pushed one end
// of that line and tilted the face about the other); beside the face, the closest points of the
// segment and the triangle (Proximity.h) when they lie on the face's boundary. Over the interior
// the contact normal of a line core (a capsule's axis, a box's edge) is the face's normal without
// its part along the core, as a cylinder's surface normal is: a face lying tilted along a rod was
// pushed along its own normal, which leans along the rod, and every push moved it along the rod
// (with the sinking below, a towel resting on a rod rode along it at 9.5 cm/s and fell off its
// end; scenes/data/rod-hang.json). A face point short of the reach is moved out along the
// contact normal, lifting the face's plane there by the height it lacks, by moving the three
// corners, each by its
// barycentric weight b_k and inverse mass w_k: Δx_k = b_k w_k / (Σ_j b_j² w_j) · depth · n, which
// moves the face point by exactly depth · n (the impulse distribution of Bridson, Fedkiw &
// Anderson 2002 for a point–triangle contact, with the body infinitely heavy). Contacts are
// resolved one after the other in triangle order (Gauss–Seidel; serial, so the same bits on any
// thread count) and swept again while a sweep still moved a face, four times at most
// (neighbouring faces share corners). Cloth then runs the vertex pass once more, so that the
// vertices keep the last word (a corner pushed out of one body can land in another).
//
// Which side: a face that crossed a core within the step (its normal now points through the
// body, or it lies on the core) goes back to the side it came from: the normal of the closest
// points at the step start, in the body's start frame, as the vertices' continuous test sends
// them. Such a face is in contact however far past the core it went (a box edge has no radius to
// catch it by), so the candidates are the faces whose path over the step, start and end, reaches
// a core's box (a sheet falling at 1.4 m/s moves 2.3 cm a step, past a 2 cm plank).
//
// After the sweeps, once: every face point in contact, and every point of a face the sweeps
// pushed, keeps no velocity into the body (inelastic, relative to the body's surface there;
// removed in every sweep, the pushes of the successive contacts of one face added up and the
// face left faster than the body: a rod rising at 1.8 m/s into a face sent its corners off at up
// to 2.5 m/s), and is held one-sided in the strain limiter in contact (holds(): n · Σ b_k x_k ≥
// n · c + reach, c the core point), as it holds heavy self-contacts, so that its rounds slide the
// cloth round the body instead of pulling the face back into it (on the rod of the test, max
// strain 0.101 with the holds, 0.103 without).
//
// In the solve: Cloth constrains the corners of the faces a pass left on a body along the contact
// normal in the next implicit solve (Cloth::constrainFaceCorners), so that a face carrying the
// cloth's weight does not sink h² g a step into the body for this pass to push back out (the
// floor that gave way in the solve, for faces: ColliderResponse.h). On the rod of the tests, over
// the last 20 of 40 s, the towel moved 5 µm along the rod with the constraints and 1.9 cm
// without; without the faces' friction as well, it slid round the rod and fell off.
//
// Friction, in the step's first pass only (as the vertex pass takes it), at the corners of the
// touching faces, each corner once: its tangential velocity relative to the body (along the
// normal of its first touching face point) is cut by μ times its normal velocity change in the
// step, the solve's constraint's and this pass's share (coulombFriction), and with
// `positionStep` its position moves by the same change times the step, so that a sticking face
// does not creep. Only faces that began the step on the body (within 1 % of the allowance beyond
// the reach) take friction: resting contact, which is what holds a towel on a rod. A face that
// meets a body within the step leaves friction to its vertices: the stress suite's 250 m/s
// sphere, which meets its sheet within a step, tore it when such faces were shifted by friction
// (strain 2.7, and the sheet passed it) and stretched it to 0.1108 when they only took its
// velocity change (0.109 without). Taken per face point instead, with the point's change spread
// over the corners by barycentric weight, the points of neighbouring faces each moved a shared
// corner by the whole of their own correction. A corner resting on the body itself is a vertex
// contact and takes friction in the vertex pass only: taken here again (bounded by its vertex
// constraint's impulse, and moved along the face's tangent plane, not the body's surface there),
// it lifted the bottom of two layers draped over a sphere 1.1 cm off it (ClothClothTest).
//
// Not covered: a mesh's vertices poking into a face without an edge crossing it (a spike narrower
// than the triangles), and a face inside a body at both ends of a step with no side to return to.
#pragma once

#include "ColliderResponse.h"
#include "StrainLimiting.h"

#include <weft/Math.h>
#include <weft/collision/Aabb.h>
#include <weft/engine/ClothModel.h>

#include <span>
#include <utility>
#include <vector>

namespace weft {

/// A segment in a body's frame (a point when both ends are equal) that faces keep `reach` (m)
/// away from: a sphere's centre, a capsule's axis, an edge of a box or a mesh.
struct FaceCore {
  Vec3 start = Vec3::Zero();
  Vec3 end = Vec3::Zero();
  Real reach = 0;
  Aabb box;  ///< the segment's box inflated by the reach (at least 0): where a face can touch it
};

/// What one resolve() did.
struct ColliderFaceReport {
  Index contacts = 0;  ///< faces pushed out of a body (a face and a core: one contact)
  Index sweeps = 0;    ///< sweeps over the contacts (the first included)
};

/// Keeps cloth faces out of sphere, capsule, box and triangle-mesh colliders (see the design
/// note).
class ColliderFaceContacts {
 public:
  /// Moves faces of `triangles` that are within reach of a core of a sphere, capsule, box or mesh
  /// (see the design note; `allowance` in m, Cloth passes the contact thickness) back out of it,
  /// and removes their velocity into the body. `xStart`: positions at the step start (which
  /// side a face came from). Vertices with inverse mass 0 (pins) are not moved. `friction`:
  /// each face point whose approach velocity was removed also takes Coulomb friction against the
  /// body (ColliderFrame::friction), bounded by that normal velocity change; `positionStep` (s)
  /// > 0 moves its position by positionStep times friction's velocity change as well, as the
  /// vertex pass does (ColliderResponse::resolve). A later pass in the same step passes false.
  /// `solveImpulses` (m/s by vertex, may be empty): the normal velocity change the implicit
  /// solve's contact constraints gave the corners (Cloth::constrainFaceCorners), which the bound
  /// takes with the pass's own, weighted as the face point weights its corners.
  ColliderFaceReport resolve(std::span<const ColliderFrame> colliders,
                             std::span<const TriangleRest> triangles, const Vec3Array& xStart,
                             std::span<const Real> inverseMasses, Real allowance, Vec3Array& x,
                             Vec3Array& v, bool friction = false, Real positionStep = 0,
                             std::span<const Real> solveImpulses = {});

  /// One sweep over the face–core pairs the last resolve() found (same `colliders` and
  /// `triangles`) at the current x: each face point short of its reach is moved back to it as
  /// resolve() does, the move also made as the velocity change Δx · inverseStep. Returns how many
  /// face points were deeper than `tolerance` (m). For the strain limiter's joint iteration
  /// (ColliderProjection); finds no new pair.
  Index project(std::span<const ColliderFrame> colliders, std::span<const TriangleRest> triangles,
                std::span<const Real> inverseMasses, Real inverseStep, Real tolerance,
                std::span<Vec3> x, std::span<Vec3> v) const;

  /// The contacts of the last resolve() as one-sided holds for the strain limiter.
  std::span<const SeparationHold> holds() const { return m_holds; }

  /// Forgets the holds (a step without colliders).
  void clear() { m_holds.clear(); }

 private:
  struct Candidate {
    Index triangle = 0;
    Index collider = 0;
    Index core = 0;                // into m_cores
    Vec3 cameFrom = Vec3::Zero();  // body frame: the core-to-face normal at the step start
    bool pushed = false;           // moved by a sweep of this resolve()
    bool startedOn = false;        // within its reach of the core at the step start (at rest on it)
  };
  std::vector<FaceCore> m_cores;         // every body's cores, this resolve()
  std::vector<Index> m_meshTriangles;    // a mesh's triangles near one face
  std::vector<std::pair<Index, Index>> m_meshEdges;  // their edges, each once
  std::vector<Candidate> m_candidates;  // a face and a core it may touch, this resolve()
  std::vector<SeparationHold> m_holds;
  // Friction is taken at the corners of the touching faces, each corner once (see the note).
  struct FrictionCorner {
    Index vertex = 0;
    Vec3 normal = Vec3::Zero();        // of its first touching face point
    Vec3 bodyVelocity = Vec3::Zero();  // of that body at the corner
    Real friction = 0;                 // that body's coefficient
    Real normalChange = 0;             // m/s: the solve's and the pass's, for the face contacts
  };
  std::vector<Index> m_cornerSlot;  // by vertex: into m_frictionCorners, or kInvalidIndex
  std::vector<FrictionCorner> m_frictionCorners;
};

}  // namespace weft
