#include "ClothClothCollision.h"

#include "Cloth.h"
#include "SelfCollision.h"

#include <weft/threading/Profiler.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace weft {
namespace {

// Rounds of "collider response on the corrected vertices, then swept tests again" after the
// first pass. Each round starts only when the previous collider pass moved a vertex, which then
// ends on the collider's thickness and so counts as held (ContactResolver.h) in the next one.
constexpr int kColliderRounds = 3;
// Rounds of "strain limiter with the pairs found held, then the swept pass again", as many as
// Cloth's (kContactLimitPasses in Cloth.cpp); most frames stop early, when the limiter finds
// nothing over the limit.
constexpr int kStrainLimitRounds = 6;

}  // namespace

ClothClothCollision::ClothClothCollision(TaskSystem* tasks) : ContactResolver(tasks) {
  if (m_tasks) m_workerPairs = std::make_unique<PerWorker<std::vector<TrianglePair>>>(*m_tasks);
}

void ClothClothCollision::rebuild() {
  const std::size_t count = m_members.size();
  m_bvhs.clear();
  m_vertexOffset.assign(1, 0);
  m_triangleOffset.assign(1, 0);
  m_owners.clear();
  m_inverseMasses.clear();
  std::vector<std::array<Index, 3>> triangles, triangleEdges;
  std::vector<std::array<Index, 2>> edges;
  Vec3Array rest;
  std::vector<Index> owners;
  std::vector<std::array<Index, 2>> memberEdges;
  std::vector<std::array<Index, 3>> memberTriangleEdges;
  for (std::size_t c = 0; c < count; ++c) {
    const Cloth& cloth = *m_members[c].cloth;
    const ClothModel& model = cloth.model();
    const Index vertexOffset = m_vertexOffset.back();
    const Index edgeOffset = Index(edges.size());
    m_bvhs.push_back(Bvh::build(model.indices(), model.restPositions()).value());
    for (Index t = 0; t < model.triangleCount(); ++t) {
      const std::array<Index, 3>& corners = m_bvhs.back().triangle(t);
      triangles.push_back({corners[0] + vertexOffset, corners[1] + vertexOffset, corners[2] + vertexOffset});
    }
    buildEdgeTables(model, memberEdges, memberTriangleEdges);
    for (const auto& edge : memberEdges) edges.push_back({edge[0] + vertexOffset, edge[1] + vertexOffset});
    for (const auto& ids : memberTriangleEdges) {
      triangleEdges.push_back({ids[0] + edgeOffset, ids[1] + edgeOffset, ids[2] + edgeOffset});
    }
    rest.insert(rest.end(), model.restPositions().begin(), model.restPositions().end());
    owners.insert(owners.end(), model.vertexCount(), Index(c));
    m_inverseMasses.insert(m_inverseMasses.end(), cloth.inverseMasses().begin(),
                           cloth.inverseMasses().end());
    m_owners.push_back({cloth.settings().material.thickness, cloth.settings().material.friction});
    m_vertexOffset.push_back(vertexOffset + model.vertexCount());
    m_triangleOffset.push_back(m_triangleOffset.back() + model.triangleCount());
  }
  const Index vertices = m_vertexOffset.back();
  m_start.resize(vertices);
  m_x.resize(vertices);
  m_v.resize(vertices);
  m_corrected.assign(vertices, 0);

  // One strain limiter over the members that have one, each edge's rest length scaled so that
  // the smallest limit stands for every member's own (see the design note).
  m_strainLimiter.reset();
  Real smallestLimit = std::numeric_limits<Real>::infinity();
  bool gaussSeidel = true;
  m_strainLimitSettings = StrainLimitSettings{};
  m_strainLimitSettings.tolerance = std::numeric_limits<Real>::infinity();
  m_strainLimitSettings.maxIterations = 0;
  for (const Member& member : m_members) {
    const StrainLimitSettings* limits = member.cloth->strainLimitSettings();
    if (!limits) continue;
    smallestLimit = std::min(smallestLimit, limits->limit);
    m_strainLimitSettings.tolerance = std::min(m_strainLimitSettings.tolerance, limits->tolerance);
    m_strainLimitSettings.maxIterations = std::max(m_strainLimitSettings.maxIterations, limits->maxIterations);
    gaussSeidel = gaussSeidel && limits->order == StrainLimitOrder::GaussSeidel;
  }
  std::vector<Edge> limitedEdges;
  for (std::size_t c = 0; c < count; ++c) {
    const StrainLimitSettings* limits = m_members[c].cloth->strainLimitSettings();
    if (!limits) continue;
    const Real scale = (1 + limits->limit) / (1 + smallestLimit);
    for (Edge edge : m_members[c].cloth->model().edges()) {
      edge.vertices[0] += m_vertexOffset[c];
      edge.vertices[1] += m_vertexOffset[c];
      edge.restLength *= scale;
      limitedEdges.push_back(edge);
    }
  }
  if (!limitedEdges.empty()) {
    m_strainLimitSettings.limit = smallestLimit;
    m_strainLimitSettings.order = gaussSeidel ? StrainLimitOrder::GaussSeidel : StrainLimitOrder::Jacobi;
    m_strainLimiter = std::make_unique<StrainLimiter>(limitedEdges, vertices);
    m_limitInverseMasses.assign(vertices, 0);
    m_limitNormals.assign(vertices, Vec3::Zero());
  }
  // The pairs are recorded for the limiter only (nothing to pay when no member has a limit).
  setRecordSeparations(m_strainLimiter != nullptr);
  m_vertexMember = owners;
  m_heldContacts.clear();
  setTopology(std::move(triangles), std::move(triangleEdges), std::move(edges), std::move(rest),
              std::move(owners));
}

void ClothClothCollision::findTrianglePairs(const Vec3Array& from, const Vec3Array& to,
                                            Real inflate, bool proximity,
                                            std::vector<TrianglePair>& pairs) {
  WEFT_PROFILE_ZONE("broad phase");
  pairs.clear();
  for (std::size_t c = 0; c < m_members.size(); ++c) {
    if (!m_active[c]) continue;
    const Index offset = m_vertexOffset[c];
    const Index vertices = m_vertexOffset[c + 1] - offset;
    m_bvhs[c].refit(std::span<const Vec3>(from.data() + offset, vertices),
                    std::span<const Vec3>(to.data() + offset, vertices), inflate, m_tasks);
    // Self pairs only for the swept stage (their proximity is the cloth's own, per substep),
    // and only for cloths that collide with themselves at all.
    if (proximity || !m_members[c].cloth->settings().selfCollision) continue;
    if (m_workerPairs) {
      m_bvhs[c].querySelf(m_memberPairs, *m_tasks, *m_workerPairs);
      const std::size_t total = m_memberPairs.size();
      m_workerPairs->forEach([total](std::vector<TrianglePair>& list) {
        if (list.capacity() < total) list.reserve(total);
      });
    } else {
      m_bvhs[c].querySelf(m_memberPairs);
    }
    const Index triangleOffset = m_triangleOffset[c];
    for (const TrianglePair& pair : m_memberPairs) {
      pairs.push_back({pair.first + triangleOffset, pair.second + triangleOffset});
    }
  }
  for (const auto& [c, d] : m_overlaps) {
    m_bvhs[c].queryPairs(m_bvhs[d], m_memberPairs);
    for (const TrianglePair& pair : m_memberPairs) {
      pairs.push_back({pair.first + m_triangleOffset[c], pair.second + m_triangleOffset[d]});
    }
  }
  std::sort(pairs.begin(), pairs.end());
}

bool ClothClothCollision::writeBack() {
  const std::vector<char>& touched = this->touched();
  bool changed = false;
  for (std::size_t c = 0; c < m_members.size(); ++c) {
    if (!m_active[c]) continue;
    Cloth& cloth = *m_members[c].cloth;
    Vec3Array& x = cloth.correctablePositions();
    Vec3Array& v = cloth.correctableVelocities();
    const Index offset = m_vertexOffset[c];
    for (Index i = 0; i < x.size(); ++i) {
      if (!touched[offset + i]) continue;
      x[i] = m_x[offset + i];
      v[i] = m_v[offset + i];
      m_corrected[offset + i] = 1;
      changed = true;
    }
  }
  return changed;
}

bool ClothClothCollision::resolveColliders(std::span<const ColliderFrame> colliders) {
  bool moved = false;
  for (std::size_t c = 0; c < m_members.size(); ++c) {
    if (!m_active[c]) continue;
    Cloth& cloth = *m_members[c].cloth;
    const Index offset = m_vertexOffset[c];
    const Index vertices = m_vertexOffset[c + 1] - offset;
    bool any = false;
    m_skip.resize(vertices);
    for (Index i = 0; i < vertices; ++i) {
      m_skip[i] = cloth.pinnedMask()[i] || !m_corrected[offset + i];
      any = any || !m_skip[i];
    }
    if (!any) continue;
    // The friction of a pair is the geometric mean of the two coefficients, as in Cloth.
    m_colliders.assign(colliders.begin(), colliders.end());
    for (ColliderFrame& collider : m_colliders) {
      collider.friction =
          std::sqrt(std::max<Real>(0, collider.friction) * cloth.settings().material.friction);
    }
    Vec3Array& x = cloth.correctablePositions();
    m_before.assign(x.begin(), x.end());
    m_colliderResponse.resolve(m_colliders, cloth.frameStartPositions(),
                               cloth.frameStartVelocities(), cloth.settings().material.thickness,
                               m_skip, x, cloth.correctableVelocities());
    for (Index i = 0; i < vertices; ++i) {
      if (m_skip[i] || x[i] == m_before[i]) continue;
      moved = true;
      m_x[offset + i] = x[i];
    }
    for (Index i = 0; i < vertices; ++i) {
      if (!m_skip[i]) m_v[offset + i] = cloth.velocities()[i];
    }
  }
  return moved;
}

void ClothClothCollision::settleColliders(Real frameDt, std::span<const ColliderFrame> colliders,
                                          SelfCollisionReport& report) {
  bool changed = writeBack();
  // Vertices the cloths pushed may now be in a collider: their collider response again, then
  // the swept tests on the chord it left.
  ContactOptions options;
  options.velocityIsAverage = false;
  options.proximity = false;
  for (int round = 0; changed && !colliders.empty() && round < kColliderRounds; ++round) {
    if (!resolveColliders(colliders)) break;
    const SelfCollisionReport again = resolve(m_start, frameDt, m_owners, m_inverseMasses, options, m_x, m_v);
    collectHeldContacts(/*restart=*/false);
    report.impacts += again.impacts;
    report.impactZones += again.impactZones;
    report.frozenVertices += again.frozenVertices;
    changed = writeBack();
  }
}

void ClothClothCollision::collectHeldContacts(bool restart) {
  if (restart) m_heldContacts.clear();
  if (!m_strainLimiter) return;
  // A pair found again (the proximity contacts of every round) is appended again: a repeat of
  // a constraint the limiter already meets, cheaper than looking it up.
  for (const SeparationHold& pair : separationHolds()) {
    // vertices[0] is on the pair's first side, vertices[3] on its second (SeparationHold).
    const bool betweenCloths = m_vertexMember[pair.vertices[0]] != m_vertexMember[pair.vertices[3]];
    if (betweenCloths || spansHeldMassRatio(pair, m_inverseMasses)) m_heldContacts.push_back(pair);
  }
}

bool ClothClothCollision::writeBackLimited() {
  bool moved = false;
  for (std::size_t c = 0; c < m_members.size(); ++c) {
    if (!m_active[c]) continue;
    Cloth& cloth = *m_members[c].cloth;
    const Index offset = m_vertexOffset[c];
    // The index space and the cloth agree on every position until the limiter moves one (the
    // limiter changes a vertex's velocity only with its position).
    if (std::equal(cloth.positions().begin(), cloth.positions().end(), m_x.begin() + offset)) continue;
    Vec3Array& x = cloth.correctablePositions();
    Vec3Array& v = cloth.correctableVelocities();
    for (Index i = 0; i < x.size(); ++i) {
      if (x[i] == m_x[offset + i]) continue;
      x[i] = m_x[offset + i];
      v[i] = m_v[offset + i];
      m_corrected[offset + i] = 1;
      moved = true;
    }
  }
  return moved;
}

void ClothClothCollision::limitStrainInContact(Real frameDt, std::span<const ColliderFrame> colliders,
                                               SelfCollisionReport& report) {
  if (!m_strainLimiter || m_heldContacts.empty() || !m_tasks) return;
  WEFT_PROFILE_ZONE("cloth contact strain limit");
  // What the limiter may move: the members in contact, minus their pinned vertices and those
  // fixed between two collider surfaces; along the collider normals of the cloths' last substep
  // it only slides.
  for (std::size_t c = 0; c < m_members.size(); ++c) {
    const Cloth& cloth = *m_members[c].cloth;
    const Index offset = m_vertexOffset[c];
    const Index vertices = m_vertexOffset[c + 1] - offset;
    const bool held = cloth.strainLimitSettings() != nullptr;
    for (Index i = 0; i < vertices; ++i) {
      const bool fixed = !m_active[c] || (held && cloth.contactHolds().fixed[i]);
      m_limitInverseMasses[offset + i] = fixed ? 0 : m_inverseMasses[offset + i];
      m_limitNormals[offset + i] = held ? cloth.contactHolds().normals[i] : Vec3::Zero();
    }
  }
  // The rounds' passes run the swept stage only: the proximity stage's pairs (those of the frame
  // start) are all held in the limiter, and running it again only applied their repulsion and
  // friction once more, and the friction dragged the light sheet back after the pad every round,
  // from where the limiter had just slid it (a dense pad on a sheet on the floor: 0.116 with it,
  // 0.101 without; two-layers.json: 22.6 ms per frame with it, 16.5 without, the same strain).
  // Within a pass the collider response keeps its friction, as in the first pass.
  ContactOptions options;
  options.velocityIsAverage = false;
  options.proximity = false;
  for (int round = 0; round < kStrainLimitRounds && !m_heldContacts.empty(); ++round) {
    const StrainLimitReport limited = m_strainLimiter->applyInContact(
        m_strainLimitSettings, m_limitInverseMasses, m_limitNormals, frameDt, m_x, m_v, *m_tasks,
        m_heldContacts);
    if (limited.iterations == 0 || !writeBackLimited()) break;
    // The contacts have the last word: no crossing along the chord the limiter left.
    const SelfCollisionReport again = resolve(m_start, frameDt, m_owners, m_inverseMasses, options, m_x, m_v);
    collectHeldContacts(/*restart=*/false);
    report.impacts += again.impacts;
    report.impactZones += again.impactZones;
    report.frozenVertices += again.frozenVertices;
    settleColliders(frameDt, colliders, report);
  }
}

SelfCollisionReport ClothClothCollision::resolveFrame(Real frameDt,
                                                      std::span<const ColliderFrame> colliders) {
  SelfCollisionReport report;
  if (m_next.size() < 2) return report;
  bool same = m_next.size() == m_members.size();
  for (std::size_t c = 0; same && c < m_next.size(); ++c) same = m_next[c].id == m_members[c].id;
  if (!same) {
    m_members = m_next;
    rebuild();
  } else {
    for (std::size_t c = 0; c < m_next.size(); ++c) m_members[c].cloth = m_next[c].cloth;
  }
  WEFT_PROFILE_ZONE("cloth contact");

  // Which cloths can touch: swept bounds over the frame, inflated by the thickness.
  const std::size_t count = m_members.size();
  m_active.assign(count, 0);
  m_overlaps.clear();
  m_bounds.resize(count);
  for (std::size_t c = 0; c < count; ++c) {
    const Cloth& cloth = *m_members[c].cloth;
    Aabb bounds = Aabb::empty();
    for (const Vec3& x : cloth.frameStartPositions()) bounds.expand(x);
    for (const Vec3& x : cloth.positions()) bounds.expand(x);
    bounds.inflate(cloth.settings().material.thickness);
    m_bounds[c] = bounds;
  }
  for (std::size_t c = 0; c < count; ++c) {
    for (std::size_t d = c + 1; d < count; ++d) {
      if (!m_bounds[c].overlaps(m_bounds[d])) continue;
      m_overlaps.push_back({Index(c), Index(d)});
      m_active[c] = m_active[d] = 1;
    }
  }
  if (m_overlaps.empty()) return report;

  for (std::size_t c = 0; c < count; ++c) {
    const Cloth& cloth = *m_members[c].cloth;
    const Index offset = m_vertexOffset[c];
    std::copy(cloth.frameStartPositions().begin(), cloth.frameStartPositions().end(), m_start.begin() + offset);
    std::copy(cloth.positions().begin(), cloth.positions().end(), m_x.begin() + offset);
    std::copy(cloth.velocities().begin(), cloth.velocities().end(), m_v.begin() + offset);
  }
  std::fill(m_corrected.begin(), m_corrected.end(), 0);
  // Within the frame the broad phase depends on its arguments only (the members taking part and
  // their overlaps are fixed above), so the rounds of limitStrainInContact, which resolve the
  // same frame start again, reuse its proximity contacts and swept certificate
  // (ContactResolver::setBroadPhaseIsPure; same bits; two-layers.json: 16.1 ms per frame at the
  // median instead of 21.6, one thread). Set again every frame: that forgets what another
  // frame's members and overlaps gave.
  setBroadPhaseIsPure(true);
  setColliders(colliders);
  // The frame as one step: proximity at its start, swept tests along its chord.
  ContactOptions options;
  options.velocityIsAverage = false;
  report = resolve(m_start, frameDt, m_owners, m_inverseMasses, options, m_x, m_v);
  collectHeldContacts(/*restart=*/true);
  settleColliders(frameDt, colliders, report);
  // The strain limiter with the pairs found held, and the pass again.
  limitStrainInContact(frameDt, colliders, report);
  setColliders({});
  return report;
}

}  // namespace weft
