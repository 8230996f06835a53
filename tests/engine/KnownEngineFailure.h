// A test condition the engine is known to fail, reported instead of asserted: the test prints
// `KNOWN ENGINE FAILURE` with the reason (which carries the measured figure) and ends SKIPPED,
// so ctest lists it, while every other condition of the test is still asserted.
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace weft::test {

/// Reports `what` as a known engine failure with `reason`. When it fails, the test ends SKIPPED
/// (a later failing expectation still fails it); when it passes, the message says to drop the
/// mark.
inline void knownEngineFailure(bool passed, const std::string& what, const std::string& reason) {
  std::printf("[known] KNOWN ENGINE FAILURE, not asserted: %s (%s): %s\n", what.c_str(),
              passed ? "passes now; drop the mark" : "fails", reason.c_str());
  if (!passed) {
    ::testing::Test::RecordProperty("known_failure", what + ": " + reason);
    GTEST_SKIP() << "KNOWN ENGINE FAILURE: " << what << ": " << reason;
  }
}

}  // namespace weft::test
