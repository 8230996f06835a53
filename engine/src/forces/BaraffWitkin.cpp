// Baraff–Witkin stretch, shear and bend kernels; see BaraffWitkin.h for the conventions.
//
// Everything here is fixed-size Eigen and allocation-free: these run once per triangle and hinge
// per substep, inside the parallel assembly.
//
// Bend derivatives. With z = (n_A, n_B, e) ∈ R⁹ treated as independent,
//
//     s = e · (n_B × n_A)   (trilinear)      y = s / |e|      c = n_A · n_B   (bilinear)
//     θ = atan2(y, c),   r² = y² + c² = |n_A|² |n_B|²  (for z that comes from a hinge)
//
//     ∂θ/∂y = c/r²    ∂θ/∂c = −y/r²    ∂²θ/∂y² = −2yc/r⁴ = −∂²θ/∂c²    ∂²θ/∂y∂c = (y² − c²)/r⁴
//
// give ∇_z θ and ∇²_z θ in closed form. The positions enter through z(x), whose Jacobian J is 9×12
// and whose only second derivatives come from the two cross products, so
//
//     ∇_x θ  = Jᵀ ∇_z θ
//     ∇²_x θ = Jᵀ ∇²_z θ J + Σ_k (∂θ/∂z_k) ∂²z_k/∂x²
//
// and for a bilinear a × b, g · (a × b) has the constant second derivative −[g]× in the (a, b)
// block and +[g]× in (b, a), where [g]× is the cross-product matrix (g × v = [g]× v).
#include <forces/BaraffWitkin.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace weft {
namespace {

using Vec9 = Eigen::Matrix<Real, 9, 1>;
using Mat9 = Eigen::Matrix<Real, 9, 9>;
using Mat9x12 = Eigen::Matrix<Real, 9, 12>;
using Mat12 = Eigen::Matrix<Real, 12, 12>;

constexpr Real kPi = std::numbers::pi_v<Real>;

/// Below this |w| (a dimensionless stretch ratio; 1 at rest) the stretch direction is undefined.
/// The Hessian grows like 1/|w|, so the threshold also caps it at a finite 1e8 · √a · weights².
constexpr Real kMinStretchRatio = 1e-8;

/// A unit vector across the unit vector `d`: the world axis least aligned with it (the first on
/// a tie), less its part along d.
Vec3 acrossDirection(const Vec3& d) {
  int axis = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::abs(d[k]) < std::abs(d[axis])) axis = k;
  }
  const Vec3 e = Vec3::Unit(axis);
  return (e - e.dot(d) * d).normalized();
}

/// A hinge whose edge, or whose triangle heights, are below this fraction of its longest edge is
/// treated as degenerate: θ's gradient grows like 1/height and its Hessian like 1/height².
constexpr Real kDegenerateHingeRatio = 1e-8;

/// Maps an angle difference into (−π, π], so a hinge at rest near ±π does not see a 2π jump.
Real wrapAngle(Real angle) {
  if (angle > kPi) {
    angle -= 2 * kPi;
  } else if (angle <= -kPi) {
    angle += 2 * kPi;
  }
  return angle;
}

/// θ from the hinge's normals and edge. atan2(s, |e| c) equals atan2(s/|e|, c) and needs no
/// division, so a collapsed edge gives atan2(0, 0) = 0 instead of NaN.
Real angleFromNormals(const Vec3& normalA, const Vec3& normalB, const Vec3& edge) {
  const Real sine = edge.dot(normalB.cross(normalA));
  const Real cosine = edge.norm() * normalA.dot(normalB);
  const Real angle = std::atan2(sine, cosine);
  // atan2 returns −π for (−0, negative); the documented range is (−π, π].
  return angle <= -kPi ? kPi : angle;
}

/// Fills a stretch condition √a (|w| − b) for w = Σ weights[i] x_i. `collapsedDirection` (unit)
/// stands for w / |w| when |w| is below kMinStretchRatio (the fibre collapsed to a point).
void fillStretchCondition(const Vec3& w, const Vec3& collapsedDirection,
                          const std::array<Real, 3>& weights, Real sqrtArea, Real restScale,
                          bool withHessian, Condition<3>& condition) {
  condition.convex = true;  // |w| is convex in w and w is linear in x
  const Real length = w.norm();
  condition.value = sqrtArea * (length - restScale);
  if (!(length > kMinStretchRatio)) {
    // Any unit vector is a subgradient of |w| at 0; the given one pushes the fibre open. The
    // Hessian, (I − ŵŵᵀ)/|w|, is unbounded there; it enters the system only for a stretched
    // condition (Condition.h), and this one is compressed, so it is left zero.
    for (int i = 0; i < 3; ++i) {
      condition.gradient.segment<3>(3 * i) = (sqrtArea * weights[i]) * collapsedDirection;
    }
    return;
  }
  const Vec3 direction = w / length;
  for (int i = 0; i < 3; ++i) {
    condition.gradient.segment<3>(3 * i) = (sqrtArea * weights[i]) * direction;
  }
  if (withHessian) {
    // ∂²|w|/∂w² = (I − ŵŵᵀ)/|w|, the projector across the fibre direction.
    const Mat3 across =
        (Mat3::Identity() - direction * direction.transpose()) * (sqrtArea / length);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        condition.hessian.block<3, 3>(3 * i, 3 * j) = (weights[i] * weights[j]) * across;
      }
    }
  }
}

/// Adds Σ_k g_k ∂²(a × b)_k/∂x² for a = Σ aCoefficients[i] x_i, b = Σ bCoefficients[i] x_i.
void addCrossProductCurvature(const Vec3& g, const std::array<Real, 4>& aCoefficients,
                              const std::array<Real, 4>& bCoefficients, Mat12& hessian) {
  const Mat3 gCross = crossMatrix(g);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      const Real weight = bCoefficients[i] * aCoefficients[j] - aCoefficients[i] * bCoefficients[j];
      if (weight != 0) {
        hessian.block<3, 3>(3 * i, 3 * j) += weight * gCross;
      }
    }
  }
}

}  // namespace

TriangleRest makeTriangleRest(std::array<Index, 3> vertices, const Vec2& uv0, const Vec2& uv1,
                              const Vec2& uv2) {
  const Vec2 d1 = uv1 - uv0;
  const Vec2 d2 = uv2 - uv0;
  // [w_u w_v] = [x1 − x0, x2 − x0] · M⁻¹ with M = [[Δu1, Δu2], [Δv1, Δv2]] (BW98 eq. 9).
  const Real det = d1.x() * d2.y() - d2.x() * d1.y();
  const Real invDet = 1 / det;

  TriangleRest rest;
  rest.vertices = vertices;
  rest.area = std::abs(det) / 2;
  // w_u = (Δv2 (x1 − x0) − Δv1 (x2 − x0)) / det, w_v = (Δu1 (x2 − x0) − Δu2 (x1 − x0)) / det.
  rest.warpWeights[1] = d2.y() * invDet;
  rest.warpWeights[2] = -d1.y() * invDet;
  rest.weftWeights[1] = -d2.x() * invDet;
  rest.weftWeights[2] = d1.x() * invDet;
  // Weights sum to zero exactly, so a rigid translation leaves w_u and w_v bit-for-bit unchanged.
  rest.warpWeights[0] = -(rest.warpWeights[1] + rest.warpWeights[2]);
  rest.weftWeights[0] = -(rest.weftWeights[1] + rest.weftWeights[2]);
  return rest;
}

StretchConditions stretchConditions(const Vec3& x0, const Vec3& x1, const Vec3& x2,
                                    const TriangleRest& rest, Real warpRestScale,
                                    Real weftRestScale, bool withHessian) {
  const auto& wu = rest.warpWeights;
  const auto& wv = rest.weftWeights;
  const Vec3 warp = wu[0] * x0 + wu[1] * x1 + wu[2] * x2;
  const Vec3 weft = wv[0] * x0 + wv[1] * x1 + wv[2] * x2;
  // √a rather than BW98's a: E = k a/2 (|w| − b)², so k is in N/m on any mesh resolution.
  const Real sqrtArea = std::sqrt(rest.area);

  // A fibre collapsed to a point (|w| ≈ 0: every vertex of a cloth on one point or one line) has
  // no direction, and without one it feels no stretch force and never opens. It is given one
  // across the other fibre, or, both collapsed, warp along x and weft across it: the same rule on
  // every triangle, so that a collapsed cloth is pushed open consistently toward a flat sheet.
  const bool warpCollapsed = !(warp.norm() > kMinStretchRatio);
  const bool weftCollapsed = !(weft.norm() > kMinStretchRatio);
  Vec3 warpFallback = Vec3::UnitX(), weftFallback = Vec3::UnitY();
  if (warpCollapsed && !weftCollapsed) warpFallback = acrossDirection(weft.normalized());
  if (weftCollapsed) weftFallback = acrossDirection(warpCollapsed ? warpFallback : warp.normalized());
  StretchConditions conditions;
  fillStretchCondition(warp, warpFallback, wu, sqrtArea, warpRestScale, withHessian, conditions.warp);
  fillStretchCondition(weft, weftFallback, wv, sqrtArea, weftRestScale, withHessian, conditions.weft);
  return conditions;
}

Condition<3> shearCondition(const Vec3& x0, const Vec3& x1, const Vec3& x2,
                            const TriangleRest& rest, bool withHessian) {
  const auto& wu = rest.warpWeights;
  const auto& wv = rest.weftWeights;
  const Vec3 warp = wu[0] * x0 + wu[1] * x1 + wu[2] * x2;
  const Vec3 weft = wv[0] * x0 + wv[1] * x1 + wv[2] * x2;
  const Real sqrtArea = std::sqrt(rest.area);  // same area scaling as stretch

  Condition<3> condition;
  condition.convex = false;  // w_u · w_v is a saddle in (w_u, w_v)
  condition.value = sqrtArea * warp.dot(weft);
  for (int i = 0; i < 3; ++i) {
    condition.gradient.segment<3>(3 * i) = sqrtArea * (wu[i] * weft + wv[i] * warp);
  }
  if (withHessian) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        condition.hessian.block<3, 3>(3 * i, 3 * j) =
            (sqrtArea * (wu[i] * wv[j] + wv[i] * wu[j])) * Mat3::Identity();
      }
    }
  }
  return condition;
}

StretchShearRest makeStretchShearRest(const TriangleRest& rest, Real warpRestScale,
                                      Real weftRestScale) {
  StretchShearRest out;
  out.sqrtArea = std::sqrt(rest.area);
  out.inverseSqrtArea = 1 / out.sqrtArea;
  for (int i = 1; i < 3; ++i) {
    out.warpWeights[i] = out.sqrtArea * rest.warpWeights[i];
    out.weftWeights[i] = out.sqrtArea * rest.weftWeights[i];
  }
  // Weights summing to zero, as makeTriangleRest's: the kernel works on edges from x0.
  out.warpWeights[0] = -(out.warpWeights[1] + out.warpWeights[2]);
  out.weftWeights[0] = -(out.weftWeights[1] + out.weftWeights[2]);
  out.warpRestLength = out.sqrtArea * warpRestScale;
  out.weftRestLength = out.sqrtArea * weftRestScale;
  return out;
}

StretchShearTerms stretchShear(const std::array<Vec3, 3>& x, const std::array<Vec3, 3>& v,
                               const std::array<Vec3, 3>& u, const StretchShearRest& rest,
                               const StretchShearCoefficients& k, Real h, bool withSystem) {
  const std::array<Real, 3>& a = rest.warpWeights;
  const std::array<Real, 3>& b = rest.weftWeights;
  // The weights sum to zero, so W = Σ a_i x_i = a_1 (x_1 − x_0) + a_2 (x_2 − x_0): a rigid
  // translation changes nothing, to the bit.
  const Vec3 edge1 = x[1] - x[0], edge2 = x[2] - x[0];
  const Vec3 warp = a[1] * edge1 + a[2] * edge2;  // W_u = √a w_u, m
  const Vec3 weft = b[1] * edge1 + b[2] * edge2;
  const Vec3 rate1 = v[1] - v[0], rate2 = v[2] - v[0];
  const Vec3 warpRate = a[1] * rate1 + a[2] * rate2;  // Ẇ_u
  const Vec3 weftRate = b[1] * rate1 + b[2] * rate2;
  const Real warpLength = warp.norm(), weftLength = weft.norm();

  // Fibre directions; a collapsed fibre (|w| ≤ kMinStretchRatio) gets the direction
  // stretchConditions gives it, and no curvature term.
  const Real minLength = kMinStretchRatio * rest.sqrtArea;
  const bool warpCollapsed = !(warpLength > minLength);
  const bool weftCollapsed = !(weftLength > minLength);
  Vec3 warpDirection = warpCollapsed ? Vec3::UnitX() : Vec3((1 / warpLength) * warp);
  Vec3 weftDirection = weftCollapsed ? Vec3::UnitY() : Vec3((1 / weftLength) * weft);
  if (warpCollapsed && !weftCollapsed) warpDirection = acrossDirection(weftDirection);
  if (weftCollapsed) weftDirection = acrossDirection(warpDirection);

  // Conditions and their rates: C_u = |W_u| − √a b_u, Ċ_u = d_u · Ẇ_u; shear C_s = W_u·W_v/√a with
  // corner gradients g_i = a_i w_v + b_i w_u, so Ċ_s = w_v·Ẇ_u + w_u·Ẇ_v.
  const Vec3 warpGradient = rest.inverseSqrtArea * warp;  // w_u
  const Vec3 weftGradient = rest.inverseSqrtArea * weft;  // w_v
  const Real warpValue = warpLength - rest.warpRestLength;
  const Real weftValue = weftLength - rest.weftRestLength;
  const Real shearValue = warp.dot(weftGradient);
  const Real warpSpeed = warpDirection.dot(warpRate);
  const Real weftSpeed = weftDirection.dot(weftRate);
  const Real shearSpeed = weftGradient.dot(warpRate) + warpGradient.dot(weftRate);

  StretchShearTerms terms;
  terms.energy = Real(0.5) * (k.warpStiffness * warpValue * warpValue +
                              k.weftStiffness * weftValue * weftValue +
                              k.shearStiffness * shearValue * shearValue);
  // f_i = −(k C + k_d Ċ) ∇_i C summed: −(a_i F_u + b_i F_v).
  const Real warpScale = k.warpStiffness * warpValue + k.stretchDamping * warpSpeed;
  const Real weftScale = k.weftStiffness * weftValue + k.stretchDamping * weftSpeed;
  const Real shearScale = k.shearStiffness * shearValue + k.shearDamping * shearSpeed;
  const Vec3 warpForce = warpScale * warpDirection + shearScale * weftGradient;
  const Vec3 weftForce = weftScale * weftDirection + shearScale * warpGradient;
  for (int i = 0; i < 3; ++i) terms.force[i] = -(a[i] * warpForce + b[i] * weftForce);
  if (!withSystem) return terms;

  // Definite stiffness of a stretch condition: k d dᵀ + κ (I − d dᵀ), κ = k C/|W| while stretched.
  const Real warpCurvature =
      !warpCollapsed && warpValue > 0 ? k.warpStiffness * warpValue / warpLength : Real(0);
  const Real weftCurvature =
      !weftCollapsed && weftValue > 0 ? k.weftStiffness * weftValue / weftLength : Real(0);

  // (∂f/∂x)·u = −(a_i P_u + b_i P_v), from U_u = Σ a_j u_j, U_v = Σ b_j u_j.
  const Vec3 probe1 = u[1] - u[0], probe2 = u[2] - u[0];
  const Vec3 warpProbe = a[1] * probe1 + a[2] * probe2;
  const Vec3 weftProbe = b[1] * probe1 + b[2] * probe2;
  const Real shearProbe =
      k.shearStiffness * (weftGradient.dot(warpProbe) + warpGradient.dot(weftProbe));
  const Vec3 warpProduct =
      warpCurvature * warpProbe +
      ((k.warpStiffness - warpCurvature) * warpDirection.dot(warpProbe)) * warpDirection +
      shearProbe * weftGradient;
  const Vec3 weftProduct =
      weftCurvature * weftProbe +
      ((k.weftStiffness - weftCurvature) * weftDirection.dot(weftProbe)) * weftDirection +
      shearProbe * warpGradient;
  for (int i = 0; i < 3; ++i) {
    terms.stiffnessTimesVelocity[i] = -(a[i] * warpProduct + b[i] * weftProduct);
  }

  // X_uu, X_vv, X_uv and its transpose (header), element by element: each product of two vector
  // entries is formed before it is scaled, so X_uu and X_vv are symmetric and X_vu is X_uvᵀ, to
  // the bit.
  const Real h2 = h * h;
  const Real shearCoefficient = h2 * k.shearStiffness + h * k.shearDamping;
  const Real warpAlong = h2 * (k.warpStiffness - warpCurvature) + h * k.stretchDamping;
  const Real weftAlong = h2 * (k.weftStiffness - weftCurvature) + h * k.stretchDamping;
  for (int column = 0; column < 3; ++column) {
    for (int row = 0; row < 3; ++row) {
      terms.warpWarp(row, column) = warpAlong * (warpDirection[row] * warpDirection[column]) +
                                    shearCoefficient * (weftGradient[row] * weftGradient[column]);
      terms.weftWeft(row, column) = weftAlong * (weftDirection[row] * weftDirection[column]) +
                                    shearCoefficient * (warpGradient[row] * warpGradient[column]);
      terms.warpWeft(row, column) = shearCoefficient * (weftGradient[row] * warpGradient[column]);
      terms.weftWarp(row, column) = shearCoefficient * (warpGradient[row] * weftGradient[column]);
    }
    terms.warpWarp(column, column) += h2 * warpCurvature;
    terms.weftWeft(column, column) += h2 * weftCurvature;
  }
  return terms;
}

Real dihedralAngle(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  const Vec3 edge = x1 - x0;
  const Vec3 normalA = edge.cross(x2 - x0);
  const Vec3 normalB = (x3 - x0).cross(edge);
  return angleFromNormals(normalA, normalB, edge);
}

Real hingeStiffnessScale(Real restLength, Real areaA, Real areaB) {
  const Real areaSum = areaA + areaB;
  return areaSum > 0 ? 3 * restLength * restLength / areaSum : Real(0);
}

Condition<4> bendCondition(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                           const Hinge& hinge, bool withHessian) {
  const Vec3 edge = x1 - x0;
  const Vec3 sideA = x2 - x0;
  const Vec3 sideB = x3 - x0;
  const Vec3 normalA = edge.cross(sideA);
  const Vec3 normalB = sideB.cross(edge);
  const Real sqrtScale = std::sqrt(std::max(hinge.stiffnessScale, Real(0)));

  Condition<4> condition;
  condition.convex = false;
  condition.value =
      sqrtScale * wrapAngle(angleFromNormals(normalA, normalB, edge) - hinge.restAngle);

  // Scale-free degeneracy test: edge length and triangle heights against the longest edge.
  // Written as !(x > y) so NaN input also lands here.
  const Real longestSquared =
      std::max({edge.squaredNorm(), sideA.squaredNorm(), sideB.squaredNorm()});
  const Real edgeLength = edge.norm();
  const Real minNormal = kDegenerateHingeRatio * longestSquared;  // |n| = |e| · height
  if (!(edgeLength > kDegenerateHingeRatio * std::sqrt(longestSquared)) ||
      !(normalA.norm() > minNormal) || !(normalB.norm() > minNormal)) {
    return condition;
  }

  // --- θ as a function of z = (n_A, n_B, e): slots 0–2, 3–5, 6–8.
  const Real invEdge = 1 / edgeLength;
  const Real triple = edge.dot(normalB.cross(normalA));  // s
  const Real sine = triple * invEdge;                     // y = |n_A||n_B| sin θ
  const Real cosine = normalA.dot(normalB);               // c = |n_A||n_B| cos θ
  const Real radiusSquared = sine * sine + cosine * cosine;
  const Real invRadiusSquared = 1 / radiusSquared;

  Vec9 tripleGradient;  // ∇_z s
  tripleGradient << edge.cross(normalB), normalA.cross(edge), normalB.cross(normalA);
  Vec9 invEdgeGradient = Vec9::Zero();  // ∇_z (1/|e|)
  invEdgeGradient.segment<3>(6) = -edge * (invEdge * invEdge * invEdge);
  const Vec9 sineGradient = invEdge * tripleGradient + triple * invEdgeGradient;
  Vec9 cosineGradient;
  cosineGradient << normalB, normalA, Vec3::Zero();

  const Real dThetaDSine = cosine * invRadiusSquared;
  const Real dThetaDCosine = -sine * invRadiusSquared;
  const Vec9 thetaGradientZ = dThetaDSine * sineGradient + dThetaDCosine * cosineGradient;

  // --- z(x): n_A = e × (x2 − x0), n_B = (x3 − x0) × e, e = x1 − x0.
  Mat9x12 jacobian = Mat9x12::Zero();
  jacobian.block<3, 3>(0, 0) = crossMatrix(x2 - x1);
  jacobian.block<3, 3>(0, 3) = -crossMatrix(sideA);
  jacobian.block<3, 3>(0, 6) = crossMatrix(edge);
  jacobian.block<3, 3>(3, 0) = crossMatrix(x1 - x3);
  jacobian.block<3, 3>(3, 3) = crossMatrix(sideB);
  jacobian.block<3, 3>(3, 9) = -crossMatrix(edge);
  jacobian.block<3, 3>(6, 0) = -Mat3::Identity();
  jacobian.block<3, 3>(6, 3) = Mat3::Identity();

  condition.gradient.noalias() = sqrtScale * (jacobian.transpose() * thetaGradientZ);
  if (!withHessian) {
    return condition;
  }

  // ∇²_z s: the constant second derivatives of the triple product e · (n_B × n_A).
  Mat9 tripleHessian = Mat9::Zero();
  const Mat3 edgeCross = crossMatrix(edge);
  const Mat3 normalACross = crossMatrix(normalA);
  const Mat3 normalBCross = crossMatrix(normalB);
  tripleHessian.block<3, 3>(0, 3) = edgeCross;
  tripleHessian.block<3, 3>(3, 0) = -edgeCross;
  tripleHessian.block<3, 3>(0, 6) = -normalBCross;
  tripleHessian.block<3, 3>(6, 0) = normalBCross;
  tripleHessian.block<3, 3>(3, 6) = normalACross;
  tripleHessian.block<3, 3>(6, 3) = -normalACross;

  // ∇²_z y = ∇²(s/|e|) = ∇²s/|e| + ∇s ∇(1/|e|)ᵀ + ∇(1/|e|) ∇sᵀ + s ∇²(1/|e|).
  const Vec3 edgeDirection = edge * invEdge;
  Mat9 sineHessian = invEdge * tripleHessian;
  sineHessian.noalias() += tripleGradient * invEdgeGradient.transpose();
  sineHessian.noalias() += invEdgeGradient * tripleGradient.transpose();
  sineHessian.block<3, 3>(6, 6) +=
      (triple * invEdge * invEdge * invEdge) *
      (3 * edgeDirection * edgeDirection.transpose() - Mat3::Identity());

  // ∇²_z c: identity blocks coupling n_A and n_B.
  Mat9 cosineHessian = Mat9::Zero();
  cosineHessian.block<3, 3>(0, 3) = Mat3::Identity();
  cosineHessian.block<3, 3>(3, 0) = Mat3::Identity();

  const Real invRadiusFourth = invRadiusSquared * invRadiusSquared;
  const Real d2ThetaDSine2 = -2 * sine * cosine * invRadiusFourth;  // = −∂²θ/∂c²
  const Real d2ThetaDSineDCosine = (sine * sine - cosine * cosine) * invRadiusFourth;

  Mat9 thetaHessianZ = dThetaDSine * sineHessian + dThetaDCosine * cosineHessian;
  thetaHessianZ.noalias() += d2ThetaDSine2 * (sineGradient * sineGradient.transpose() -
                                              cosineGradient * cosineGradient.transpose());
  thetaHessianZ.noalias() += d2ThetaDSineDCosine * (sineGradient * cosineGradient.transpose() +
                                                    cosineGradient * sineGradient.transpose());

  Mat12 thetaHessian;
  thetaHessian.noalias() = jacobian.transpose() * (thetaHessianZ * jacobian);
  // The cross products' own curvature: n_A = (x1 − x0) × (x2 − x0), n_B = (x3 − x0) × (x1 − x0).
  addCrossProductCurvature(thetaGradientZ.segment<3>(0), {-1, 1, 0, 0}, {-1, 0, 1, 0},
                           thetaHessian);
  addCrossProductCurvature(thetaGradientZ.segment<3>(3), {-1, 0, 0, 1}, {-1, 1, 0, 0},
                           thetaHessian);

  // Symmetric in exact arithmetic; symmetrise so the assembled matrix is symmetric to the bit.
  condition.hessian = (sqrtScale / 2) * (thetaHessian + thetaHessian.transpose());
  return condition;
}

}  // namespace weft
