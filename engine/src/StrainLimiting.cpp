#include "StrainLimiting.h"

#include <weft/threading/GrainSizes.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

namespace weft {
namespace {

// An edge's test and impulse cost about what a vertex update does (a subtraction, a square root,
// a few products), so edges use the per-vertex grain: the curtain's 3,670 edges are 2 blocks.
constexpr TaskSystem::Index kGrainEdges = kGrainVertices;
// An edge whose held weight (applyInContact) is below this fraction of its free weight is taken
// as uncorrectable: its two ends lie (nearly) along their contact normals, and the impulse that
// would fix it through the small remainder grows without bound.
constexpr Real kSmallestHeldWeight = 1e-3;

// The weight an over-long edge's correction sees when each end may move only across its contact
// normal (zero: free): w (1 − (n·d)²) per end, d the edge's direction. Zero for an edge whose ends
// are both held (nearly) along it, which cannot be corrected without pushing into a surface and
// is left to the collisions.
Real heldWeight(Real weightA, Real weightB, const Vec3& normalA, const Vec3& normalB,
                const Vec3& direction) {
  const Real alongA = normalA.dot(direction), alongB = normalB.dot(direction);
  const Real held = weightA * (1 - alongA * alongA) + weightB * (1 - alongB * alongB);
  return held > kSmallestHeldWeight * (weightA + weightB) ? held : 0;
}

// The fraction of a held correction to take (see "A held end's step" in StrainLimiting.h): the
// correction changes the edge vector `delta` by `change` (the difference of its ends' shifts);
// the result is the first s in (0, 1] with |delta + s change| = longest, or, when the edge
// cannot get that short along `change`, the s at which it is shortest. Exactly 1 is kept for a
// linearised step that does not overshoot, so an edge the step brings to the limit to round-off
// keeps its full step.
Real heldStepFraction(const Vec3& delta, const Vec3& change, Real longest) {
  const Real a = change.squaredNorm(), b = delta.dot(change);
  if (!(a > 0) || !(b < 0)) return 0;  // the correction would not shorten the edge at all
  const Real c = delta.squaredNorm() - longest * longest;
  const Real discriminant = b * b - a * c;
  const Real fraction = discriminant >= 0 ? (-b - std::sqrt(discriminant)) / a : -b / a;
  return std::min<Real>(1, fraction);
}

// The shifts of an edge's ends for a correction `impulse` (from a to b's side: a moves by
// weightA · impulse, b by −weightB · impulse), each held end kept on its surface (its shift
// without the part along its contact normal; a zero normal holds nothing).
std::pair<Vec3, Vec3> heldShifts(Real weightA, Real weightB, const Vec3& impulse,
                                 const Vec3& normalA, const Vec3& normalB) {
  Vec3 shiftA = weightA * impulse;
  shiftA -= normalA.dot(shiftA) * normalA;
  Vec3 shiftB = -weightB * impulse;
  shiftB -= normalB.dot(shiftB) * normalB;
  return {shiftA, shiftB};
}

}  // namespace

StrainLimiter::StrainLimiter(std::span<const Edge> edges, Index vertexCount) {
  m_edges.reserve(edges.size());
  m_incidenceOffsets.assign(std::size_t(vertexCount) + 1, 0);
  for (const Edge& edge : edges) {
    assert(edge.vertices[0] < vertexCount && edge.vertices[1] < vertexCount &&
           "StrainLimiter: edge vertex outside the mesh; pass the model's vertexCount()");
    m_edges.push_back(LimitedEdge{edge.vertices[0], edge.vertices[1], edge.restLength});
    ++m_incidenceOffsets[edge.vertices[0] + 1];
    ++m_incidenceOffsets[edge.vertices[1] + 1];
  }
  for (Index i = 0; i < vertexCount; ++i) m_incidenceOffsets[i + 1] += m_incidenceOffsets[i];
  // Filled in edge order, so every vertex lists its edges in increasing order: the gather sums
  // them in an order that does not depend on threads.
  m_incidentEdges.resize(m_incidenceOffsets[vertexCount]);
  std::vector<Index> fill(m_incidenceOffsets.begin(), m_incidenceOffsets.end() - 1);
  for (Index e = 0; e < Index(m_edges.size()); ++e) {
    m_incidentEdges[fill[m_edges[e].a]++] = e;
    m_incidentEdges[fill[m_edges[e].b]++] = e;
  }
  m_impulses.assign(m_edges.size(), Vec3::Zero());
  m_overLimit.assign(m_edges.size(), 0);
  m_correctionCount.assign(vertexCount, 0);
}

StrainLimitReport StrainLimiter::apply(const StrainLimitSettings& settings,
                                       std::span<const Real> inverseMasses, Real h,
                                       std::span<Vec3> x, std::span<Vec3> v, TaskSystem& tasks) {
  return run(settings, inverseMasses, {}, {}, nullptr, h, x, v, tasks);
}

StrainLimitReport StrainLimiter::applyInContact(const StrainLimitSettings& settings,
                                                std::span<const Real> inverseMasses,
                                                std::span<const Vec3> contactNormals, Real h,
                                                std::span<Vec3> x, std::span<Vec3> v,
                                                TaskSystem& tasks,
                                                std::span<const SeparationHold> separations,
                                                PositionConstraints* constraints) {
  assert(contactNormals.size() == m_correctionCount.size() &&
         "StrainLimiter::applyInContact: one contact normal (zero: none) per vertex");
  return run(settings, inverseMasses, contactNormals, separations, constraints, h, x, v, tasks);
}

void StrainLimiter::separate(std::span<const SeparationHold> separations,
                             std::span<const Real> inverseMasses,
                             std::span<const Vec3> contactNormals, Real inverseStep, bool backward,
                             std::span<Vec3> x, std::span<Vec3> v) {
  const std::size_t count = separations.size();
  for (std::size_t k = 0; k < count; ++k) {
    const SeparationHold& pair = separations[backward ? count - 1 - k : k];
    Vec3 point = Vec3::Zero();
    for (int j = 0; j < 4; ++j) point += pair.weights[j] * x[pair.vertices[j]];
    const Real shortfall = pair.separation - pair.normal.dot(point);
    if (!(shortfall > 0)) continue;
    // Every movable vertex of the pair counts as heavy as the pair's heaviest (see the design
    // note): a light sheet under a heavy weight would otherwise take almost all of each
    // correction and give it back to the edges on the next pass, which then converges at
    // m_light / m_heavy per iteration. Within the pair the correction is shared by the weights;
    // a vertex held on a collider moves only across its surface's normal n_j, so its weight is
    // w_j² W (1 − (n_j·n)²).
    Real pairInverseMass = std::numeric_limits<Real>::infinity();
    for (int j = 0; j < 4; ++j) {
      const Real w = inverseMasses[pair.vertices[j]];
      if (w > 0 && pair.weights[j] != 0) pairInverseMass = std::min(pairInverseMass, w);
    }
    if (!std::isfinite(pairInverseMass)) continue;  // all four pinned or held fixed
    Real weight = 0;
    for (int j = 0; j < 4; ++j) {
      const Index i = pair.vertices[j];
      if (inverseMasses[i] == 0) continue;
      const Real along = contactNormals[i].dot(pair.normal);
      weight += pair.weights[j] * pair.weights[j] * (1 - along * along);
    }
    if (!(weight > kSmallestHeldWeight)) continue;
    const Real lambda = shortfall / (weight * pairInverseMass);
    for (int j = 0; j < 4; ++j) {
      const Index i = pair.vertices[j];
      if (inverseMasses[i] == 0) continue;
      Vec3 shift = (pair.weights[j] * pairInverseMass * lambda) * pair.normal;
      shift -= contactNormals[i].dot(shift) * contactNormals[i];
      x[i] += shift;
      v[i] += inverseStep * shift;
    }
  }
}

void StrainLimiter::sweep(Real stretchFactor, std::span<const Real> inverseMasses,
                          std::span<const Vec3> contactNormals, Real inverseStep, bool backward,
                          std::span<Vec3> x, std::span<Vec3> v) const {
  const Index edgeCount = Index(m_edges.size());
  const bool inContact = !contactNormals.empty();
  for (Index k = 0; k < edgeCount; ++k) {
    const LimitedEdge& edge = m_edges[backward ? edgeCount - 1 - k : k];
    const Real weightA = inverseMasses[edge.a], weightB = inverseMasses[edge.b];
    const Real weightSum = weightA + weightB;
    const Vec3 delta = x[edge.b] - x[edge.a];
    const Real length = delta.norm();
    const Real longest = stretchFactor * edge.restLength;
    if (!(length > longest) || weightSum == 0) continue;
    Vec3 shiftA, shiftB;
    if (inContact) {
      const Vec3& normalA = contactNormals[edge.a];
      const Vec3& normalB = contactNormals[edge.b];
      const Vec3 direction = delta / length;
      const Real held = heldWeight(weightA, weightB, normalA, normalB, direction);
      if (held == 0) continue;
      const Vec3 impulse = ((length - longest) / held) * direction;
      std::tie(shiftA, shiftB) = heldShifts(weightA, weightB, impulse, normalA, normalB);
      if (!normalA.isZero() || !normalB.isZero()) {
        // The held step is linearised and can carry an end past the point where the edge is
        // shortest (see "A held end's step"): take the part that reaches the limit.
        const Real fraction = heldStepFraction(delta, shiftB - shiftA, longest);
        shiftA *= fraction;
        shiftB *= fraction;
      }
    } else {
      const Vec3 impulse = ((length - longest) / (weightSum * length)) * delta;
      shiftA = weightA * impulse;
      shiftB = -weightB * impulse;
    }
    x[edge.a] += shiftA;
    v[edge.a] += inverseStep * shiftA;
    x[edge.b] += shiftB;
    v[edge.b] += inverseStep * shiftB;
  }
}

StrainLimitReport StrainLimiter::run(const StrainLimitSettings& settings,
                                     std::span<const Real> inverseMasses,
                                     std::span<const Vec3> contactNormals,
                                     std::span<const SeparationHold> separations,
                                     PositionConstraints* constraints, Real h, std::span<Vec3> x,
                                     std::span<Vec3> v, TaskSystem& tasks) {
  const Index vertexCount = Index(m_correctionCount.size());
  assert(x.size() == vertexCount && v.size() == vertexCount && inverseMasses.size() == vertexCount &&
         "StrainLimiter::apply: one position, velocity and inverse mass per vertex");
  const bool inContact = !contactNormals.empty();
  assert(h > 0 && settings.limit > 0 && std::isfinite(settings.limit) &&
         "StrainLimiter::apply: needs h > 0 and a finite limit > 0 (0 or infinity means off: "
         "do not call)");
  const Real stretchFactor = 1 + settings.limit;
  const Real tolerantFactor = 1 + settings.limit + settings.tolerance;
  const Real inverseStep = 1 / h;
  const Index edgeCount = Index(m_edges.size());
  const auto sum = [](Index a, Index b) { return a + b; };
  const bool jacobi = settings.order != StrainLimitOrder::GaussSeidel;

  StrainLimitReport report;
  // The further constraints are projected first (the collision passes before this run may have
  // left some violated) and after every iteration; `violated` counts those the last projection
  // found violated, and the run goes on until neither they nor the edges need correcting.
  Index violated = constraints ? constraints->project(x, v, inverseStep) : 0;
  for (int iteration = 0;; ++iteration) {
    // 1. Per edge: the impulse that brings it back to the limit, and the count of edges that
    //    are still over limit + tolerance (the stopping test).
    const Index over = tasks.parallelReduce(
        edgeCount, kGrainEdges, Index(0),
        [&](Index begin, Index end) {
          Index blockOver = 0;
          for (Index e = begin; e < end; ++e) {
            const LimitedEdge& edge = m_edges[e];
            Real weightSum = inverseMasses[edge.a] + inverseMasses[edge.b];
            const Vec3 delta = x[edge.b] - x[edge.a];
            const Real length = delta.norm();
            const Real longest = stretchFactor * edge.restLength;
            if (inContact && length > longest && weightSum > 0) {
              weightSum = heldWeight(inverseMasses[edge.a], inverseMasses[edge.b],
                                     contactNormals[edge.a], contactNormals[edge.b],
                                     delta / length);
            }
            const bool over = length > longest && weightSum != 0;
            // The Gauss–Seidel sweep works out each edge's impulse as it goes; only the Jacobi
            // gather below reads these.
            if (jacobi) {
              m_overLimit[e] = over;
              if (over) m_impulses[e] = ((length - longest) / (weightSum * length)) * delta;
              const bool held = inContact && (!contactNormals[edge.a].isZero() ||
                                              !contactNormals[edge.b].isZero());
              if (over && held) {
                // The fraction of the held step that does not overshoot, as in the sweep: taken
                // as if the edge moved alone (the gather gives it a share of at most that).
                const auto [shiftA, shiftB] =
                    heldShifts(inverseMasses[edge.a], inverseMasses[edge.b], m_impulses[e],
                               contactNormals[edge.a], contactNormals[edge.b]);
                m_impulses[e] *= heldStepFraction(delta, shiftB - shiftA, longest);
              }
            }
            if (over) blockOver += length > tolerantFactor * edge.restLength;
          }
          return blockOver;
        },
        sum);
    report.edgesOverLimit = over;
    if ((over == 0 && violated == 0) || iteration == settings.maxIterations) break;
    report.iterations = iteration + 1;

    if (!jacobi) {
      sweep(stretchFactor, inverseMasses, contactNormals, inverseStep, iteration % 2 == 1, x, v);
      separate(separations, inverseMasses, contactNormals, inverseStep, iteration % 2 == 1, x, v);
      if (constraints) violated = constraints->project(x, v, inverseStep);
      continue;
    }

    // 2. Per vertex: how many over-limit edges move it (none for a vertex that cannot move).
    tasks.parallelFor(vertexCount, kGrainVertices, [&](Index begin, Index end, int) {
      for (Index i = begin; i < end; ++i) {
        Index count = 0;
        if (inverseMasses[i] > 0) {
          for (Index k = m_incidenceOffsets[i]; k < m_incidenceOffsets[i + 1]; ++k) {
            count += Index(m_overLimit[m_incidentEdges[k]]);
          }
        }
        m_correctionCount[i] = count;
      }
    });

    // 3. Per vertex: gather the corrections in edge order; each edge's share is divided by the
    //    larger count of its two ends, the same on both sides, so momentum is unchanged.
    tasks.parallelFor(vertexCount, kGrainVertices, [&](Index begin, Index end, int) {
      for (Index i = begin; i < end; ++i) {
        if (m_correctionCount[i] == 0) continue;
        Vec3 shift = Vec3::Zero();
        for (Index k = m_incidenceOffsets[i]; k < m_incidenceOffsets[i + 1]; ++k) {
          const Index e = m_incidentEdges[k];
          if (!m_overLimit[e]) continue;
          const LimitedEdge& edge = m_edges[e];
          const Real share =
              Real(1) / Real(std::max(m_correctionCount[edge.a], m_correctionCount[edge.b]));
          // The impulse points from a to b: a moves along it, b against it.
          if (edge.a == i) {
            shift += share * m_impulses[e];
          } else {
            shift -= share * m_impulses[e];
          }
        }
        shift *= inverseMasses[i];
        if (inContact) shift -= contactNormals[i].dot(shift) * contactNormals[i];
        x[i] += shift;
        v[i] += inverseStep * shift;
      }
    });
    // The self-contacts after the edges, serially (they are few): the same for any thread count.
    separate(separations, inverseMasses, contactNormals, inverseStep, iteration % 2 == 1, x, v);
    if (constraints) violated = constraints->project(x, v, inverseStep);
  }
  return report;
}

}  // namespace weft
