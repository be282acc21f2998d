#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

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
  const KinectDepthModel model;
  for (double z : {1.0, 2.0, 3.0})
    EXPECT_NEAR(model.sigma(z), 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4), 1e-15);
  // Kinect: 1/8 px disparity, baseline 0.075 m, focal 580 px.
  EXPECT_NEAR(model.depthStep(2.0), 4.0 / (8 * 580 * 0.075), 1e-15);
}

TEST(KinectDepthModel, UnquantisedNoiseStatisticsMatchSigmaAt1To3Metres) {
  KinectDepthModel::Params p = noDropout();
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
    double sum = 0, sum2 = 0;
    int n = 0;
    for (int v = 0; v < frame.depth.rows; ++v)
      for (int u = 0; u < frame.depth.cols; ++u) {
        const float d = frame.depth.at<float>(v, u);
        if (std::isnan(d))
          continue;
        sum += d - z;
        sum2 += (d - z) * (d - z);
        ++n;
      }
    const double mean = sum / n, std = std::sqrt(sum2 / n - mean * mean);
    std::printf("plane at %.1f m: residual std %.4f m (model %.4f m, real fr3 frame %.3f m)\n", z,
                std, renderer.depthModel().expectedStd(z), real_std);
    EXPECT_GT(n, 0.95 * 160 * 120);
    EXPECT_NEAR(mean, 0.0, 0.001) << "z = " << z;
    EXPECT_NEAR(std / renderer.depthModel().expectedStd(z), 1.0, 0.1) << "z = " << z;
    EXPECT_GT(std, 0.6 * real_std) << "z = " << z;
    EXPECT_LT(std, 1.4 * real_std) << "z = " << z;
  }
}
