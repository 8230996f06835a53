// FixedStepAccumulator: runs a simulation at a fixed step under a variable display frame rate
// ("Fix Your Timestep", Glenn Fiedler 2004).
//
//   every display frame:  steps = accumulator.advance(frame time)
//                         repeat steps times:  world.step(accumulator.step())
//                         draw: blend the last two states by accumulator.alpha()
//
// The simulation then never sees the display's frame rate: the same inputs give the same steps,
// and so the same bits, at 40 Hz or 144 Hz. After a stall (a debugger, a slow load) at most
// maxStepsPerFrame steps are taken and the rest of the backlog is dropped, so the game slows down
// instead of spending ever longer frames catching up (droppedSteps() counts what was dropped).
#pragma once

#include <weft/Math.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace weft {

/// Turns variable display frame times into a whole number of fixed simulation steps.
class FixedStepAccumulator {
 public:
  /// `step` in s (> 0, finite; otherwise 1/60 s), at most `maxStepsPerFrame` (≥ 1) steps per
  /// advance().
  explicit FixedStepAccumulator(Real step = 1.0 / 60.0, int maxStepsPerFrame = 4)
      : m_step(std::isfinite(step) && step > 0 ? step : 1.0 / 60.0),
        m_maxStepsPerFrame(std::max(1, maxStepsPerFrame)) {}

  /// Adds a display frame's duration (s) and returns how many fixed steps to take now. A
  /// negative or non-finite duration adds nothing (a clock that went backwards is not time).
  int advance(Real frameTime) {
    if (!(std::isfinite(frameTime) && frameTime > 0)) return 0;
    m_accumulated += frameTime;
    // A frame of exactly one step must give one step, not zero and then two: forgive round-off
    // of a millionth of a step.
    int steps = int(std::min<Real>(std::floor(m_accumulated / m_step + kRoundOff), 1e9));
    if (steps > m_maxStepsPerFrame) {
      m_droppedSteps += std::uint64_t(steps - m_maxStepsPerFrame);
      steps = m_maxStepsPerFrame;
      m_accumulated = steps * m_step;  // drop the backlog beyond the cap
    }
    m_accumulated = std::max<Real>(0, m_accumulated - steps * m_step);
    m_totalSteps += std::uint64_t(steps);
    return steps;
  }

  /// Where the display time lies between the last two steps, in [0, 1): blend the previous
  /// state by 1 − alpha and the current one by alpha when drawing.
  Real alpha() const { return std::clamp<Real>(m_accumulated / m_step, 0, 1 - 1e-12); }
  /// s, the fixed step.
  Real step() const { return m_step; }
  /// Steps advance() has returned so far.
  std::uint64_t totalSteps() const { return m_totalSteps; }
  /// Steps dropped because a frame asked for more than maxStepsPerFrame.
  std::uint64_t droppedSteps() const { return m_droppedSteps; }
  /// Forgets the time not yet stepped (after a pause or a load).
  void reset() { m_accumulated = 0; }

 private:
  static constexpr Real kRoundOff = 1e-6;
  Real m_step;
  int m_maxStepsPerFrame;
  Real m_accumulated = 0;
  std::uint64_t m_totalSteps = 0;
  std::uint64_t m_droppedSteps = 0;
};

}  // namespace weft
