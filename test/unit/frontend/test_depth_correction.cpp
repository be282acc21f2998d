// The depth camera's fixed disparity distortion (frontend/depth_correction.h) and its estimation
// from flat surfaces without ground truth (frontend/depth_correction_estimator.h): the correction
// undoes a known distortion exactly; the estimator, given planes seen through a known distortion
// with disparity noise, recovers the distortion's non-affine part (the affine part is what every
// plane absorbs, and comes out zero).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "quadric_slam/frontend/depth_correction.h"
#include "quadric_slam/frontend/depth_correction_estimator.h"

namespace quadric_slam {
namespace {

constexpr int kWidth = 640, kHeight = 480;
constexpr double kFx = 525.0, kCx = 319.5, kCy = 239.5;
constexpr double kFocalBaseline = kFx * 0.075;

// A smooth distortion of the kind a structured-light sensor has (disparity px): a radial bowl and
// a low-frequency wave over the image.
double trueDistortion(double u, double v) {
  const double x = (u - kCx) / kCx, y = (v - kCy) / kCy;
  const double r2 = 0.5 * (x * x + y * y);  // 1 at the corners
  return 0.05 * r2 + 0.03 * std::sin(2 * M_PI * u / 300.0) * std::cos(2 * M_PI * v / 260.0);
}

// The distortion less its least-squares affine part over the image's pixels (sampled).
std::vector<double> nonAffine(const std::vector<Eigen::Vector2d>& pixels,
                              const std::vector<double>& values) {
  Eigen::MatrixXd a(pixels.size(), 3);
  Eigen::VectorXd b(pixels.size());
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    a.row(i) << 1.0, pixels[i].x(), pixels[i].y();
    b[i] = values[i];
  }
  const Eigen::Vector3d coefficients = a.colPivHouseholderQr().solve(b);
  const Eigen::VectorXd rest = b - a * coefficients;
  return std::vector<double>(rest.data(), rest.data() + rest.size());
}

// The measured depth of a plane n.p = offset (camera frame) at pixel (u, v) through the
// distortion: true disparity f b / z less D.
double measuredDepth(const Eigen::Vector3d& n, double offset, double u, double v) {
  const Eigen::Vector3d ray((u - kCx) / kFx, (v - kCy) / kFx, 1.0);
  const double z = offset / n.dot(ray);
  return kFocalBaseline / (kFocalBaseline / z - trueDistortion(u, v));
}

TEST(DepthCorrection, UndoesTheDistortionItHolds) {
  // A correction whose nodes carry the true distortion at a fine grid: at the nodes exact.
  const int cols = 33, rows = 25;
  std::vector<double> offsets;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      offsets.push_back(
          trueDistortion(c * (kWidth - 1.0) / (cols - 1), r * (kHeight - 1.0) / (rows - 1)));
  const DepthCorrection correction(kWidth, kHeight, cols, rows, offsets, kFocalBaseline);
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.1, -1.0).normalized();
  for (int r = 0; r < rows; r += 3) {
    for (int c = 0; c < cols; c += 4) {
      const double u = c * (kWidth - 1.0) / (cols - 1), v = r * (kHeight - 1.0) / (rows - 1);
      const Eigen::Vector3d ray((u - kCx) / kFx, (v - kCy) / kFx, 1.0);
      const double z_true = -2.5 / n.dot(ray);
      EXPECT_NEAR(correction.correctedDepth(u, v, measuredDepth(n, -2.5, u, v)), z_true, 1e-9);
    }
  }
  // apply() moves points along their rays to the corrected depth (decimation 2: pixel 2 col).
  pcl::PointCloud<pcl::PointXYZ> cloud(kWidth / 2, kHeight / 2);
  for (int row = 0; row < static_cast<int>(cloud.height); ++row)
    for (int col = 0; col < static_cast<int>(cloud.width); ++col) {
      const double u = 2 * col, v = 2 * row, z = measuredDepth(n, -2.5, u, v);
      cloud(col, row) =
          pcl::PointXYZ(static_cast<float>((u - kCx) / kFx * z),
                        static_cast<float>((v - kCy) / kFx * z), static_cast<float>(z));
    }
  cloud(5, 5).z = std::numeric_limits<float>::quiet_NaN();
  correction.apply(&cloud, 2);
  double worst = 0.0;
  for (int row = 0; row < static_cast<int>(cloud.height); row += 7)
    for (int col = 0; col < static_cast<int>(cloud.width); col += 7) {
      if (!std::isfinite(cloud(col, row).z))
        continue;
      const Eigen::Vector3d p = cloud(col, row).getVector3fMap().cast<double>();
      worst = std::max(worst, std::abs(n.dot(p) + 2.5));  // off the true plane
    }
  // Between nodes bilinear interpolation leaves the wave's curvature: well under a millimetre.
  EXPECT_LT(worst, 5e-4);
  EXPECT_TRUE(std::isnan(cloud(5, 5).z));
  EXPECT_THROW(correction.apply(&cloud, 1), std::invalid_argument);  // not the image's size
  // Empty: nothing changes.
  pcl::PointCloud<pcl::PointXYZ> copy = cloud;
  DepthCorrection().apply(&copy, 1);
  EXPECT_EQ(copy(10, 10).z, cloud(10, 10).z);
}

// A negative offset larger than a far point's disparity: no depth, not a negative one.
TEST(DepthCorrection, BeyondInfinityIsNoData) {
  const DepthCorrection correction(kWidth, kHeight, 2, 2, std::vector<double>(4, -5.0),
                                   kFocalBaseline);
  EXPECT_TRUE(std::isnan(correction.correctedDepth(100, 100, 9.0)));  // disparity 4.4 px
  EXPECT_NEAR(correction.correctedDepth(100, 100, 2.0),
              kFocalBaseline / (kFocalBaseline / 2.0 - 5.0), 1e-12);
  pcl::PointCloud<pcl::PointXYZ> cloud(kWidth, kHeight);
  cloud(3, 4) = pcl::PointXYZ(1.0f, 1.0f, 9.0f);
  cloud(5, 4) = pcl::PointXYZ(0.1f, 0.1f, 2.0f);
  correction.apply(&cloud, 1);
  EXPECT_TRUE(std::isnan(cloud(3, 4).z));
  EXPECT_NEAR(cloud(5, 4).z, kFocalBaseline / (kFocalBaseline / 2.0 - 5.0), 1e-4);
}

TEST(DepthCorrection, RejectsBadGrids) {
  EXPECT_THROW(DepthCorrection(kWidth, kHeight, 1, 5, std::vector<double>(5, 0.0), kFocalBaseline),
               std::invalid_argument);
  EXPECT_THROW(DepthCorrection(kWidth, kHeight, 3, 3, std::vector<double>(8, 0.0), kFocalBaseline),
               std::invalid_argument);
  EXPECT_THROW(DepthCorrection(kWidth, kHeight, 3, 3, std::vector<double>(9, 0.0), 0.0),
               std::invalid_argument);
  EXPECT_THROW(DepthCorrection(kWidth, kHeight, 3, 3, std::vector<double>(9, NAN), kFocalBaseline),
               std::invalid_argument);
}

// Planes at 1-4 m in many orientations, each covering part of the image, seen through the
// distortion with 0.05 px of disparity noise: the estimate is the distortion's non-affine part.
TEST(DepthCorrectionEstimator, RecoversTheNonAffineDistortionFromPlanes) {
  DepthCorrectionEstimator::Params params;
  params.pixel_stride = 3;
  params.smoothness = 10.0;  // ~1300 pixels a node here (the real sequences: tens of thousands)
  DepthCorrectionEstimator estimator(kWidth, kHeight, kFocalBaseline, params);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (int s = 0; s < 100; ++s) {
    const Eigen::Vector3d n =
        Eigen::Vector3d(0.5 * uniform(rng), 0.5 * uniform(rng), -1.0).normalized();
    const double offset = -(2.5 + 1.5 * uniform(rng));
    // A rectangle of the image, half its width and height, somewhere in it.
    const int u0 = static_cast<int>((0.5 + 0.5 * uniform(rng)) * kWidth / 2);
    const int v0 = static_cast<int>((0.5 + 0.5 * uniform(rng)) * kHeight / 2);
    std::vector<Eigen::Vector2d> pixels;
    std::vector<double> depths;
    for (int v = v0; v < v0 + kHeight / 2; ++v)
      for (int u = u0; u < u0 + kWidth / 2; ++u) {
        const double d = kFocalBaseline / measuredDepth(n, offset, u, v) + noise(rng);
        pixels.emplace_back(u, v);
        depths.push_back(kFocalBaseline / d);
      }
    // A few pixels of another surface (an edge): left out as outliers.
    for (int i = 0; i < 50; ++i) {
      pixels.emplace_back(u0 + i, v0);
      depths.push_back(0.5);
    }
    EXPECT_GT(estimator.addPlane(pixels, depths), 8000);
  }
  const DepthCorrection estimate = estimator.solve();
  std::vector<Eigen::Vector2d> samples;
  std::vector<double> truth, estimated;
  for (int v = 0; v < kHeight; v += 8)
    for (int u = 0; u < kWidth; u += 8) {
      samples.emplace_back(u, v);
      truth.push_back(trueDistortion(u, v));
      estimated.push_back(estimate.offsetAt(u, v));
    }
  // Compared over the same pixels, each less its affine part (what no plane can tell).
  const std::vector<double> truth_rest = nonAffine(samples, truth);
  const std::vector<double> estimated_rest = nonAffine(samples, estimated);
  double sum_sq = 0.0, truth_sq = 0.0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    sum_sq += std::pow(estimated_rest[i] - truth_rest[i], 2);
    truth_sq += truth_rest[i] * truth_rest[i];
  }
  const double error = std::sqrt(sum_sq / samples.size());
  const double size = std::sqrt(truth_sq / samples.size());
  EXPECT_GT(size, 0.015);
  EXPECT_LT(error, 0.2 * size) << "distortion RMS " << size << " px, estimate off by " << error;
  // The nodes carry no affine part (1, u, v over the grid).
  Eigen::MatrixXd affine(estimate.cols() * estimate.rows(), 3);
  for (int r = 0; r < estimate.rows(); ++r)
    for (int c = 0; c < estimate.cols(); ++c)
      affine.row(r * estimate.cols() + c) << 1.0, c, r;
  const Eigen::Map<const Eigen::VectorXd> nodes(estimate.offsets().data(), affine.rows());
  EXPECT_LT((affine.transpose() * nodes).norm(), 1e-6);
  // The segments fit their planes better with it: down towards the noise.
  const DepthCorrectionEstimator::Fit fit = estimator.fit(estimate);
  EXPECT_LT(fit.rms_after, fit.rms_before);
  EXPECT_LT(fit.rms_after, 0.055);
}

TEST(DepthCorrectionEstimator, SmallSegmentsAndNoDataAreRefused) {
  DepthCorrectionEstimator estimator(kWidth, kHeight, kFocalBaseline, {});
  EXPECT_THROW(estimator.solve(), std::runtime_error);
  std::vector<Eigen::Vector2d> pixels{{10, 10}, {12, 10}};
  EXPECT_EQ(estimator.addPlane(pixels, {1.0, 1.0}), 0);
  EXPECT_THROW(estimator.addPlane(pixels, {1.0}), std::invalid_argument);
  DepthCorrectionEstimator::Params bad;
  bad.cols = 2;
  EXPECT_THROW(DepthCorrectionEstimator(kWidth, kHeight, kFocalBaseline, bad),
               std::invalid_argument);
}

}  // namespace
}  // namespace quadric_slam
