// FoldCulling: decides, before a self-collision pass, that the pass cannot find anything, so it
// can be skipped without changing a bit of the result.
//
// Design note. The contact detection acts only on pairs of features that share no
// vertex and are closer than the thickness at the step start, or that meet during the step. A
// cloth can produce such a pair only where it folds back over itself. The test below proves the
// absence of folds in the manner of normal-cone culling (Volino & Magnenat-Thalmann 1994, "Efficient
// self-collision detection on smoothly discretized surface animations"), made exact:
//
//  1. Project the start positions on the plane normal to a = Σ area normals (one axis for the
//     whole cloth). Every triangle must keep its orientation (n_t · a > 0): the projection is then
//     a local homeomorphism, and for a disk-like mesh (connected, Euler characteristic 1, one
//     boundary loop: checked once) whose projected boundary is simple it is an embedding.
//  2. Separation δ: the smallest projected altitude of any triangle, and the smallest projected
//     distance between boundary features that share no vertex (boundary vertex to boundary edge,
//     found by a sweep along one axis). In an embedding, a vertex lies at least δ from every
//     feature it is not part of (the disk of radius δ around it stays in its own star or, at the
//     border, meets another part of the boundary only through a boundary edge closer than δ), and
//     the closest points of two disjoint features are a vertex of one and the other feature. So
//     every vertex–triangle and edge–edge pair the pass would test is at least δ apart, in the
//     plane and so in space.
//  3. Motion: no vertex moves more than d during the step (3D distance, hence also projected),
//     measured from a common shift of the whole cloth (which moves no feature relative to
//     another: a swinging or falling cloth moves far, its parts little against each other).
//     Features then approach by at most 2d and no triangle can flip (that needs a relative
//     motion of a full altitude), so every intermediate position is an embedding with pairs at
//     least δ − 2d apart.
//
// If δ − 2d > thickness, no pair is within the thickness at the start and none meets during the
// step: the pass would return without touching a vertex, and skipping it is exact. The test costs
// one sweep over triangles and vertices plus a sort of the boundary, against the BVH refits and
// queries of a pass. Where it fails (any fold, any dense gathering) the pass runs as usual.
#pragma once

#include <weft/Math.h>
#include <weft/engine/ClothModel.h>

#include <array>
#include <span>
#include <vector>

namespace weft {

class FoldCulling {
 public:
  /// Prepares the boundary of the model; culling is disabled for a model that is not one
  /// disk-like piece (several pieces, holes, closed surfaces), which the argument does not cover.
  explicit FoldCulling(const ClothModel& model);

  /// True when a self-collision pass over the step start → end cannot find a pair closer than
  /// `thickness` nor a crossing (see the design note). No allocation after the first call.
  bool cannotTouchItself(std::span<const Vec3> start, std::span<const Vec3> end, Real thickness);

  /// False when the model's shape rules the test out (then cannotTouchItself() is always false).
  bool applicable() const { return m_applicable; }

 private:
  const ClothModel* m_model;
  bool m_applicable = false;
  std::vector<std::array<Index, 2>> m_boundaryEdges;
  // Sweep scratch: per boundary edge its interval along the sweep axis, sorted by the lower end.
  struct Interval {
    Real low, high;
    Index edge;
  };
  std::vector<Interval> m_intervals;
};

}  // namespace weft
