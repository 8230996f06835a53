// Heap accounting for the engine tests: the global operator new of the test binary is replaced
// in StepAllocationTest.cpp, which also counts the bytes every allocation holds (the allocator's
// usable size, so what a vector really costs).
#pragma once

namespace weft::test {

/// Bytes allocated through operator new and not yet freed.
long long heapLiveBytes();
/// The most bytes live at once since the last resetHeapPeak().
long long heapPeakBytes();
/// Starts a new peak at the bytes live now.
void resetHeapPeak();

}  // namespace weft::test
