// ContactSpace: one index space over the vertices, edges and triangles of every cloth a substep
// moves, so that detection, projection and impacts treat contact within a cloth and between
// cloths alike (a pair of two cloths is a pair of this space with two owners).
//
// The cloths keep their own state for the implicit solve (each has its own matrix); the space
// gathers positions and velocities after the solve and scatters them back after the impacts.
// Tables are built when the set of cloths changes, never per substep.
#pragma once

#include <weft/Math.h>
#include <weft/collision/Aabb.h>

#include <array>
#include <span>
#include <vector>

namespace weft {

/// Pairs of cloth features this many thicknesses apart at the substep start are contacts: one
/// that approaches by up to a thickness within the substep is caught at the start, where its side
/// is known. Features that close at rest are neighbours in the material and never a contact.
inline constexpr Real kPairReach = 2;

class Cloth;

/// Per-cloth (owner) parameters of the contact space.
struct ContactOwner {
  Real thickness = 0.003;     ///< m, contact distance kept between features
  Real friction = 0.3;        ///< Coulomb coefficient
  bool selfCollision = true;  ///< pairs within this cloth are detected
  bool otherCloths = true;    ///< pairs with other cloths that also allow it are detected
};

class ContactSpace {
 public:
  /// Builds the tables for `cloths` (in this order); allocates.
  void build(std::span<Cloth* const> cloths);
  /// True when the space was built for exactly these cloths.
  bool builtFor(std::span<Cloth* const> cloths) const;
  /// Edges longer than their limit by more than `tolerance` times their rest length, among
  /// those with a free end.
  Index edgesOverLimit(Real tolerance) const;

  /// Copies positions and velocities of every cloth into x and v.
  void gather();
  /// Copies x and v back into the cloths.
  void scatter() const;
  /// Copies the start of the substep (x₀, v₀) from x and v.
  void markStart() {
    startX = x;
    startV = v;
  }

  std::span<Cloth* const> cloths() const { return m_cloths; }
  /// Makes a cloth's vertices movable (its own inverse masses) or immovable (a sleeping cloth,
  /// an obstacle for the others this frame).
  void setMovable(std::size_t cloth, bool movable);
  Index vertexCount() const { return Index(x.size()); }
  Index firstVertex(std::size_t cloth) const { return m_firstVertex[cloth]; }

  // Per vertex.
  Vec3Array x, v;            ///< current positions (m) and velocities (m/s)
  Vec3Array startX, startV;  ///< at the substep start
  std::vector<Real> inverseMass;  ///< 1/kg, 0 for pinned vertices
  std::vector<Index> owner;       ///< index of the vertex's cloth
  Vec3Array rest;                 ///< rest positions (features close at rest never repel)

  // Per owner.
  std::vector<ContactOwner> owners;

  // Topology, in ids of this space.
  std::vector<std::array<Index, 3>> triangles;
  std::vector<std::array<Index, 3>> triangleEdges;  ///< the three edges of every triangle
  std::vector<std::array<Index, 2>> edges;          ///< mesh edges
  std::vector<Real> restLengths;                    ///< m, per edge
  /// m, per edge: the longest the strain limit allows ((1 + limit) · rest; infinity: no limit).
  std::vector<Real> longest;
  /// Tethers (the strain limit's long-range part): each free vertex of a cloth with pins and a
  /// strain limit may be at most `tetherLength` from its anchor, the pin nearest along the mesh
  /// at rest, (1 + limit) times that path. Every edge at its limit allows exactly that, so a
  /// tether never conflicts with the edges; it brings a long or heavily loaded chain within its
  /// limit in one sweep where edge corrections alone travel one edge per sweep and a heavy vertex
  /// moves by m_light / m_heavy of its excess per sweep. kInvalidIndex: none.
  std::vector<Index> tetherAnchor;
  std::vector<Real> tetherLength;
  /// m, per vertex: the rest path length to the nearest pin of its cloth (infinity: none). An
  /// edge over its limit moves only its end farther from the pins (the nearer end is held by
  /// the pins through the cloth: "follow the leader", Müller et al. 2012), so a hanging chain is
  /// brought within its limit in one sweep instead of diffusing the correction edge by edge.
  std::vector<Real> anchorDistance;
  /// The edges in the order the projector sweeps them: by the anchor distance of their nearer
  /// end, then by index (nearest the pins first).
  std::vector<Index> edgeOrder;
  /// Per vertex, the positions in edgeOrder of its edges: those of vertex i are
  /// edgeSlots[edgeSlotBegin[i], edgeSlotBegin[i + 1]), the edges a move of the vertex may take
  /// over their limit.
  std::vector<Index> edgeSlotBegin, edgeSlots;
  /// Builds edgeSlotBegin and edgeSlots from edges and edgeOrder, giving edges that edgeOrder
  /// does not list (a space put together by hand) their index order. build() calls it; the
  /// projector does for a space whose tables do not match its edges. Allocates.
  void listEdgeSlots();
  /// True when edgeOrder, edgeSlotBegin and edgeSlots are those of the current edges and vertices.
  bool edgeSlotsListed() const {
    return edgeOrder.size() == edges.size() && edgeSlots.size() == 2 * edges.size() &&
           edgeSlotBegin.size() == x.size() + 1;
  }

  /// Marks whether a cloth's faces are kept out of colliders (ClothSettings::faceContacts).
  bool faceContacts(Index vertex) const {
    return m_faceContacts.empty() || m_faceContacts[owner[vertex]] != 0;
  }

  /// m, the largest thickness of the owners (0 with none).
  Real maxThickness() const;
  /// The box of the paths of the movable vertices, from startX to `end`.
  Aabb movablePaths(std::span<const Vec3> end) const;

  /// Thickness (m) and friction of a pair of vertices' owners: the larger thickness and the
  /// geometric mean of the frictions (one owner: its own values).
  Real pairThickness(Index a, Index b) const;
  Real pairFriction(Index a, Index b) const;
  /// Whether pairs between these vertices' owners are detected.
  bool pairsAllowed(Index a, Index b) const;
  /// Whether a vertex and a triangle, or two edges, of one cloth lie within the pairs' reach
  /// (kPairReach thicknesses) of each other at rest: neighbours in the material, which the
  /// elastic forces keep apart and no contact stage treats as a pair.
  bool restNeighbours(Index vertex, const std::array<Index, 3>& triangle) const;
  bool restNeighbours(const std::array<Index, 2>& p, const std::array<Index, 2>& q) const;

 private:
  void buildTethers(const Cloth& cloth, Index offset, Real factor);

  std::vector<Cloth*> m_cloths;
  std::vector<Index> m_firstVertex;
  std::vector<char> m_faceContacts;  // per cloth
};

}  // namespace weft
