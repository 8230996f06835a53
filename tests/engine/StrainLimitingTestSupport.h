// Shared by the strain limiter's unit tests (StrainLimitingTest, StrainLimitingContactTest,
// StrainLimitingSelfContactTest), which build their edges by hand.
#pragma once

#include <weft/engine/ClothModel.h>

namespace weft::test {

/// The step the limiter's velocity update divides by, s.
constexpr Real kStep = 1.0 / 60.0;

/// An edge between vertices a and b with the given rest length, m.
inline Edge makeEdge(Index a, Index b, Real restLength) {
  Edge edge;
  edge.vertices = {a, b};
  edge.restLength = restLength;
  return edge;
}

}  // namespace weft::test
