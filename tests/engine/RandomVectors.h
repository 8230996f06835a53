// Random vectors for the solver tests: reproducible from a seeded std::mt19937.
#pragma once

#include <weft/Math.h>

#include <random>

namespace weft::test {

/// A vector with components uniform in [−1, 1].
inline Vec3 randomVec3(std::mt19937& random) {
  std::uniform_real_distribution<Real> uniform(-1, 1);
  return Vec3(uniform(random), uniform(random), uniform(random));
}

}  // namespace weft::test
