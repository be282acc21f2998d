#include "quadric_slam/odometry/feature_motion_guess.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "quadric_slam/odometry/point_to_plane_icp.h"
#include "quadric_slam/types/param_checks.h"

namespace quadric_slam {
namespace {

// RANSAC stops once a better minimal set is this unlikely to be missed.
constexpr double kRansacConfidence = 0.99;
// The three points of a minimal set must lie at least this far apart (m) and off one line (the
// triangle's smallest height, m): a sliver fixes no rotation about its long side.
constexpr double kMinSampleSide = 0.05;
constexpr double kMinSampleHeight = 0.02;
// ORB's scale step between pyramid levels.
constexpr double kPyramidScale = 1.2;
// Refinements on the reprojections (each over the pairs agreeing with the last pose).
constexpr int kRefinementRounds = 2;
// The same seed on every call: the same frames give the same guess.
constexpr unsigned kRansacSeed = 0x51ca;

Eigen::Isometry3d rigidFit(const Eigen::Matrix3Xd& current, const Eigen::Matrix3Xd& reference) {
  Eigen::Isometry3d T;
  T.matrix() = Eigen::umeyama(current, reference, false);
  return T;
}

bool wellShaped(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double ab = (b - a).norm(), bc = (c - b).norm(), ca = (a - c).norm();
  const double longest = std::max({ab, bc, ca});
  if (std::min({ab, bc, ca}) < kMinSampleSide)
    return false;
  const double twice_area = (b - a).cross(c - a).norm();
  return twice_area / longest >= kMinSampleHeight;
}

Eigen::Matrix3Xd columns(const Eigen::Matrix3Xd& m, const std::vector<int>& indices) {
  Eigen::Matrix3Xd out(3, indices.size());
  for (size_t i = 0; i < indices.size(); ++i)
    out.col(i) = m.col(indices[i]);
  return out;
}

// The standard deviation of the points along their second principal axis (m).
double secondSpread(const Eigen::Matrix3Xd& points) {
  const Eigen::Vector3d mean = points.rowwise().mean();
  const Eigen::Matrix3Xd centred = points.colwise() - mean;
  const Eigen::Matrix3d covariance = centred * centred.transpose() / points.cols();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  return std::sqrt(std::max(0.0, eigen.eigenvalues()(1)));  // ascending: (1) is the middle one
}

}  // namespace

void FeatureMotionGuesser::Params::validate() const {
  const ParamRangeCheck check("FeatureMotionGuesser::Params");
  check(max_features >= 50 && max_features <= 20000, "max_features", "[50, 20000]", max_features);
  check(fast_threshold >= 1 && fast_threshold <= 100, "fast_threshold", "[1, 100]", fast_threshold);
  check(pyramid_levels >= 1 && pyramid_levels <= 16, "pyramid_levels", "[1, 16]", pyramid_levels);
  check(match_ratio > 0 && match_ratio <= 1, "match_ratio", "(0, 1]", match_ratio);
  check(min_depth > 0 && std::isfinite(min_depth), "min_depth", "(0, inf) m", min_depth);
  check(max_depth > min_depth && std::isfinite(max_depth), "max_depth", "(min_depth, inf) m",
        max_depth);
  check(inlier_pixels > 0 && std::isfinite(inlier_pixels), "inlier_pixels", "(0, inf) px",
        inlier_pixels);
  check(inlier_distance > 0 && std::isfinite(inlier_distance), "inlier_distance", "(0, inf) m",
        inlier_distance);
  check(inlier_distance_per_z2 >= 0 && std::isfinite(inlier_distance_per_z2),
        "inlier_distance_per_z2", "[0, inf) 1/m", inlier_distance_per_z2);
  check(ransac_iterations >= 1 && ransac_iterations <= 100000, "ransac_iterations", "[1, 100000]",
        ransac_iterations);
  check(min_inliers >= 3 && min_inliers <= 100000, "min_inliers", "[3, 100000]", min_inliers);
  check(min_inlier_fraction >= 0 && min_inlier_fraction <= 1, "min_inlier_fraction", "[0, 1]",
        min_inlier_fraction);
  check(min_spread >= 0 && std::isfinite(min_spread), "min_spread", "[0, inf) m", min_spread);
}

FeatureMotionGuesser::FeatureMotionGuesser() : FeatureMotionGuesser(Params()) {}

FeatureMotionGuesser::FeatureMotionGuesser(const Params& params)
    : params_((params.validate(), params)),
      orb_(cv::ORB::create(params.max_features, static_cast<float>(kPyramidScale),
                           params.pyramid_levels, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31,
                           params.fast_threshold)) {}

FeatureFrame FeatureMotionGuesser::describe(const cv::Mat& image, const cv::Mat& depth,
                                            const CameraIntrinsics& intrinsics) {
  if (image.cols != intrinsics.width || image.rows != intrinsics.height ||
      (image.type() != CV_8UC1 && image.type() != CV_8UC3))
    throw std::invalid_argument(
        "FeatureMotionGuesser::describe: the image must be 8-bit grey or colour at the "
        "intrinsics' size");
  std::string problem;
  const int decimation = depth.type() == CV_32FC1 ? organizedCloudDecimation(intrinsics, depth.cols,
                                                                             depth.rows, &problem)
                                                  : 0;
  if (decimation == 0)
    throw std::invalid_argument(
        "FeatureMotionGuesser::describe: the depth (CV_32FC1) must be the "
        "image's size divided by an integer" +
        (problem.empty() ? std::string() : ": " + problem));
  cv::Mat grey = image;
  if (image.type() == CV_8UC3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);  // the weights barely matter for corners

  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  orb_->detectAndCompute(grey, cv::noArray(), keypoints, descriptors);

  FeatureFrame frame;
  std::vector<int> rows;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const cv::Point2f& pixel = keypoints[i].pt;
    const int u = std::clamp(static_cast<int>(pixel.x) / decimation, 0, depth.cols - 1);
    const int v = std::clamp(static_cast<int>(pixel.y) / decimation, 0, depth.rows - 1);
    const float z = depth.at<float>(v, u);
    if (!(z >= params_.min_depth && z <= params_.max_depth))
      continue;
    // The corner's own (sub-pixel) ray at its grid cell's depth.
    frame.points.emplace_back((pixel.x - intrinsics.cx) * z / intrinsics.fx,
                              (pixel.y - intrinsics.cy) * z / intrinsics.fy, z);
    frame.pixels.emplace_back(pixel.x, pixel.y);
    frame.pixel_scales.push_back(std::pow(kPyramidScale, keypoints[i].octave));
    rows.push_back(static_cast<int>(i));
  }
  frame.intrinsics = intrinsics;
  frame.descriptors.create(static_cast<int>(rows.size()), descriptors.cols, descriptors.type());
  for (size_t i = 0; i < rows.size(); ++i)
    descriptors.row(rows[i]).copyTo(frame.descriptors.row(static_cast<int>(i)));
  return frame;
}

FeatureMotionGuess FeatureMotionGuesser::guess(const FeatureFrame& reference,
                                               const FeatureFrame& current) const {
  FeatureMotionGuess out;
  if (reference.points.size() < 3 || current.points.size() < 3) {
    out.message = "too few corners with depth";
    return out;
  }
  std::vector<std::vector<cv::DMatch>> nearest;
  matcher_.knnMatch(current.descriptors, reference.descriptors, nearest, 2);
  std::vector<std::pair<int, int>> kept;  // (current, reference)
  for (const std::vector<cv::DMatch>& m : nearest) {
    if (m.size() == 2 && m[0].distance < params_.match_ratio * m[1].distance)
      kept.emplace_back(m[0].queryIdx, m[0].trainIdx);
  }
  out.matches = static_cast<int>(kept.size());
  if (out.matches < params_.min_inliers) {
    out.message = "too few corners matched (" + std::to_string(out.matches) + ")";
    return out;
  }
  const auto gather = [&](const FeatureFrame& frame, bool is_current, MatchedCorners& side) {
    side.points.resize(3, out.matches);
    side.pixels.resize(2, out.matches);
    side.pixel_scales.resize(out.matches);
    side.intrinsics = frame.intrinsics;
    for (int i = 0; i < out.matches; ++i) {
      const int index = is_current ? kept[i].first : kept[i].second;
      side.points.col(i) = frame.points[index];
      side.pixels.col(i) = frame.pixels[index];
      side.pixel_scales(i) = frame.pixel_scales[index];
    }
  };
  gather(reference, false, out.reference);
  gather(current, true, out.current);
  const Eigen::Matrix3Xd& reference_points = out.reference.points;
  const Eigen::Matrix3Xd& current_points = out.current.points;
  const CornerPairGates gates = this->gates();
  const auto agreeing = [&](const Eigen::Isometry3d& T) {
    return cornerPairsAgreeing(out.reference, out.current, T, gates);
  };

  std::mt19937 rng(kRansacSeed);
  std::uniform_int_distribution<int> pick(0, out.matches - 1);
  std::vector<int> best;
  int needed = params_.ransac_iterations;
  for (int iteration = 0; iteration < needed; ++iteration) {
    const int a = pick(rng), b = pick(rng), c = pick(rng);
    if (!wellShaped(reference_points.col(a), reference_points.col(b), reference_points.col(c)))
      continue;
    const std::vector<int> sample = {a, b, c};
    const Eigen::Isometry3d T =
        rigidFit(columns(current_points, sample), columns(reference_points, sample));
    std::vector<int> inliers = agreeing(T);
    if (inliers.size() <= best.size())
      continue;
    best = std::move(inliers);
    const double share = static_cast<double>(best.size()) / out.matches;
    const double miss = 1.0 - share * share * share;  // a minimal set with an outlier
    if (miss <= 0)
      break;
    needed =
        std::min(params_.ransac_iterations,
                 static_cast<int>(std::ceil(std::log(1 - kRansacConfidence) / std::log(miss))));
  }
  if (static_cast<int>(best.size()) < std::max(3, params_.min_inliers)) {
    out.message = "no motion agreed by " + std::to_string(params_.min_inliers) + " matches (best " +
                  std::to_string(best.size()) + " of " + std::to_string(out.matches) + ")";
    return out;
  }
  // Least squares in 3D over the consensus, then on the reprojections and depths over the pairs
  // that agree, twice (the second time over the pairs agreeing with the first refinement); a
  // refinement is kept when at least as many pairs agree with it.
  Eigen::Isometry3d T = rigidFit(columns(current_points, best), columns(reference_points, best));
  best = agreeing(T);
  for (int round = 0; round < kRefinementRounds && best.size() >= 3; ++round) {
    const Eigen::Isometry3d refined =
        refineCornerPairPose(out.reference, out.current, best, T, gates);
    std::vector<int> refined_agreeing = agreeing(refined);
    if (refined_agreeing.size() < best.size())
      break;
    T = refined;
    best = std::move(refined_agreeing);
  }
  out.inliers = static_cast<int>(best.size());
  out.T_reference_current = T;
  if (out.inliers < params_.min_inliers ||
      out.inliers < params_.min_inlier_fraction * out.matches) {
    out.message = "too few matches agree (" + std::to_string(out.inliers) + " of " +
                  std::to_string(out.matches) + ")";
    return out;
  }
  if (secondSpread(columns(reference_points, best)) < params_.min_spread) {
    out.message = "the agreeing corners lie along one line";
    return out;
  }
  out.information = cornerPairInformation(out.reference, out.current, best, T, gates);
  out.found = true;
  return out;
}

int FeatureMotionGuesser::screenMatches(const FeatureFrame& reference, const FeatureFrame& current,
                                        int stride) const {
  if (reference.descriptors.rows < 2 || current.descriptors.empty() || stride < 1)
    return 0;
  cv::Mat sampled;
  for (int row = 0; row < current.descriptors.rows; row += stride)
    sampled.push_back(current.descriptors.row(row));
  std::vector<std::vector<cv::DMatch>> nearest;
  matcher_.knnMatch(sampled, reference.descriptors, nearest, 2);
  return static_cast<int>(std::count_if(nearest.begin(), nearest.end(), [&](const auto& m) {
    return m.size() == 2 && m[0].distance < params_.match_ratio * m[1].distance;
  }));
}

int FeatureMotionGuesser::agreeingMatches(const FeatureMotionGuess& guess,
                                          const Eigen::Isometry3d& T_reference_current) const {
  return static_cast<int>(
      cornerPairsAgreeing(guess.reference, guess.current, T_reference_current, gates()).size());
}

CornerPairGates FeatureMotionGuesser::gates() const {
  CornerPairGates gates;
  gates.pixels = params_.inlier_pixels;
  gates.depth = params_.inlier_distance;
  gates.depth_per_z2 = params_.inlier_distance_per_z2;
  return gates;
}

}  // namespace quadric_slam
