#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "quadric_slam/sim/kinect_depth_model.h"
#include "quadric_slam/sim/renderer.h"
#include "quadric_slam/sim/surfaces.h"

using quadric_slam::KinectDepthModel;
using quadric_slam::SimRandom;

namespace {

struct Moments {
  double mean = 0, std = 0;
  int valid = 0;
};

Moments sample(const KinectDepthModel& model, double z, int n, std::uint64_t seed) {
  SimRandom random(seed);
  double sum = 0, sum2 = 0;
  Moments m;
  for (int i = 0; i < n; ++i) {
    const float d = model.measure(z, 1.0, random);
    if (std::isnan(d))
      continue;
    sum += d;
    sum2 += static_cast<double>(d) * d;
    ++m.valid;
  }
  m.mean = sum / m.valid;
  m.std = std::sqrt(sum2 / m.valid - m.mean * m.mean);
  return m;
}

KinectDepthModel::Params noDropout() {
  KinectDepthModel::Params p;
  p.dropout_probability = 0.0;
  return p;
}

}  // namespace

TEST(KinectDepthModel, SigmaFollowsNguyenFormula) {
  const KinectDepthModel model(KinectDepthModel::nguyenParams());
  for (double z : {1.0, 2.0, 3.0})
    EXPECT_NEAR(model.sigma(z), 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4), 1e-15);
  // Kinect: 1/8 px disparity, baseline 0.075 m, focal 580 px.
  EXPECT_NEAR(model.depthStep(2.0), 4.0 / (8 * 580 * 0.075), 1e-15);
}

TEST(KinectDepthModel, UnquantisedNoiseStatisticsMatchSigmaAt1To3Metres) {
  KinectDepthModel::Params p = KinectDepthModel::nguyenParams();
  p.dropout_probability = 0.0;
  p.disparity_resolution = 0.0;
  const KinectDepthModel model(p);
  const int n = 40000;
  for (double z : {1.0, 2.0, 3.0}) {
    const Moments m = sample(model, z, n, 7 + static_cast<int>(z));
    const double sigma = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);
    EXPECT_EQ(m.valid, n);
    EXPECT_NEAR(m.mean, z, 4.0 * sigma / std::sqrt(n)) << "z = " << z;
    EXPECT_NEAR(m.std / sigma, 1.0, 0.03) << "z = " << z;
  }
}

TEST(KinectDepthModel, QuantisedStatisticsMatchExpectedStdAndLieOnDisparityGrid) {
  const KinectDepthModel model(noDropout());
  for (double z : {1.0, 2.0, 3.0}) {
    const Moments m = sample(model, z, 40000, 11 + static_cast<int>(z));
    EXPECT_NEAR(m.mean, z, 0.1 * model.depthStep(z)) << "z = " << z;
    EXPECT_NEAR(m.std / model.expectedStd(z), 1.0, 0.08) << "z = " << z;
  }
  SimRandom random(3);
  for (int i = 0; i < 100; ++i) {
    const double d = model.measure(2.3, 1.0, random);
    const double disparity_steps = 580 * 0.075 / d / 0.125;
    EXPECT_NEAR(disparity_steps, std::round(disparity_steps), 1e-3);
  }
}

TEST(KinectDepthModel, NoDataOutsideRangeAndAtGrazingIncidence) {
  const KinectDepthModel model(noDropout());
  SimRandom random(5);
  EXPECT_TRUE(std::isnan(model.measure(0.45, 1.0, random)));
  EXPECT_TRUE(std::isnan(model.measure(4.6, 1.0, random)));
  EXPECT_FALSE(std::isnan(model.measure(0.6, 1.0, random)));
  EXPECT_FALSE(std::isnan(model.measure(4.4, 1.0, random)));
  const double deg = M_PI / 180.0;
  EXPECT_TRUE(std::isnan(model.measure(2.0, std::cos(80 * deg), random)));
  EXPECT_TRUE(std::isnan(model.measure(2.0, std::cos(76 * deg), random)));
  EXPECT_FALSE(std::isnan(model.measure(2.0, std::cos(70 * deg), random)));
  EXPECT_TRUE(std::isnan(model.measure(std::nan(""), 1.0, random)));
}

TEST(KinectDepthModel, RandomDropoutRateMatchesProbability) {
  KinectDepthModel::Params p;
  p.dropout_probability = 0.05;
  const KinectDepthModel model(p);
  SimRandom random(9);
  int missing = 0;
  const int n = 40000;
  for (int i = 0; i < n; ++i)
    missing += std::isnan(model.measure(1.5, 1.0, random)) ? 1 : 0;
  EXPECT_NEAR(missing / static_cast<double>(n), 0.05, 0.005);
}

TEST(KinectDepthModel, DropsTheFarSideOfDepthDiscontinuities) {
  KinectDepthModel::Params p = noDropout();
  p.edge_dropout_px = 2;
  const KinectDepthModel model(p);
  // Left half at 1 m, right half at 2 m: the 2 px of the far side next to the edge have no data.
  cv::Mat depth(20, 40, CV_32FC1, cv::Scalar(2.0f)), cosine(20, 40, CV_32FC1, cv::Scalar(1.0f));
  depth.colRange(0, 20).setTo(1.0f);
  const cv::Mat out = model.apply(depth, cosine, 1);
  for (int v = 0; v < 20; ++v) {
    for (int u = 0; u < 40; ++u) {
      const bool expect_missing = u == 20 || u == 21;
      EXPECT_EQ(std::isnan(out.at<float>(v, u)), expect_missing) << "u " << u << " v " << v;
    }
  }
  // Same seed, same image: same result (per-row streams).
  const cv::Mat again = model.apply(depth, cosine, 1);
  EXPECT_EQ(cv::countNonZero(out != again), 0);
}

TEST(KinectDepthModel, ValidateNamesTheBadField) {
  KinectDepthModel::Params p;
  p.max_range = 0.3;
  try {
    p.validate();
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_range"), std::string::npos) << e.what();
  }
  p = KinectDepthModel::Params();
  p.max_incidence = 2.0;
  EXPECT_THROW(KinectDepthModel{p}, std::invalid_argument);
  p = KinectDepthModel::Params();
  p.dropout_probability = 1.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

// The real fr3_long_office frame (test/data/README.md) has robust plane-fit residual std of
// 0.9 cm on the floor at about 2.1 m and 1.4 cm on the back wall at about 2.5 m. A rendered
// fronto-parallel plane with the default model must give residuals of that size.
TEST(KinectDepthModel, PlaneResidualsAreTheSizeOfTheRealFr3Frame) {
  for (const auto& [z, real_std] : {std::pair<double, double>{2.1, 0.009}, {2.5, 0.014}}) {
    quadric_slam::Scene scene;
    quadric_slam::PrimitiveSpec wall;
    wall.name = "wall";
    wall.type = quadric_slam::PrimitiveType::kRectangle;
    wall.size = Eigen::Vector3d(0, 10, 10);
    wall.T_world_primitive.linear() =
        Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();  // normal = z
    wall.T_world_primitive.translation() = Eigen::Vector3d(0, 0, z);
    scene.primitives.push_back(wall);
    scene.camera = {525, 525, 79.5, 59.5, 160, 120};
    const quadric_slam::Renderer renderer(quadric_slam::buildSurfaces(scene), scene.camera,
                                          KinectDepthModel::Params(), {});
    const quadric_slam::RenderedFrame frame = renderer.render(Eigen::Isometry3d::Identity(), 4);
    // The harsh model's systematic part (radial bend and fixed pattern) is known per pixel:
    // what remains must be the noise of expectedStd; the whole error must be the real size.
    const KinectDepthModel& model = renderer.depthModel();
    const cv::Mat pattern = model.disparityPattern(frame.depth.size());
    const double cu = 0.5 * (frame.depth.cols - 1), cv0 = 0.5 * (frame.depth.rows - 1);
    double sum = 0, sum2 = 0, raw_sum = 0, raw_sum2 = 0;
    int n = 0;
    for (int v = 0; v < frame.depth.rows; ++v)
      for (int u = 0; u < frame.depth.cols; ++u) {
        const float d = frame.depth.at<float>(v, u);
        if (std::isnan(d))
          continue;
        const double r = std::hypot(u - cu, v - cv0) / std::hypot(cu, cv0);
        const double systematic =
            model.distortion(z, r) + z * z / (580 * 0.075) * pattern.at<float>(v, u);
        const double e = d - z - systematic;
        sum += e;
        sum2 += e * e;
        raw_sum += d - z;
        raw_sum2 += (d - z) * (d - z);
        ++n;
      }
    const double mean = sum / n, std = std::sqrt(sum2 / n - mean * mean);
    const double raw_mean = raw_sum / n, raw_std = std::sqrt(raw_sum2 / n - raw_mean * raw_mean);
    std::printf(
        "plane at %.1f m: residual std %.4f m, noise alone %.4f m (model %.4f m, real fr3 "
        "frame %.3f m)\n",
        z, raw_std, std, renderer.depthModel().expectedStd(z), real_std);
    EXPECT_GT(n, 0.95 * 160 * 120);
    EXPECT_NEAR(mean, 0.0, 0.001) << "z = " << z;
    EXPECT_NEAR(std / renderer.depthModel().expectedStd(z), 1.0, 0.1) << "z = " << z;
    EXPECT_GT(raw_std, 0.8 * real_std) << "z = " << z;
    EXPECT_LT(raw_std, 1.4 * real_std) << "z = " << z;
  }
}

// ---------------------------------------------------------------------------------------------
// The harsh model (the default): its statistics on a rendered fronto-parallel plane.
namespace {

constexpr int kWidth = 640, kHeight = 480;

cv::Mat planeAt(double z) {
  return cv::Mat(kHeight, kWidth, CV_32FC1, cv::Scalar(static_cast<float>(z)));
}

cv::Mat facing() {
  return cv::Mat(kHeight, kWidth, CV_32FC1, cv::Scalar(1.0f));
}

// Harsh terms only as asked: no dropout, no shadow; systematic terms off unless set.
KinectDepthModel::Params harshNoiseOnly() {
  KinectDepthModel::Params p = KinectDepthModel::harshParams();
  p.dropout_probability = 0.0;
  p.distortion_r2 = p.distortion_r4 = 0.0;
  p.pattern_amplitude = 0.0;
  return p;
}

double normalisedRadius(int u, int v) {
  const double cu = 0.5 * (kWidth - 1), cv0 = 0.5 * (kHeight - 1);
  return std::hypot(u - cu, v - cv0) / std::hypot(cu, cv0);
}

// Mean of (image - z) over a square of side `size` centred at (u, v).
double meanError(const cv::Mat& depth, double z, int u, int v, int size) {
  double sum = 0;
  int n = 0;
  for (int y = v - size / 2; y < v + size / 2; ++y)
    for (int x = u - size / 2; x < u + size / 2; ++x)
      if (!std::isnan(depth.at<float>(y, x)))
        sum += depth.at<float>(y, x) - z, ++n;
  return sum / n;
}

// Normalised autocorrelation of (image - z) along rows at the given lag.
double rowCorrelation(const cv::Mat& depth, double z, int lag) {
  double c0 = 0, cl = 0;
  long n0 = 0, nl = 0;
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u + lag < depth.cols; ++u) {
      const double a = depth.at<float>(v, u) - z, b = depth.at<float>(v, u + lag) - z;
      c0 += a * a, ++n0;
      cl += a * b, ++nl;
    }
  return (cl / nl) / (c0 / n0);
}

}  // namespace

TEST(KinectDepthModel, HarshIsTheDefaultAndNguyenIsKinder) {
  const KinectDepthModel harsh, nguyen(KinectDepthModel::nguyenParams());
  EXPECT_GT(harsh.params().sigma_scale, 1.0);
  EXPECT_GT(harsh.params().correlated_fraction, 0.0);
  EXPECT_NE(harsh.params().distortion_r2, 0.0);
  for (double z : {1.0, 2.5, 4.0})
    EXPECT_NEAR(harsh.sigma(z), harsh.params().sigma_scale * nguyen.sigma(z), 1e-12);
  EXPECT_EQ(nguyen.distortion(3.0, 1.0), 0.0);
  EXPECT_THROW(KinectDepthModel::paramsForModel("gentle"), std::invalid_argument);
  KinectDepthModel::Params p = KinectDepthModel::nguyenParams();
  p.min_range = 0.7;
  KinectDepthModel::applyModel("harsh", &p);  // model terms only
  EXPECT_EQ(p.min_range, 0.7);
  EXPECT_EQ(p.sigma_scale, KinectDepthModel::harshParams().sigma_scale);
}

TEST(KinectDepthModel, HarshPlaneStdPerRangeMatchesExpectedStd) {
  const KinectDepthModel model(harshNoiseOnly());
  for (double z : {1.0, 2.0, 3.0, 4.0}) {
    const cv::Mat out = model.apply(planeAt(z), facing(), 17 + static_cast<int>(z));
    cv::Scalar mean, stddev;
    cv::meanStdDev(out - z, mean, stddev);
    EXPECT_NEAR(mean[0], 0.0, 0.05 * model.expectedStd(z)) << "z = " << z;
    EXPECT_NEAR(stddev[0] / model.expectedStd(z), 1.0, 0.1) << "z = " << z;
  }
  // And the scale is the one asked for: a second model with half the scale has half the std
  // once quantisation is off.
  KinectDepthModel::Params p = harshNoiseOnly();
  p.disparity_resolution = 0.0;
  KinectDepthModel::Params half = p;
  half.sigma_scale = 0.5 * p.sigma_scale;
  cv::Scalar m1, s1, m2, s2;
  cv::meanStdDev(KinectDepthModel(p).apply(planeAt(3.0), facing(), 3) - 3.0, m1, s1);
  cv::meanStdDev(KinectDepthModel(half).apply(planeAt(3.0), facing(), 3) - 3.0, m2, s2);
  EXPECT_NEAR(s1[0], KinectDepthModel(p).sigma(3.0), 0.05 * s1[0]);
  EXPECT_NEAR(s2[0] / s1[0], 0.5, 0.01);
}

TEST(KinectDepthModel, FlatWallBendsTowardsTheCornersAsTheDistortionSays) {
  KinectDepthModel::Params p = harshNoiseOnly();
  p.distortion_r2 = KinectDepthModel::harshParams().distortion_r2;
  p.distortion_r4 = 0.02;
  const KinectDepthModel model(p);
  const double z = 3.0;
  // The formula: dz = z^2 / (f b) (k2 r^2 + k4 r^4).
  EXPECT_NEAR(model.distortion(z, 1.0), 9.0 / (580 * 0.075) * (p.distortion_r2 + 0.02), 1e-12);
  EXPECT_EQ(model.distortion(z, 0.0), 0.0);
  // On noisy images (16 frames averaged: the correlated noise leaves few independent samples
  // in a cell): 60 x 60 px cells at the centre and at each corner, against the cell mean of the
  // formula. The std of a cell difference is about 1.2 mm here.
  cv::Mat sum(kHeight, kWidth, CV_32FC1, cv::Scalar(0.0f));
  for (int frame = 0; frame < 16; ++frame)
    sum += model.apply(planeAt(z), facing(), 50 + frame);
  const cv::Mat out = sum / 16.0;
  cv::Mat formula(kHeight, kWidth, CV_32FC1);
  for (int v = 0; v < kHeight; ++v)
    for (int u = 0; u < kWidth; ++u)
      formula.at<float>(v, u) = static_cast<float>(z + model.distortion(z, normalisedRadius(u, v)));
  const double centre = meanError(out, z, kWidth / 2, kHeight / 2, 60);
  const double centre_formula = meanError(formula, z, kWidth / 2, kHeight / 2, 60);
  EXPECT_NEAR(centre, centre_formula, 0.002);
  for (const auto& [u, v] : {std::pair<int, int>{30, 30},
                             {kWidth - 30, 30},
                             {30, kHeight - 30},
                             {kWidth - 30, kHeight - 30}}) {
    const double expected = meanError(formula, z, u, v, 60) - centre_formula;
    EXPECT_GT(expected, 0.008);  // about a centimetre at 3 m
    EXPECT_NEAR(meanError(out, z, u, v, 60) - centre, expected, 0.0035) << u << ", " << v;
  }
}

TEST(KinectDepthModel, FixedPatternHasItsAmplitudeAndDoesNotChangeWithTheFrame) {
  KinectDepthModel::Params p = harshNoiseOnly();
  p.pattern_amplitude = 0.05;
  const KinectDepthModel model(p);
  const cv::Mat pattern = model.disparityPattern(cv::Size(kWidth, kHeight));
  cv::Scalar mean, stddev;
  cv::meanStdDev(pattern, mean, stddev);
  const double rms = std::sqrt(mean[0] * mean[0] + stddev[0] * stddev[0]);
  EXPECT_NEAR(rms / 0.05, 1.0, 0.35);
  // Smooth: neighbouring pixels differ by a small part of the amplitude.
  EXPECT_NEAR(pattern.at<float>(100, 100), pattern.at<float>(100, 101), 0.01 * 0.05 * 20);
  // The same for every frame (a device property), different for another pattern_seed.
  const cv::Mat again = model.disparityPattern(cv::Size(kWidth, kHeight));
  EXPECT_EQ(cv::countNonZero(pattern != again), 0);
  KinectDepthModel::Params other = p;
  other.pattern_seed = p.pattern_seed + 1;
  EXPECT_GT(cv::norm(KinectDepthModel(other).disparityPattern(cv::Size(kWidth, kHeight)) - pattern),
            0.1 * cv::norm(pattern));
  // Averaged over frames, the depth error follows the pattern: z^2 / (f b) * D(u, v).
  const double z = 2.0;
  cv::Mat sum(kHeight, kWidth, CV_64FC1, cv::Scalar(0.0));
  for (int frame = 0; frame < 8; ++frame) {
    cv::Mat e;
    cv::Mat(model.apply(planeAt(z), facing(), 100 + frame) - z).convertTo(e, CV_64F);
    sum += e;
  }
  cv::Mat expected;
  pattern.convertTo(expected, CV_64F, z * z / (580 * 0.075));
  cv::Mat blurred_mean, blurred_expected;
  cv::blur(sum / 8.0, blurred_mean, cv::Size(31, 31));
  cv::blur(expected, blurred_expected, cv::Size(31, 31));
  EXPECT_LT(cv::norm(blurred_mean - blurred_expected) / cv::norm(blurred_expected), 0.35);
}

TEST(KinectDepthModel, NoiseCorrelationMatchesTheCorrelationLength) {
  KinectDepthModel::Params p = harshNoiseOnly();
  p.disparity_resolution = 0.0;  // quantisation adds its own white part
  const double f = p.correlated_fraction, s = p.correlation_px;
  const cv::Mat out = KinectDepthModel(p).apply(planeAt(2.5), facing(), 9);
  for (int lag : {1, 2, 4, 8}) {
    const double expected = f * std::exp(-lag * lag / (4.0 * s * s));
    EXPECT_NEAR(rowCorrelation(out, 2.5, lag), expected, 0.04) << "lag " << lag;
  }
  // Independent noise: no correlation.
  KinectDepthModel::Params independent = KinectDepthModel::nguyenParams();
  independent.dropout_probability = 0.0;
  independent.disparity_resolution = 0.0;
  const cv::Mat white = KinectDepthModel(independent).apply(planeAt(2.5), facing(), 9);
  EXPECT_NEAR(rowCorrelation(white, 2.5, 2), 0.0, 0.02);
}

TEST(KinectDepthModel, ProjectorShadowBesideANearerSurface) {
  KinectDepthModel::Params p = harshNoiseOnly();
  p.edge_dropout_px = 0;
  const KinectDepthModel model(p);
  // A near post (1.5 m, columns 300-339) in front of a wall at 3 m: the projector on the right
  // cannot light f b (1/1.5 - 1/3) = 14.5 px of wall left of the post.
  cv::Mat depth = planeAt(3.0);
  depth.colRange(300, 340).setTo(1.5f);
  const cv::Mat out = model.apply(depth, facing(), 2);
  const double width = 580 * 0.075 * (1 / 1.5 - 1 / 3.0);
  for (int v : {10, 240, 470}) {
    int shadow = 0;
    for (int u = 0; u < kWidth; ++u)
      shadow += std::isnan(out.at<float>(v, u)) ? 1 : 0;
    EXPECT_NEAR(shadow, width, 1.0) << "row " << v;
    EXPECT_TRUE(std::isnan(out.at<float>(v, 299)));
    EXPECT_FALSE(std::isnan(out.at<float>(v, 340)));  // right of the post: lit
    EXPECT_FALSE(std::isnan(out.at<float>(v, 320)));  // the post itself
  }
  p.projector_side = 0;
  const cv::Mat lit = KinectDepthModel(p).apply(depth, facing(), 2);
  EXPECT_EQ(cv::countNonZero(lit != lit), 0);  // no NaN (NaN != NaN)
}

TEST(KinectDepthModel, HarshOutputIsDeterministicPerSeed) {
  const KinectDepthModel model;
  const cv::Mat a = model.apply(planeAt(2.0), facing(), 42),
                b = model.apply(planeAt(2.0), facing(), 42);
  const cv::Mat c = model.apply(planeAt(2.0), facing(), 43);
  cv::Mat a0 = a.clone(), b0 = b.clone(), c0 = c.clone();
  cv::patchNaNs(a0, 0), cv::patchNaNs(b0, 0), cv::patchNaNs(c0, 0);
  EXPECT_EQ(cv::countNonZero(a0 != b0), 0);
  EXPECT_GT(cv::countNonZero(a0 != c0), kWidth * kHeight / 4);
}

TEST(KinectDepthModel, ValidateRejectsBadHarshTerms) {
  auto bad = [](auto change) {
    KinectDepthModel::Params p;
    change(p);
    EXPECT_THROW(p.validate(), std::invalid_argument);
  };
  bad([](KinectDepthModel::Params& p) { p.sigma_scale = -1; });
  bad([](KinectDepthModel::Params& p) { p.correlated_fraction = 1.5; });
  bad([](KinectDepthModel::Params& p) { p.correlation_px = 0; });
  bad([](KinectDepthModel::Params& p) { p.distortion_r2 = 5; });
  bad([](KinectDepthModel::Params& p) { p.pattern_amplitude = -0.1; });
  bad([](KinectDepthModel::Params& p) { p.projector_side = 2; });
}
