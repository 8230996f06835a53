#include "StrainLimiting.h"

#include <weft/threading/GrainSizes.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace weft {
namespace {

// An edge's test or PCG update costs about what a vertex update does (a few loads, products and
// at most a square root), so edges use the per-vertex grain: the curtain's 3,670 edges are 2
// blocks.
constexpr TaskSystem::Index kGrainEdges = kGrainVertices;

// The PCG of one projection stops when no active edge's residual excess is above this fraction
// of the tolerance (relative to its rest length): the rest is left to the next projection.
constexpr Real kResidualFraction = 0.25;

struct DotAndMax {
  Real dot = 0;
  Real max = 0;
};

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
  // Filled in edge order, so every vertex lists its edges in increasing order: the gathers sum
  // them in an order that does not depend on threads.
  m_incidentEdges.resize(m_incidenceOffsets[vertexCount]);
  std::vector<Index> fill(m_incidenceOffsets.begin(), m_incidenceOffsets.end() - 1);
  for (Index e = 0; e < Index(m_edges.size()); ++e) {
    m_incidentEdges[fill[m_edges[e].a]++] = e;
    m_incidentEdges[fill[m_edges[e].b]++] = e;
  }
  const std::size_t edgeCount = m_edges.size();
  m_active.assign(edgeCount, 0);
  m_direction.assign(edgeCount, Vec3::Zero());
  for (std::vector<Real>* scalars : {&m_diagonal, &m_multiplier, &m_residual, &m_preconditioned,
                                     &m_search, &m_product}) {
    scalars->assign(edgeCount, 0);
  }
  m_shift.assign(vertexCount, Vec3::Zero());
}

template <class Scalars>
void StrainLimiter::gatherShifts(const Scalars& s, std::span<const Real> inverseMasses,
                                 TaskSystem& tasks) {
  // Vertex a of an edge moves along its direction (toward b), b against it.
  tasks.parallelFor(Index(m_shift.size()), kGrainVertices, [&](Index begin, Index end, int) {
    for (Index i = begin; i < end; ++i) {
      Vec3 shift = Vec3::Zero();
      if (inverseMasses[i] > 0) {
        for (Index k = m_incidenceOffsets[i]; k < m_incidenceOffsets[i + 1]; ++k) {
          const Index e = m_incidentEdges[k];
          if (!m_active[e]) continue;
          const Real amount = s(e);
          if (m_edges[e].a == i) {
            shift += amount * m_direction[e];
          } else {
            shift -= amount * m_direction[e];
          }
        }
        shift *= inverseMasses[i];
      }
      m_shift[i] = shift;
    }
  });
}

StrainLimitReport StrainLimiter::apply(const StrainLimitSettings& settings,
                                       std::span<const Real> inverseMasses, Real h,
                                       std::span<Vec3> x, std::span<Vec3> v, TaskSystem& tasks) {
  const Index vertexCount = Index(m_shift.size());
  assert(x.size() == vertexCount && v.size() == vertexCount && inverseMasses.size() == vertexCount &&
         "StrainLimiter::apply: one position, velocity and inverse mass per vertex");
  assert(h > 0 && settings.limit > 0 && std::isfinite(settings.limit) &&
         "StrainLimiter::apply: needs h > 0 and a finite limit > 0 (0 or infinity means off: "
         "do not call)");
  (void)vertexCount;
  const Real stretchFactor = 1 + settings.limit;
  const Real tolerantFactor = 1 + settings.limit + settings.tolerance;
  const Real residualTolerance = kResidualFraction * settings.tolerance;
  const Real inverseStep = 1 / h;
  const Index edgeCount = Index(m_edges.size());
  const auto addCounts = [](Index a, Index b) { return a + b; };
  const auto addDotKeepMax = [](DotAndMax a, DotAndMax b) {
    return DotAndMax{a.dot + b.dot, std::max(a.max, b.max)};
  };

  StrainLimitReport report;
  for (int pass = 0;; ++pass) {
    // Per edge: active when over the limit (or active in an earlier projection) and movable;
    // its direction, excess (the first residual, with λ = 0; negative for an active edge now
    // below the limit) and preconditioned residual. Counts the edges over limit + tolerance.
    const Index over = tasks.parallelReduce(
        edgeCount, kGrainEdges, Index(0),
        [&](Index begin, Index end) {
          Index blockOver = 0;
          for (Index e = begin; e < end; ++e) {
            const LimitedEdge& edge = m_edges[e];
            const Real weightSum = inverseMasses[edge.a] + inverseMasses[edge.b];
            const Vec3 delta = x[edge.b] - x[edge.a];
            const Real length = delta.norm();
            const Real longest = stretchFactor * edge.restLength;
            m_multiplier[e] = 0;
            // Once active, an edge stays active for the later projections of this call and is
            // held at the limit: otherwise the next projection, free to re-stretch it, would
            // trade it back and forth with its neighbours instead of converging.
            const bool wasActive = pass > 0 && m_active[e];
            if ((!(length > longest) && !wasActive) || weightSum == 0 || !(length > 0)) {
              m_active[e] = 0;
              m_residual[e] = m_preconditioned[e] = m_search[e] = 0;
              continue;
            }
            m_active[e] = 1;
            m_direction[e] = delta / length;
            m_diagonal[e] = weightSum;
            m_residual[e] = length - longest;
            m_preconditioned[e] = m_search[e] = m_residual[e] / weightSum;
            blockOver += length > tolerantFactor * edge.restLength;
          }
          return blockOver;
        },
        addCounts);
    report.edgesOverLimit = over;
    if (std::getenv("SLDEBUG")) { Real mx=0; for (Index e=0;e<edgeCount;++e) mx=std::max(mx,(x[m_edges[e].b]-x[m_edges[e].a]).norm()/m_edges[e].restLength-1); std::fprintf(stderr,"pass %d over %u maxstrain %.6f iters %d\n",pass,over,mx,report.iterations);}
    if (over == 0 || pass == settings.maxPasses) break;
    report.passes = pass + 1;

    // PCG on J W Jᵀ λ = c over the active edges, from λ = 0.
    Real residualDotPreconditioned = tasks.parallelReduce(
        edgeCount, kGrainEdges, Real(0),
        [&](Index begin, Index end) {
          Real dot = 0;
          for (Index e = begin; e < end; ++e) dot += m_residual[e] * m_preconditioned[e];
          return dot;
        },
        [](Real a, Real b) { return a + b; });
    Real searchFactor = 0;  // β of the previous iteration; the search direction is updated lazily
    for (int iteration = 0; iteration < settings.maxIterations; ++iteration) {
      ++report.iterations;
      // s = z + β s, read on the fly by the vertices and stored by the product pass below.
      const Real beta = searchFactor;
      gatherShifts([&](Index e) { return m_preconditioned[e] + beta * m_search[e]; },
                   inverseMasses, tasks);
      const Real searchDotProduct = tasks.parallelReduce(
          edgeCount, kGrainEdges, Real(0),
          [&](Index begin, Index end) {
            Real dot = 0;
            for (Index e = begin; e < end; ++e) {
              if (!m_active[e]) continue;
              m_search[e] = m_preconditioned[e] + beta * m_search[e];
              m_product[e] = m_direction[e].dot(m_shift[m_edges[e].a] - m_shift[m_edges[e].b]);
              dot += m_search[e] * m_product[e];
            }
            return dot;
          },
          [](Real a, Real b) { return a + b; });
      if (!(searchDotProduct > 0)) break;  // nothing left to reduce (or round-off took over)
      const Real alpha = residualDotPreconditioned / searchDotProduct;
      const DotAndMax next = tasks.parallelReduce(
          edgeCount, kGrainEdges, DotAndMax{},
          [&](Index begin, Index end) {
            DotAndMax block;
            for (Index e = begin; e < end; ++e) {
              if (!m_active[e]) continue;
              m_multiplier[e] += alpha * m_search[e];
              m_residual[e] -= alpha * m_product[e];
              m_preconditioned[e] = m_residual[e] / m_diagonal[e];
              block.dot += m_residual[e] * m_preconditioned[e];
              block.max = std::max(block.max, std::abs(m_residual[e]) / m_edges[e].restLength);
            }
            return block;
          },
          addDotKeepMax);
      if (next.max <= residualTolerance) break;
      searchFactor = next.dot / residualDotPreconditioned;
      residualDotPreconditioned = next.dot;
    }

    // Move by the multipliers, as a velocity change over the step. A negative one holds an edge
    // at the limit that the others would have shortened below it; clamping it to 0 instead
    // would unbalance the large opposite multipliers that redundant edges (a triangle's three)
    // can carry, and throw vertices far off.
    gatherShifts([&](Index e) { return m_multiplier[e]; }, inverseMasses, tasks);
    tasks.parallelFor(Index(m_shift.size()), kGrainVertices, [&](Index begin, Index end, int) {
      for (Index i = begin; i < end; ++i) {
        x[i] += m_shift[i];
        v[i] += inverseStep * m_shift[i];
      }
    });
  }
  return report;
}

}  // namespace weft
