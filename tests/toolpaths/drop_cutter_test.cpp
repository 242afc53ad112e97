// Drop-cutter against triangles: closed forms for planes, ridges and spikes, and an
// independent brute-force oracle (the triangles sampled densely, the cutter's lower surface
// evaluated at every sample) on random triangles.

#include "toolpaths/drop_cutter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <random>

namespace hybridctl::toolpaths {
namespace {

using geometry::Triangle;
using geometry::Vec3;
using Mesh = std::shared_ptr<const std::vector<Triangle>>;

Mesh mesh(std::vector<Triangle> t) { return std::make_shared<const std::vector<Triangle>>(std::move(t)); }

// The plane z = c + x tan(angle), as two triangles over [-50, 50]^2.
Mesh slope(double angle_deg, double c = 0) {
  const double t = std::tan(angle_deg * std::numbers::pi / 180);
  auto z = [&](double x) { return c + x * t; };
  const Vec3 a{-50, -50, z(-50)}, b{50, -50, z(50)}, d{50, 50, z(50)}, e{-50, 50, z(-50)};
  return mesh({{a, b, d}, {a, d, e}});
}

const CutterShape kBall{4, 4}, kBull{5, 1}, kFlat{3, 0};

TEST(CutterShape, LowerSurfaceOfEachShape) {
  EXPECT_DOUBLE_EQ(kFlat.height_at(2.9), 0);
  EXPECT_DOUBLE_EQ(kBall.height_at(0), 0);
  EXPECT_NEAR(kBall.height_at(4), 4, 1e-12);
  EXPECT_NEAR(kBall.height_at(2), 4 - std::sqrt(12.0), 1e-12);
  EXPECT_DOUBLE_EQ(kBull.height_at(4), 0);  // the flat bottom out to R - r
  EXPECT_NEAR(kBull.height_at(5), 1, 1e-12);
  EXPECT_TRUE(std::isinf(kBull.height_at(5.01)));
}

TEST(DropCutter, OnAFlatFaceEveryShapeStandsOnIt) {
  for (const CutterShape& s : {kBall, kBull, kFlat}) {
    const DropCutter drop(slope(0, 7.5), s);
    EXPECT_NEAR(drop.tip_height({3.3, -2.1}), 7.5, 1e-12);
  }
}

TEST(DropCutter, OnASlopeTheBallStandsItsRadiusOffThePlane) {
  for (const double angle : {10.0, 30.0, 60.0}) {
    const double a = angle * std::numbers::pi / 180;
    const DropCutter drop(slope(angle), kBall);
    // The ball's centre lies R along the normal: R / cos(a) above the plane over the axis.
    EXPECT_NEAR(drop.tip_height({1.5, 2}), 1.5 * std::tan(a) + 4 / std::cos(a) - 4, 1e-9) << angle;
  }
}

TEST(DropCutter, OnASlopeTheBullNoseTouchesWithItsUphillCorner) {
  for (const double angle : {10.0, 45.0, 70.0}) {
    const double a = angle * std::numbers::pi / 180;
    const DropCutter drop(slope(angle), kBull);
    // The corner's tube centre, R - r uphill of the axis, stands r / cos(a) above the plane.
    EXPECT_NEAR(drop.tip_height({-2, 0}), (-2 + 4) * std::tan(a) + 1 / std::cos(a) - 1, 1e-9) << angle;
  }
}

TEST(DropCutter, OnASlopeTheFlatEndTouchesWithItsUphillRim) {
  const DropCutter drop(slope(20), kFlat);
  EXPECT_NEAR(drop.tip_height({0, 0}), 3 * std::tan(20 * std::numbers::pi / 180), 1e-9);
}

TEST(DropCutter, ARidgeIsMetOnItsEdge) {
  // A roof with its ridge along Y at x = 0, z = 10, faces falling 30 degrees each way.
  const double t = std::tan(30 * std::numbers::pi / 180);
  const Vec3 r0{0, -50, 10}, r1{0, 50, 10}, l0{-20, -50, 10 - 20 * t}, l1{-20, 50, 10 - 20 * t};
  const Vec3 q0{20, -50, 10 - 20 * t}, q1{20, 50, 10 - 20 * t};
  const DropCutter drop(mesh({{l0, r0, r1}, {l0, r1, l1}, {r0, q0, q1}, {r0, q1, r1}}), kBall);
  // Over the ridge the ball rests on it at its tip.
  EXPECT_NEAR(drop.tip_height({0, 3}), 10, 1e-9);
  // 1 mm to the side the ball still rests on the ridge (its contact point at 1 mm from
  // the axis, short of where the face would touch it: R sin 30 = 2 mm).
  EXPECT_NEAR(drop.tip_height({1, 3}), 10 - (4 - std::sqrt(16 - 1.0)), 1e-9);
  // 3 mm to the side it rests on the face.
  EXPECT_NEAR(drop.tip_height({3, 3}), 10 - 3 * t + 4 / std::cos(30 * std::numbers::pi / 180) - 4, 1e-9);
}

TEST(DropCutter, ASpikeIsMetAtItsVertex) {
  const Vec3 apex{0, 0, 5};
  const DropCutter drop(mesh({{Vec3{-1, -1, 0}, Vec3{1, -1, 0}, apex}, {Vec3{1, -1, 0}, Vec3{0, 1, 0}, apex},
                              {Vec3{0, 1, 0}, Vec3{-1, -1, 0}, apex}}),
                        kBall);
  EXPECT_NEAR(drop.tip_height({2.5, 0}), 5 - (4 - std::sqrt(16 - 6.25)), 1e-9);
  // Beyond the radius nothing of the spike is under the cutter but its base corners.
  EXPECT_LT(drop.tip_height({6, 0}), 0.01);
  EXPECT_TRUE(std::isinf(drop.tip_height({20, 20})));
}

// The brute force: every triangle sampled at 200 x 200 barycentric points, each sample
// under the cutter lifting it to sample.z - f(d). A lower bound that converges.
double brute_tip(const std::vector<Triangle>& tris, const CutterShape& s, Point2 p) {
  double best = -std::numeric_limits<double>::infinity();
  constexpr int n = 200;
  for (const Triangle& t : tris)
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const double u = double(i) / n, v = double(j) / n, w = 1 - u - v;
        const Vec3 q{u * t[0].x + v * t[1].x + w * t[2].x, u * t[0].y + v * t[1].y + w * t[2].y,
                     u * t[0].z + v * t[1].z + w * t[2].z};
        const double d = std::hypot(q.x - p.x, q.y - p.y);
        if (d <= s.radius) best = std::max(best, q.z - s.height_at(d));
      }
  return best;
}

TEST(DropCutter, AgreesWithSamplingOnRandomTriangles) {
  std::mt19937 rng(20261206);
  std::uniform_real_distribution<double> xy(-6, 6), z(-3, 3);
  for (int round = 0; round < 60; ++round) {
    std::vector<Triangle> tris;
    for (int k = 0; k < 3; ++k) tris.push_back({Vec3{xy(rng), xy(rng), z(rng)}, Vec3{xy(rng), xy(rng), z(rng)}, Vec3{xy(rng), xy(rng), z(rng)}});
    const CutterShape s = round % 3 == 0 ? kBall : round % 3 == 1 ? kBull : kFlat;
    const DropCutter drop(mesh(tris), s);
    const Point2 p{xy(rng) / 2, xy(rng) / 2};
    const double exact = drop.tip_height(p), sampled = brute_tip(tris, s, p);
    if (std::isinf(sampled)) {
      EXPECT_TRUE(std::isinf(exact));
      continue;
    }
    // Never below what any sample of the triangles demands; above it by no more than
    // the sampling's reach (a sample spacing of 0.06 mm or so on these triangles).
    EXPECT_GE(exact, sampled - 1e-9) << "round " << round;
    EXPECT_LE(exact, sampled + 0.05) << "round " << round;
  }
}

TEST(ScallopStepOver, FromTheCornerRadius) {
  EXPECT_NEAR(scallop_step_over(kBall, 0.01), 2 * std::sqrt(2 * 4 * 0.01 - 0.0001), 1e-12);
  EXPECT_NEAR(scallop_step_over(kBull, 0.01), 2 * std::sqrt(2 * 1 * 0.01 - 0.0001), 1e-12);
  EXPECT_DOUBLE_EQ(scallop_step_over(kFlat, 0.01), 6);
  EXPECT_THROW(scallop_step_over(kBall, 0), std::invalid_argument);
}

}  // namespace
}  // namespace hybridctl::toolpaths
