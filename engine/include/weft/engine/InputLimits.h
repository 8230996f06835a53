// The largest inputs the engine takes, and why: beyond them a double cannot carry the simulation
// (positions lose their resolution, products of values overflow) or the health monitor would
// call the first frame a divergence. Inputs past a limit are refused with an error naming the
// field and the limit; inputs within run a finite simulation whose status flags say how it went.
#pragma once

#include <weft/Math.h>

namespace weft {

/// m, the largest magnitude of any coordinate of a cloth vertex (rest, placed or set) and of a
/// pin target: doubles resolve 1.2e-10 m there, far below any contact thickness. Worlds larger
/// than this move their origin with the player.
inline constexpr Real kMaxCoordinate = 1e6;

/// m, the farthest from the origin a simulated vertex may go: a vertex beyond it is a failed
/// substep (HealthFailure::OutOfRange), not a state to collide, since doubles there no longer
/// resolve a cloth's thickness against its neighbours' (1.2e-7 m spacing). 10³ × kMaxCoordinate.
inline constexpr Real kMaxSimulatedCoordinate = 1e9;

/// m/s, the fastest a cloth vertex, the wind or a collider may move: the health monitor treats a
/// vertex faster than this as a diverged integration (HealthFailure::Speed) and rolls it back.
inline constexpr Real kMaxSpeed = 1e4;

/// m/s², the largest gravity: a second of free fall reaches kMaxSpeed.
inline constexpr Real kMaxGravity = 1e4;

/// The largest value of any material, spring, mass or force field in its SI unit (stiffness in
/// N/m, density in kg/m², a vertex's mass in kg, an external force in N): products of a few such
/// values stay far inside the double range in the solver's norms (1e300 overflows them).
inline constexpr Real kMaxMaterialValue = 1e30;

}  // namespace weft
