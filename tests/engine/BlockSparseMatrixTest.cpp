// Tests of BlockSparseMatrix: the pattern (slots, duplicates, sorted rows) and the products.
#include <solver/BlockSparseMatrix.h>

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <array>
#include <limits>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace weft {
namespace {

using Pair = std::array<Index, 2>;

/// A chain plus random extra couplings, with some pairs repeated in both orders.
std::vector<Pair> randomPairs(Index vertexCount, Index extraPairs, std::mt19937& random) {
  std::vector<Pair> pairs;
  for (Index i = 0; i + 1 < vertexCount; ++i) pairs.push_back({i, i + 1});
  std::uniform_int_distribution<Index> pick(0, vertexCount - 1);
  for (Index k = 0; k < extraPairs; ++k) {
    const Index i = pick(random);
    const Index j = pick(random);
    if (i != j) pairs.push_back({i, j});
  }
  // Duplicates, reversed and as is: elements sharing an edge name the same pair many times.
  const size_t original = pairs.size();
  for (size_t k = 0; k < original; k += 3) {
    pairs.push_back({pairs[k][1], pairs[k][0]});
    pairs.push_back(pairs[k]);
  }
  return pairs;
}

Eigen::VectorXd flatten(const Vec3Array& x) {
  Eigen::VectorXd flat(3 * x.size());
  for (size_t i = 0; i < x.size(); ++i) flat.segment<3>(3 * i) = x[i];
  return flat;
}

Vec3Array randomVectors(Index count, std::mt19937& random) {
  std::uniform_real_distribution<Real> uniform(-1, 1);
  Vec3Array x(count);
  for (Vec3& v : x) v = Vec3(uniform(random), uniform(random), uniform(random));
  return x;
}

void fillRandomBlocks(BlockSparseMatrix& matrix, std::mt19937& random) {
  std::uniform_real_distribution<Real> uniform(-1, 1);
  for (Index s = 0; s < matrix.blockCount(); ++s) {
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) matrix.block(s)(a, b) = uniform(random);
    }
  }
}

TEST(BlockSparseMatrix, SlotsExistForEveryPairInBothOrdersAndOnlyForThem) {
  std::mt19937 random(7);
  const Index vertexCount = 60;
  const std::vector<Pair> pairs = randomPairs(vertexCount, 80, random);
  BlockSparseMatrix matrix(vertexCount, pairs);
  ASSERT_EQ(matrix.blockRows(), vertexCount);

  std::set<std::pair<Index, Index>> coupled;
  for (const Pair& p : pairs) {
    coupled.insert({p[0], p[1]});
    coupled.insert({p[1], p[0]});
  }
  std::set<Index> seenSlots;
  for (Index row = 0; row < vertexCount; ++row) {
    EXPECT_EQ(matrix.slot(row, row), matrix.diagonalSlot(row)) << "row " << row;
    EXPECT_EQ(matrix.column(matrix.diagonalSlot(row)), row);
    for (Index col = 0; col < vertexCount; ++col) {
      const Index slot = matrix.slot(row, col);
      if (row == col || coupled.count({row, col}) != 0) {
        ASSERT_NE(slot, kInvalidIndex) << "(" << row << ", " << col << ") should be stored";
        EXPECT_EQ(matrix.column(slot), col);
        EXPECT_GE(slot, matrix.rowBegin(row));
        EXPECT_LT(slot, matrix.rowEnd(row));
        EXPECT_TRUE(seenSlots.insert(slot).second) << "slot " << slot << " returned twice";
      } else {
        EXPECT_EQ(slot, kInvalidIndex) << "(" << row << ", " << col << ") is not coupled";
      }
    }
  }
  EXPECT_EQ(seenSlots.size(), matrix.blockCount());
  EXPECT_EQ(matrix.slot(0, vertexCount), kInvalidIndex);
  EXPECT_EQ(matrix.slot(vertexCount, 0), kInvalidIndex);
}

TEST(BlockSparseMatrix, DuplicatePairsAreMergedAndRowsSorted) {
  // 0–1 five times in both orders, 2–3 twice, a self pair: 4 diagonal + 2·2 off-diagonal blocks.
  const std::vector<Pair> pairs = {{0, 1}, {1, 0}, {0, 1}, {2, 3}, {1, 0}, {3, 2}, {0, 1}, {2, 2}};
  BlockSparseMatrix matrix(4, pairs);
  EXPECT_EQ(matrix.blockCount(), 8u);
  EXPECT_EQ(matrix.rowEnd(0) - matrix.rowBegin(0), 2u);
  EXPECT_EQ(matrix.slot(0, 2), kInvalidIndex);
  EXPECT_EQ(matrix.slot(1, 3), kInvalidIndex);

  std::mt19937 random(3);
  const BlockSparseMatrix large(200, randomPairs(200, 400, random));
  for (Index row = 0; row < large.blockRows(); ++row) {
    for (Index s = large.rowBegin(row) + 1; s < large.rowEnd(row); ++s) {
      EXPECT_LT(large.column(s - 1), large.column(s)) << "row " << row << " not strictly sorted";
    }
  }
}

TEST(BlockSparseMatrix, BlocksStartAtZeroAndSetZeroKeepsThePattern) {
  std::mt19937 random(11);
  BlockSparseMatrix matrix(30, randomPairs(30, 40, random));
  for (Index s = 0; s < matrix.blockCount(); ++s) EXPECT_TRUE(matrix.block(s).isZero(0));
  const Index blockCount = matrix.blockCount();
  fillRandomBlocks(matrix, random);
  matrix.setZero();
  EXPECT_EQ(matrix.blockCount(), blockCount);
  for (Index s = 0; s < matrix.blockCount(); ++s) EXPECT_TRUE(matrix.block(s).isZero(0));
}

TEST(BlockSparseMatrix, MultiplyMatchesEigen) {
  std::mt19937 random(5);
  const Index vertexCount = 300;
  BlockSparseMatrix matrix(vertexCount, randomPairs(vertexCount, 500, random));
  fillRandomBlocks(matrix, random);
  const Vec3Array x = randomVectors(vertexCount, random);
  Vec3Array y(vertexCount);
  matrix.multiply(x, y);

  const Eigen::SparseMatrix<Real> eigenMatrix = matrix.toEigen();
  ASSERT_EQ(eigenMatrix.rows(), 3 * vertexCount);
  ASSERT_EQ(eigenMatrix.nonZeros(), 9 * static_cast<Eigen::Index>(matrix.blockCount()));
  const Eigen::VectorXd expected = eigenMatrix * flatten(x);
  const Eigen::VectorXd actual = flatten(y);
  EXPECT_LE((actual - expected).lpNorm<Eigen::Infinity>(), 1e-12 * expected.lpNorm<Eigen::Infinity>());

  // Each block sits where the pattern says: compare one off-diagonal block entry by entry.
  const Index slot = matrix.slot(10, 11);
  ASSERT_NE(slot, kInvalidIndex);
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      EXPECT_EQ(eigenMatrix.coeff(30 + a, 33 + b), matrix.block(slot)(a, b));
    }
  }
}

TEST(BlockSparseMatrix, MultiplyRowsOverAnySplitIsBitwiseEqualToMultiply) {
  std::mt19937 random(9);
  const Index vertexCount = 257;
  BlockSparseMatrix matrix(vertexCount, randomPairs(vertexCount, 600, random));
  fillRandomBlocks(matrix, random);
  const Vec3Array x = randomVectors(vertexCount, random);
  Vec3Array whole(vertexCount);
  matrix.multiply(x, whole);

  for (Index split : {Index(0), Index(1), Index(100), Index(256), vertexCount}) {
    Vec3Array parts(vertexCount, Vec3::Constant(std::numeric_limits<Real>::quiet_NaN()));
    // Second range first: the order the ranges run in must not matter either.
    matrix.multiplyRows(split, vertexCount, x, parts);
    matrix.multiplyRows(0, split, x, parts);
    for (Index i = 0; i < vertexCount; ++i) {
      ASSERT_EQ(parts[i], whole[i]) << "split " << split << ", row " << i;
    }
  }
}

}  // namespace
}  // namespace weft
