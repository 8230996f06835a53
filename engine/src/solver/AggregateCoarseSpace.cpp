// AggregateCoarseSpace: aggregation, the Galerkin coarse matrix and its LDLᵀ. See the header for
// the design note.
#include <solver/AggregateCoarseSpace.h>

#include <Eigen/OrderingMethods>

#include <algorithm>
#include <cmath>

namespace weft {

namespace {

/// Greedy aggregation of a graph's nodes (Vaněk et al.'s first two passes) given as adjacency
/// lists; returns the aggregate count and fills aggregateOf.
template <typename Neighbours>
Index aggregateGraph(Index nodes, Neighbours&& neighbours, std::vector<Index>& aggregateOf) {
  aggregateOf.assign(nodes, kInvalidIndex);
  Index count = 0;
  // Pass 1: a node whose neighbours are all unaggregated founds an aggregate of them all.
  for (Index node = 0; node < nodes; ++node) {
    if (aggregateOf[node] != kInvalidIndex) continue;
    bool neighboursFree = true;
    neighbours(node, [&](Index other) {
      neighboursFree = neighboursFree && aggregateOf[other] == kInvalidIndex;
    });
    if (!neighboursFree) continue;
    neighbours(node, [&](Index other) { aggregateOf[other] = count; });
    aggregateOf[node] = count++;
  }
  // Pass 2: every node left has an aggregated neighbour (else pass 1 would have taken it); it
  // joins the first one's aggregate, read from pass 1's result so the order does not matter.
  const std::vector<Index> firstPass = aggregateOf;
  for (Index node = 0; node < nodes; ++node) {
    if (firstPass[node] != kInvalidIndex) continue;
    neighbours(node, [&](Index other) {
      if (aggregateOf[node] == kInvalidIndex && firstPass[other] != kInvalidIndex) {
        aggregateOf[node] = firstPass[other];
      }
    });
    if (aggregateOf[node] == kInvalidIndex) aggregateOf[node] = count++;  // no neighbour at all
  }
  return count;
}

}  // namespace

void AggregateCoarseSpace::build(const BlockSparseMatrix& A) {
  const Index rows = A.blockRows();
  m_patternId = A.patternId();
  m_factorised = false;
  const Index count = aggregateGraph(
      rows,
      [&](Index row, auto&& visit) {
        for (Index slot = A.rowBegin(row); slot < A.rowEnd(row); ++slot) visit(A.column(slot));
      },
      m_aggregateOf);
  m_aggregateCount = count;
  // Each aggregate's rows, in row order: the order in which their terms are summed.
  m_memberOffsets.assign(count + 1, 0);
  for (Index aggregate : m_aggregateOf) ++m_memberOffsets[aggregate + 1];
  for (Index a = 0; a < count; ++a) m_memberOffsets[a + 1] += m_memberOffsets[a];
  m_members.resize(rows);
  {
    std::vector<Index> next(m_memberOffsets.begin(), m_memberOffsets.end() - 1);
    for (Index row = 0; row < rows; ++row) m_members[next[m_aggregateOf[row]]++] = row;
  }

  // Coarse blocks: one per pair of aggregates joined by a block of A, numbered by (I, J).
  std::vector<std::pair<std::uint64_t, Index>> keys;  // (I·count + J, slot)
  keys.reserve(A.blockCount());
  for (Index row = 0; row < rows; ++row) {
    for (Index slot = A.rowBegin(row); slot < A.rowEnd(row); ++slot) {
      keys.emplace_back(std::uint64_t(m_aggregateOf[row]) * count + m_aggregateOf[A.column(slot)],
                        slot);
    }
  }
  std::sort(keys.begin(), keys.end());
  m_slotBlock.assign(A.blockCount(), 0);
  std::vector<std::uint64_t> blockKeys;
  for (const auto& [key, slot] : keys) {
    if (blockKeys.empty() || blockKeys.back() != key) blockKeys.push_back(key);
    m_slotBlock[slot] = Index(blockKeys.size() - 1);
  }
  const Index blockCount = Index(blockKeys.size());
  m_blocks.assign(blockCount, Mat3::Zero());
  m_blockRowOffsets.assign(count + 1, 0);
  for (std::uint64_t key : blockKeys) ++m_blockRowOffsets[key / count + 1];
  for (Index a = 0; a < count; ++a) m_blockRowOffsets[a + 1] += m_blockRowOffsets[a];
  m_diagonalBlock.assign(count, 0);
  for (Index b = 0; b < blockCount; ++b) {
    const Index I = Index(blockKeys[b] / count), J = Index(blockKeys[b] % count);
    if (I == J) m_diagonalBlock[I] = b;
  }

  // The scalar pattern's fill-reducing order (AMD on the symmetric pattern), once.
  const int unknowns = int(3 * count);
  std::vector<Eigen::Triplet<Real, int>> pattern;
  pattern.reserve(std::size_t(9) * blockCount);
  for (Index b = 0; b < blockCount; ++b) {
    const int I = int(blockKeys[b] / count), J = int(blockKeys[b] % count);
    for (int a = 0; a < 3; ++a) {
      for (int c = 0; c < 3; ++c) pattern.emplace_back(3 * I + a, 3 * J + c, Real(1));
    }
  }
  CoarseMatrix full(unknowns, unknowns);
  full.setFromTriplets(pattern.begin(), pattern.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> inverseOrder;
  Eigen::AMDOrdering<int> amd;
  amd(full, inverseOrder);  // inverseOrder maps new positions to old unknowns
  m_coarseIndex.assign(unknowns, 0);
  for (int position = 0; position < unknowns; ++position) {
    m_coarseIndex[inverseOrder.indices()[position]] = position;
  }

  // A_c's upper triangle in that order, and where each block entry's value lives.
  std::vector<Eigen::Triplet<Real, int>> upper;
  upper.reserve(pattern.size() / 2 + unknowns);
  for (const auto& entry : pattern) {
    const int p = m_coarseIndex[entry.row()], q = m_coarseIndex[entry.col()];
    if (p <= q) upper.emplace_back(p, q, Real(0));
  }
  m_matrix.resize(unknowns, unknowns);
  m_matrix.setFromTriplets(upper.begin(), upper.end());
  m_matrix.makeCompressed();
  m_blockValues.assign(blockCount, {});
  for (Index b = 0; b < blockCount; ++b) {
    const int I = int(blockKeys[b] / count), J = int(blockKeys[b] % count);
    for (int a = 0; a < 3; ++a) {
      for (int c = 0; c < 3; ++c) {
        const int p = m_coarseIndex[3 * I + a], q = m_coarseIndex[3 * J + c];
        int& value = m_blockValues[b][3 * a + c];
        value = -1;
        if (p > q) continue;
        const int* begin = m_matrix.innerIndexPtr() + m_matrix.outerIndexPtr()[q];
        const int* end = m_matrix.innerIndexPtr() + m_matrix.outerIndexPtr()[q + 1];
        value = int(std::lower_bound(begin, end, p) - m_matrix.innerIndexPtr());
      }
    }
  }
  m_solver.analyzePattern(m_matrix);
  m_restricted.setZero(unknowns);
  m_coarse.setZero(unknowns);
}

bool AggregateCoarseSpace::assemble(const BlockSparseMatrix& A, const VertexFilter& filter,
                                    TaskSystem* tasks) {
  if (!built(A)) build(A);
  m_factorised = false;
  // Aggregate I's rows write only the blocks (I, J), each in its rows' order: any split of the
  // aggregates over threads gives the same sums.
  const auto assembleAggregates = [&](Index begin, Index end) {
    Real nonFinite = 0;
    for (Index aggregate = begin; aggregate < end; ++aggregate) {
      for (Index b = m_blockRowOffsets[aggregate]; b < m_blockRowOffsets[aggregate + 1]; ++b) {
        m_blocks[b].setZero();
      }
      for (Index k = m_memberOffsets[aggregate]; k < m_memberOffsets[aggregate + 1]; ++k) {
        const Index row = m_members[k];
        const ConstraintKind rowKind = filter.kind(row);
        if (rowKind == ConstraintKind::Fixed) continue;
        const Mat3 rowProjection =
            rowKind == ConstraintKind::Free ? Mat3::Identity() : filter.projection(row);
        for (Index slot = A.rowBegin(row); slot < A.rowEnd(row); ++slot) {
          const Index column = A.column(slot);
          const ConstraintKind columnKind = filter.kind(column);
          if (columnKind == ConstraintKind::Fixed) continue;
          Mat3& target = m_blocks[m_slotBlock[slot]];
          if (rowKind == ConstraintKind::Free && columnKind == ConstraintKind::Free) {
            target += A.block(slot);
          } else {
            const Mat3 columnProjection =
                columnKind == ConstraintKind::Free ? Mat3::Identity() : filter.projection(column);
            target.noalias() += rowProjection * A.block(slot) * columnProjection;
          }
        }
      }
      // The shift that keeps A_c definite where S P₀ loses a translation (header).
      Mat3& diagonal = m_blocks[m_diagonalBlock[aggregate]];
      const Real mean = diagonal.trace() / 3;
      diagonal.diagonal().array() += mean > 0 ? Real(1e-10) * mean : Real(1);
      // Into A_c's values (upper triangle, AMD order): every block of row I, once.
      Real* values = m_matrix.valuePtr();
      for (Index b = m_blockRowOffsets[aggregate]; b < m_blockRowOffsets[aggregate + 1]; ++b) {
        const Real* entries = m_blocks[b].data();  // column-major: entry (a, c) at a + 3c
        for (int a = 0; a < 3; ++a) {
          for (int c = 0; c < 3; ++c) {
            const int value = m_blockValues[b][3 * a + c];
            if (value >= 0) values[value] = entries[a + 3 * c];
          }
        }
        nonFinite += m_blocks[b].allFinite() ? 0 : 1;
      }
    }
    return nonFinite;
  };
  constexpr Index kGrainAggregates = 64;
  const Real nonFinite =
      tasks ? tasks->parallelReduce(m_aggregateCount, kGrainAggregates, Real(0), assembleAggregates,
                                    [](Real a, Real b) { return a + b; })
            : assembleAggregates(0, m_aggregateCount);
  if (nonFinite > 0) return false;
  m_solver.factorizeInPlace(m_matrix);
  m_factorised = m_solver.info() == Eigen::Success && m_solver.definite();
  return m_factorised;
}

Real AggregateCoarseSpace::addCorrection(const VertexFilter& filter, const Vec3Array& r,
                                         Vec3Array& z, TaskSystem* tasks) {
  if (!m_factorised) return 0;
  const Index rows = Index(m_aggregateOf.size());
  // P₀ᵀ r: each aggregate sums its rows in row order.
  const auto restrictAggregates = [&](Index begin, Index end, int) {
    for (Index aggregate = begin; aggregate < end; ++aggregate) {
      Vec3 sum = Vec3::Zero();
      for (Index k = m_memberOffsets[aggregate]; k < m_memberOffsets[aggregate + 1]; ++k) {
        sum += r[m_members[k]];
      }
      for (int a = 0; a < 3; ++a) m_restricted[m_coarseIndex[3 * aggregate + a]] = sum[a];
    }
  };
  constexpr Index kGrainAggregates = 256;
  if (tasks) {
    tasks->parallelFor(m_aggregateCount, kGrainAggregates, restrictAggregates);
  } else {
    restrictAggregates(0, m_aggregateCount, 0);
  }
  m_coarse = m_solver.solve(m_restricted);
  const auto prolong = [&](Index begin, Index end) {
    Real sum = 0;
    for (Index row = begin; row < end; ++row) {
      const Index base = 3 * m_aggregateOf[row];
      const Vec3 motion(m_coarse[m_coarseIndex[base]], m_coarse[m_coarseIndex[base + 1]],
                        m_coarse[m_coarseIndex[base + 2]]);
      z[row] += filter.filter(row, motion);
      sum += r[row].dot(z[row]);
    }
    return sum;
  };
  constexpr Index kGrain = 2048;
  if (!tasks) {
    Real sum = 0;
    for (Index begin = 0; begin < rows; begin += kGrain) {
      sum += prolong(begin, std::min(rows, begin + kGrain));
    }
    return sum;
  }
  return tasks->parallelReduce(rows, kGrain, Real(0), prolong,
                               [](Real a, Real b) { return a + b; });
}

}  // namespace weft
