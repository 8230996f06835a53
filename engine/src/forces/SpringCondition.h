// SpringCondition: the Hooke spring of mass-spring cloth as a Baraff–Witkin condition.
//
//     x0 o~~~~~~~~~~o x1        L = x0 − x1,   C = |L| − R
//
// With E = k/2 C² this is Provot's (1995) linear spring: F0 = −k (|L| − R) L/|L| = −F1, and the
// condition damping −k_d Ċ ∇C damps only the relative velocity along the spring. |L| is convex,
// so the condition is convex and StiffnessMode::Definite keeps its geometric stiffness while the
// spring is stretched (Condition.h). The stiffness k is in N/m per spring.
#pragma once

#include <forces/Condition.h>
#include <weft/Math.h>

namespace weft {

/// Spring condition |x0 − x1| − restLength (m) with gradient and, when asked, Hessian. A collapsed
/// spring (|x0 − x1| ≈ 0) has no direction: its gradient and Hessian are zero, its value finite.
Condition<2> springCondition(const Vec3& x0, const Vec3& x1, Real restLength, bool withHessian);

}  // namespace weft
