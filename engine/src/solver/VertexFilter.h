// VertexFilter: the per-vertex filter S and target z of Baraff & Witkin 1998, §5.3.
//
// Design note.
// BW98 enforce pins and contacts inside the linear solve rather than by penalty forces: every
// vertex i has a 3×3 projection S_i onto the directions in which its velocity change Δv_i is free,
// and a target z_i that fixes Δv_i in the others. With p, q orthonormal constraint directions:
//
//     free                   S_i = I                 Δv_i unconstrained
//     one direction  (p)     S_i = I − p pᵀ          pᵀΔv_i = pᵀz_i      (contact with one surface)
//     two directions (p, q)  S_i = I − p pᵀ − q qᵀ   also qᵀΔv_i = qᵀz_i (a crease, two surfaces)
//     fixed                  S_i = 0                 Δv_i = z_i          (pins, scripted vertices)
//
// The solver (FilteredPcg) keeps every iterate of the form S·y + (I − S)z, so only the constrained
// part (I − S_i)z_i of a target matters. target() returns exactly that part: components of z
// along free directions are dropped when a constraint is set.
//
// Storage: one byte of kind per vertex plus dense per-vertex targets and directions. The kind
// byte makes a free vertex cost one load and one branch in every filtered kernel; the dense
// arrays mean constraints can change every step (contacts come and go) with no allocation, which
// a sparse side table of constrained vertices would need when it grows. Rejected: one Mat3 S_i per
// vertex (72 bytes read per vertex per kernel for what is the identity almost everywhere).
#pragma once

#include <weft/Math.h>

#include <array>
#include <cstdint>
#include <vector>

namespace weft {

/// How many directions of a vertex's velocity change are prescribed; the value is that count.
enum class ConstraintKind : std::uint8_t {
  Free = 0,           ///< S = I
  OneDirection = 1,   ///< S = I − p pᵀ
  TwoDirections = 2,  ///< S = I − p pᵀ − q qᵀ, p ⟂ q
  Fixed = 3,          ///< S = 0
};

/// The BW98 filter S and target z, per vertex.
class VertexFilter {
 public:
  /// Sets the vertex count and makes every vertex free. Allocates when the count grows.
  void resize(Index vertexCount);

  /// Makes every vertex free (the start of each step's constraint gathering); no allocation.
  void setAllFree();

  /// Number of vertices.
  Index size() const { return static_cast<Index>(m_kinds.size()); }

  /// Number of vertices that are not free.
  Index constrainedVertexCount() const { return m_constrainedVertexCount; }

  /// Removes any constraint from a vertex: S_i = I, target 0.
  void setFree(Index vertex);

  /// Prescribes the whole velocity change of a vertex: S_i = 0, Δv_i = target (m/s), exactly.
  void setFixed(Index vertex, const Vec3& target);

  /// Prescribes the velocity change along one direction (any nonzero length; normalised here):
  /// S_i = I − p pᵀ with p = direction/‖direction‖, and pᵀΔv_i = pᵀtarget. A zero or non-finite
  /// direction is a caller bug: asserted, and the vertex is left free in release builds.
  void setConstrained(Index vertex, const Vec3& direction, const Vec3& target);

  /// Prescribes the velocity change along two directions; direction1 is made orthogonal to
  /// direction0 (Gram–Schmidt), and both are normalised. When the two are parallel (sine of the
  /// angle below kParallelSine) the second adds nothing and the one-direction filter is used.
  void setConstrained(Index vertex, const Vec3& direction0, const Vec3& direction1,
                      const Vec3& target);

  /// Gives `vertex` exactly the constraint (kind, directions, target) that `from` holds for
  /// `fromVertex`, bit for bit: renumbers constraints gathered by vertex into system rows.
  void copyConstraint(Index vertex, const VertexFilter& from, Index fromVertex);

  /// The vertex's kind of constraint.
  ConstraintKind kind(Index vertex) const { return static_cast<ConstraintKind>(m_kinds[vertex]); }

  /// Number of prescribed directions: 0 (free), 1, 2 or 3 (fixed).
  int constrainedCount(Index vertex) const { return static_cast<int>(m_kinds[vertex]); }

  /// The constrained part (I − S_i) z_i of the target, m/s; zero for free vertices.
  const Vec3& target(Index vertex) const { return m_targets[vertex]; }

  /// Unit constraint direction k (0 or 1) of a vertex; meaningful for k < constrainedCount() ≤ 2.
  const Vec3& direction(Index vertex, int k) const { return m_directions[vertex][k]; }

  /// S_i v for one vertex. Fixed vertices return exact zeros (not 0·v), so a NaN in a fixed
  /// vertex's row cannot leak into the solve. Always inlined: the PCG's sweeps call it per row.
  [[gnu::always_inline]] Vec3 filter(Index vertex, const Vec3& v) const {
    switch (static_cast<ConstraintKind>(m_kinds[vertex])) {
      case ConstraintKind::Free:
        return v;
      case ConstraintKind::OneDirection: {
        const Vec3& p = m_directions[vertex][0];
        return v - p * p.dot(v);
      }
      case ConstraintKind::TwoDirections: {
        const Vec3& p = m_directions[vertex][0];
        const Vec3& q = m_directions[vertex][1];
        return v - p * p.dot(v) - q * q.dot(v);
      }
      case ConstraintKind::Fixed:
        break;
    }
    return Vec3::Zero();
  }

  /// The 3×3 projection S_i of a vertex.
  Mat3 projection(Index vertex) const;

  /// out = S·in over all vertices. in and out may be the same array.
  void apply(const Vec3Array& in, Vec3Array& out) const;

  /// out[i] = S_i in[i] for i in [begin, end); other entries untouched. in and out may alias.
  void applyRange(Index begin, Index end, const Vec3Array& in, Vec3Array& out) const;

  /// Below this sine of the angle between two directions they count as parallel.
  static constexpr Real kParallelSine = 1e-6;

 private:
  /// Records a kind change of one vertex, keeping constrainedVertexCount() exact.
  void setKind(Index vertex, ConstraintKind kind);

  std::vector<std::uint8_t> m_kinds;               ///< ConstraintKind per vertex
  Vec3Array m_targets;                             ///< (I − S_i) z_i per vertex, m/s
  std::vector<std::array<Vec3, 2>> m_directions;   ///< orthonormal p, q per vertex (when used)
  Index m_constrainedVertexCount = 0;
};

}  // namespace weft
