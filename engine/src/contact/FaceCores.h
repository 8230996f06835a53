// FaceCores: keeping the faces of a cloth, not only its vertices, out of bodies thinner than its
// triangles (a rod, a plank, a mesh's edge), where a body could pass between the vertices.
//
// Each body is reduced to cores, segments in its own frame that faces keep a reach away from: a
// sphere's centre (a segment of length 0) and a capsule's axis, reach = radius − allowance (at
// least allowance / 2, for a body thinner than that); a box's twelve edges, reach = allowance / 2
// (a flat face of a body cannot pass between the vertices, its edges can). The allowance is the
// contact thickness: the vertices keep it outside, and a coarse mesh over a curved body sags
// between them by l² / (8 R), so a round body's core stays that far inside, and ordinary draping
// makes no face contact at all. Half of it for box edges keeps a face on its side of an edge it
// bends round, with room to tell the side at the next substep.
//
// A mesh's cores are the edges near the face where the surface bulges more than allowance / 2
// into a face of its extent (MeshEdge::bulge: a ridge's turn, or turns adding up over narrow
// triangles as a curve's sag), and the vertices that peak that much, reach = allowance / 4. Over
// the others a face whose corners keep the allowance stays twice that reach away, so a smooth
// region (a character's torso, a finely meshed ball) makes no face contacts, while a rod, a
// crease or a fingertip thinner than the face does. Rejected: every edge near the face (tens of
// contacts per face on a fine mesh, each tested every projection sweep), a fixed angle threshold
// (a rod of many narrow sides turns little at each edge).
//
// Contact points of a face and a core (facePoints), in the body's frame: over the face's interior,
// the part of the core inside the triangle's prism is a line whose height over the face is
// linear, so its two ends are the deepest points (a rod lying along a face touches it along a
// line); beside the face, the closest points of the segment and the triangle. Over the interior a
// line core pushes across itself: the contact normal is the face's normal without its part along
// the core, as a cylinder's surface normal is, so a face lying tilted along a rod is not pushed
// along the rod. A point short of its reach is moved out by moving the three corners, each by its
// barycentric weight b_k and inverse mass w_k: Δx_k = b_k w_k / (Σ_j b_j² w_j) · depth · n, which
// moves the face point by exactly depth · n (Bridson, Fedkiw & Anderson 2002's distribution, the
// body infinitely heavy).
//
// Which side: a face that crossed a core within the substep goes back to the side it came from,
// the normal of the closest points at the substep start in the body's start frame. Over the
// face's interior that normal decides only when it leans out of the face's plane: a face that
// came from beside a core (a box's vertical edge beside a sheet squeezed under the box) has no
// side along its normal to go back to, and is kept on the side each core point is on, not sent
// the length of the core to its far end.
#pragma once

#include <weft/Math.h>
#include <weft/collision/Aabb.h>
#include <weft/collision/RigidMotion.h>
#include <weft/collision/Shape.h>

#include <array>
#include <span>
#include <vector>

namespace weft {

/// A segment in a body's frame (a point when both ends are equal) that faces keep `reach` (m)
/// away from: a sphere's centre, a capsule's axis, an edge of a box or a mesh.
struct FaceCore {
  Vec3 start = Vec3::Zero();
  Vec3 end = Vec3::Zero();
  Real reach = 0;
  Aabb box;  ///< the segment's box inflated by the reach: where a face can touch it
};

/// A core from `start` to `end` kept `reach` away from, with its box.
FaceCore makeCore(const Vec3& start, const Vec3& end, Real reach);

/// Appends the cores of a sphere, capsule or box (body frame) for contact allowance `allowance`
/// (m); a plane has none, a mesh's are its edges near each face (appendMeshCores).
void appendCores(const Shape& shape, Real allowance, std::vector<FaceCore>& cores);

/// Appends the edges of `mesh` whose triangles' boxes meet `near` (body frame), each once, as
/// cores of reach allowance / 4, but only those where the surface bulges more than allowance / 2
/// into a face of extent `span` (m; MeshEdge::bulge). `scratch` is reused working memory.
void appendMeshCores(const TriangleMeshShape& mesh, const Aabb& near, Real allowance, Real span,
                     std::vector<FaceCore>& cores, std::vector<Index>& triangleScratch,
                     std::vector<Index>& edgeScratch);

/// A point where a face meets a core, in the body's frame: the face point (barycentric weights),
/// the unit normal from the core to the face, the core point, and how far the face point must
/// move along the normal to be `reach` from the core (≤ 0: it is).
struct FacePoint {
  Vec3 barycentric = Vec3::Zero();
  Vec3 normal = Vec3::Zero();
  Vec3 corePoint = Vec3::Zero();
  Real depth = 0;
};

/// The contact points of face (a, b, c) with `core` (body frame), at most three, into `points`;
/// returns how many are deeper than `minDepth`. `cameFrom`: the core-to-face normal at the
/// substep start (zero if unknown).
int facePoints(const FaceCore& core, const Vec3& cameFrom, const Vec3& a, const Vec3& b,
               const Vec3& c, Real minDepth, std::array<FacePoint, 3>& points);

/// True when face (a, b, c) is provably clear of the core (body frame): facePoints with the same
/// `cameFrom` would find no point deeper than 0. A cheap test (a separating direction, boxes,
/// the face's plane) that spares the exact one for the many cores a face lies clear of.
bool faceClearOfCore(const FaceCore& core, const Vec3& cameFrom, const Vec3& a, const Vec3& b,
                     const Vec3& c);

/// True when every point of face (a, b, c) is provably farther than `distance` (m) from the
/// core (body frame), by the boxes' gap or the gap along `direction` (zero: boxes only).
bool faceFartherThan(const FaceCore& core, const Vec3& direction, const Vec3& a, const Vec3& b,
                     const Vec3& c, Real distance);

/// Σ b_k² w_k over a face's corners: the inverse mass of a face point against an immovable body.
Real pointInverseMass(const Vec3& b, const std::array<Index, 3>& corner,
                      std::span<const Real> inverseMasses);

/// Pushes each point where the face of `corner` is short of its reach from `core` out to it, one
/// after the other, each seeing the face where the last push left it (the body posed at
/// `endPose`); each shift Δx is also made as the velocity change Δx · inverseStep in `v`. Every
/// contact point is listed, shallow ones too, so that the list recomputed after a push
/// enumerates the same points in the same order. Returns the largest depth pushed (m, 0: none)
/// and sets `normal` (world) to that point's direction.
Real pushFaceOut(const FaceCore& core, const Vec3& cameFrom, const Pose& endPose,
                 const std::array<Index, 3>& corner, std::span<const Real> inverseMasses,
                 std::span<Vec3> x, std::span<Vec3> v, Real inverseStep, Vec3& normal);

}  // namespace weft
