// RigidFit: the best rigid motion of one point set onto another (the pin teleport's carry).
#include "RigidFit.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <numbers>
#include <vector>

namespace weft {
namespace {

Mat3 turn(Real angle, const Vec3& axis) {
  return Eigen::AngleAxis<Real>(angle, axis.normalized()).toRotationMatrix();
}

std::vector<Vec3> moved(const std::vector<Vec3>& points, const Mat3& rotation, const Vec3& shift) {
  std::vector<Vec3> out;
  for (const Vec3& p : points) out.push_back(rotation * p + shift);
  return out;
}

const Vec3 kGravity(0, -9.81, 0);

TEST(RigidFit, RecoversATurnAndAJumpOfPointsInAPlane) {
  const std::vector<Vec3> from = {{0, 0, 0}, {0.4, 0, 0}, {0, 0.3, 0}, {0.4, 0.3, 0}, {0.1, 0.2, 0}};
  for (const Mat3& rotation : {turn(std::numbers::pi, Vec3::UnitY()), turn(2.1, Vec3(0.3, -0.5, 0.8)),
                               turn(1e-3, Vec3::UnitX())}) {
    const Vec3 shift(10, -2, 3);
    const std::vector<Vec3> to = moved(from, rotation, shift);
    const RigidFit fit = fitRigidMotion(from, to, kGravity);
    EXPECT_EQ(fit.kind, RigidFitKind::Full);
    EXPECT_LT((fit.rotation - rotation).norm(), 1e-14);
    for (std::size_t k = 0; k < from.size(); ++k) EXPECT_LT((fit.apply(from[k]) - to[k]).norm(), 1e-13);
  }
}

TEST(RigidFit, AngleIsTheTurnAboutTheAxis) {
  // pinTeleportAngle compares against it: exact at 0 and π, where acos is at its ends.
  for (Real angle : {Real(0), Real(1e-3), Real(0.5), std::numbers::pi / 2, Real(3.0), std::numbers::pi}) {
    RigidFit fit;
    fit.rotation = turn(angle, Vec3(0.3, -0.5, 0.8));
    EXPECT_NEAR(fit.angle(), angle, 1e-7) << angle;  // acos loses half the digits near 0 and π
  }
  RigidFit identity;
  EXPECT_EQ(identity.angle(), 0.0);
}

TEST(RigidFit, NeverReturnsAReflection) {
  // The targets are the points mirrored (z → −z of a non-planar set): the best proper rotation,
  // det +1, not the mirror.
  const std::vector<Vec3> from = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  std::vector<Vec3> to = from;
  for (Vec3& p : to) p.z() = -p.z();
  const RigidFit fit = fitRigidMotion(from, to, kGravity);
  EXPECT_NEAR(fit.rotation.determinant(), 1.0, 1e-14);
  EXPECT_LT((fit.rotation * fit.rotation.transpose() - Mat3::Identity()).norm(), 1e-14);
}

TEST(RigidFit, APureTranslationIsExactlyOne) {
  const std::vector<Vec3> from = {{0.1, 1, 0}, {0.5, 1, 0.2}, {0.3, 0.7, -0.1}};
  const Vec3 shift(10, 2, -3);
  const RigidFit fit = fitRigidMotion(from, moved(from, Mat3::Identity(), shift), kGravity);
  EXPECT_TRUE(fit.translationOnly());
  EXPECT_EQ(fit.rotation, Mat3::Identity());
  // The carry adds the mean jump, as the translation-only teleport did.
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : from) mean += (p + shift) - p;
  mean /= Real(from.size());
  EXPECT_EQ(fit.apply(from[0]), Vec3(from[0] + mean));
}

TEST(RigidFit, OnePointOrCoincidentPointsGiveTheTranslation) {
  const std::vector<Vec3> one = {{1, 2, 3}};
  RigidFit fit = fitRigidMotion(one, moved(one, turn(1.0, Vec3::UnitZ()), Vec3(5, 0, 0)), kGravity);
  EXPECT_EQ(fit.kind, RigidFitKind::Translation);
  EXPECT_EQ(fit.rotation, Mat3::Identity());
  const std::vector<Vec3> same = {{1, 2, 3}, {1, 2, 3}, {1, 2, 3}};
  fit = fitRigidMotion(same, moved(same, turn(1.0, Vec3::UnitZ()), Vec3(5, 0, 0)), kGravity);
  EXPECT_EQ(fit.kind, RigidFitKind::Translation);
}

TEST(RigidFit, CollinearPointsTurnTheirLineKeepingGravitysPlane) {
  // A row of pins along x.
  std::vector<Vec3> row;
  for (int k = 0; k < 9; ++k) row.push_back(Vec3(-0.2 + 0.05 * k, 1.0, 0.0));
  // Turned about the vertical (a half-turn too, where the smallest rotation has no axis) or about
  // a horizontal axis across the line: recovered exactly.
  for (const Mat3& rotation : {turn(std::numbers::pi, Vec3::UnitY()), turn(std::numbers::pi / 2, Vec3::UnitY()),
                               turn(0.7, Vec3::UnitY()), turn(std::numbers::pi / 3, Vec3::UnitZ())}) {
    const RigidFit fit = fitRigidMotion(row, moved(row, rotation, Vec3(3, 4, 5)), kGravity);
    EXPECT_EQ(fit.kind, RigidFitKind::Line);
    EXPECT_LT((fit.rotation - rotation).norm(), 1e-14);
  }
  // A turn about the line itself cannot be seen: the fit maps the line and leaves the rest.
  const RigidFit about = fitRigidMotion(row, moved(row, turn(1.0, Vec3::UnitX()), Vec3::Zero()), kGravity);
  EXPECT_TRUE(about.translationOnly());
  // Without gravity: the smallest rotation that maps the line onto the new one (about z here).
  const RigidFit smallest =
      fitRigidMotion(row, moved(row, turn(0.5, Vec3(0, 0, 1)), Vec3::Zero()), Vec3::Zero());
  EXPECT_LT((smallest.rotation - turn(0.5, Vec3(0, 0, 1))).norm(), 1e-14);
  // A line along gravity's axis turned to lie across it: the smallest rotation.
  std::vector<Vec3> column;
  for (int k = 0; k < 5; ++k) column.push_back(Vec3(0, 0.1 * k, 0));
  const Mat3 tip = turn(std::numbers::pi / 2, Vec3::UnitZ());
  const RigidFit tipped = fitRigidMotion(column, moved(column, tip, Vec3::Zero()), kGravity);
  EXPECT_EQ(tipped.kind, RigidFitKind::Line);
  EXPECT_LT((tipped.rotation - tip).norm(), 1e-14);
}

}  // namespace
}  // namespace weft
