#include "quadric_slam/odometry/photometric_refinement.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "quadric_slam/odometry/pose_math.h"
#include "quadric_slam/types/param_checks.h"

namespace quadric_slam {

namespace {

// Bilinear interpolation of a CV_32F image at (x, y), pixel centres at integers; false outside the
// area where all four neighbours exist.
bool sample(const cv::Mat& image, double x, double y, double& value) {
  if (!(x >= 0 && y >= 0 && x < image.cols - 1 && y < image.rows - 1))
    return false;
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double ax = x - x0, ay = y - y0;
  const float* row0 = image.ptr<float>(y0);
  const float* row1 = image.ptr<float>(y0 + 1);
  value = (1 - ay) * ((1 - ax) * row0[x0] + ax * row0[x0 + 1]) +
          ay * ((1 - ax) * row1[x0] + ax * row1[x0 + 1]);
  return true;
}

// Pinhole intrinsics of pyramid level `level` (each level halves the previous; pixel centres stay
// centres: x_L = (x_0 + 0.5) / 2^L - 0.5).
struct LevelCamera {
  double fx, fy, cx, cy;
  LevelCamera(const CameraIntrinsics& k, int level) {
    const double s = 1.0 / (1 << level);
    fx = k.fx * s;
    fy = k.fy * s;
    cx = (k.cx + 0.5) * s - 0.5;
    cy = (k.cy + 0.5) * s - 0.5;
  }
};

// A current pixel used at one level: its 3D point (current camera frame) and intensity.
struct PhotometricPoint {
  Eigen::Vector3d point;
  double intensity;
};

double huberWeight(double r, double k) {
  const double a = std::abs(r);
  return a <= k ? 1.0 : k / a;
}

// The normal equations of the intensity residuals at pose T over the free directions and the
// brightness offset: r = I_reference(pi(T p)) - I_current(p) - offset. The offset takes up a
// change of the sensor's exposure between the frames (a real camera's auto exposure moves a whole
// image by several grey levels in a tenth of a second), which would otherwise pull the pose. The
// unknowns are ordered (free directions..., offset).
struct Normal {
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  double weighted_sq = 0, weight = 0;
  int used = 0;
  double meanSquare() const { return weight > 0 ? weighted_sq / weight : 0; }
};

Normal normalEquations(const std::vector<PhotometricPoint>& points, const cv::Mat& intensity,
                       const cv::Mat& gx, const cv::Mat& gy, const LevelCamera& camera,
                       const Eigen::Isometry3d& T, double offset,
                       const PhotometricRefinement::Directions& free, double huber) {
  const int k = static_cast<int>(free.cols());
  Normal n;
  n.H = Eigen::MatrixXd::Zero(k + 1, k + 1);
  n.g = Eigen::VectorXd::Zero(k + 1);
  Eigen::RowVectorXd J(k + 1);
  J(k) = -1.0;
  for (const PhotometricPoint& p : points) {
    const Eigen::Vector3d P = T * p.point;
    if (!(P.z() > 1e-3))
      continue;
    const double inv_z = 1.0 / P.z();
    const double x = camera.fx * P.x() * inv_z + camera.cx;
    const double y = camera.fy * P.y() * inv_z + camera.cy;
    double reference = 0, dx = 0, dy = 0;
    if (!sample(intensity, x, y, reference) || !sample(gx, x, y, dx) || !sample(gy, x, y, dy))
      continue;
    const double r = reference - p.intensity - offset;
    J.head(k) = intensityJacobian(P, dx, dy, camera.fx, camera.fy) * free;
    const double w = huberWeight(r, huber);
    n.H.noalias() += w * J.transpose() * J;
    n.g.noalias() += w * r * J.transpose();
    n.weighted_sq += w * r * r;
    n.weight += w;
    ++n.used;
  }
  return n;
}

// The current frame's usable pixels at `level`: valid points whose current intensity gradient is
// at least min_gradient, the max_points strongest.
std::vector<PhotometricPoint> levelPoints(const IntensityPyramid& current,
                                          const PhotometricRefinement::Cloud& cloud, int level,
                                          const PhotometricRefinement::Params& params) {
  const int decimation = current.width() / static_cast<int>(cloud.width);
  const int scale = 1 << level;
  // Visit about one cloud point per pixel of the level.
  const int stride = std::max(1, scale / decimation);
  const cv::Mat& intensity = current.intensity[level];
  const cv::Mat& gx = current.gradient_x[level];
  const cv::Mat& gy = current.gradient_y[level];
  // Selected by the gradient at the nearest pixel of the level (a read, no interpolation: most
  // pixels fail the test), keyed by its square.
  const double min_squared_gradient = params.min_gradient * params.min_gradient;
  std::vector<std::pair<double, PhotometricPoint>> candidates;
  for (std::uint32_t r = 0; r < cloud.height; r += stride) {
    const double y = (r * decimation + 0.5) / scale - 0.5;
    const int row = static_cast<int>(std::lround(y));
    if (row < 0 || row >= intensity.rows)
      continue;
    const float* gx_row = gx.ptr<float>(row);
    const float* gy_row = gy.ptr<float>(row);
    for (std::uint32_t c = 0; c < cloud.width; c += stride) {
      const double x = (c * decimation + 0.5) / scale - 0.5;
      const int column = static_cast<int>(std::lround(x));
      if (column < 0 || column >= intensity.cols)
        continue;
      const double squared_gradient =
          gx_row[column] * gx_row[column] + gy_row[column] * gy_row[column];
      if (squared_gradient < min_squared_gradient)
        continue;
      const pcl::PointNormal& q = cloud(c, r);
      double value = 0;
      if (!std::isfinite(q.x) || !std::isfinite(q.y) || !(q.z > 0) ||
          !sample(intensity, x, y, value))
        continue;
      candidates.push_back(
          {squared_gradient, PhotometricPoint{Eigen::Vector3d(q.x, q.y, q.z), value}});
    }
  }
  if (static_cast<int>(candidates.size()) > params.max_points) {
    std::nth_element(candidates.begin(), candidates.begin() + params.max_points, candidates.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    candidates.resize(params.max_points);
  }
  std::vector<PhotometricPoint> points;
  points.reserve(candidates.size());
  for (auto& candidate : candidates)
    points.push_back(candidate.second);
  return points;
}

}  // namespace

Eigen::Matrix<double, 1, 6> intensityJacobian(const Eigen::Vector3d& P, double gx, double gy,
                                              double fx, double fy) {
  const double inv_z = 1.0 / P.z();
  // grad I * d(projection)/dP.
  const Eigen::RowVector3d dI_dP(gx * fx * inv_z, gy * fy * inv_z,
                                 -(gx * fx * P.x() + gy * fy * P.y()) * inv_z * inv_z);
  Eigen::Matrix<double, 1, 6> J;
  J.head<3>() = dI_dP;
  J.tail<3>() = P.cross(dI_dP.transpose()).transpose();  // dI_dP * (-[P]x) = (P x dI_dP)^T
  return J;
}

IntensityPyramid IntensityPyramid::fromImage(const cv::Mat& image, int levels) {
  if (image.empty())
    throw std::invalid_argument("IntensityPyramid: the image is empty");
  if (image.type() != CV_8UC1 && image.type() != CV_8UC3)
    throw std::invalid_argument("IntensityPyramid: the image must be 8-bit grey or colour");
  if (levels < 1 || levels > 6)
    throw std::invalid_argument("IntensityPyramid: levels must be in [1, 6], got " +
                                std::to_string(levels));
  IntensityPyramid pyramid;
  cv::Mat grey;
  if (image.type() == CV_8UC3)
    cv::cvtColor(image, grey, cv::COLOR_RGB2GRAY);
  else
    grey = image;
  cv::Mat level;
  grey.convertTo(level, CV_32F);
  for (int l = 0; l < levels; ++l) {
    if (l > 0) {
      cv::Mat smaller;
      cv::pyrDown(pyramid.intensity.back(), smaller);
      level = smaller;
    }
    cv::Mat dx, dy;
    // Central differences, (I(x + 1) - I(x - 1)) / 2: grey levels per pixel of the level.
    cv::Sobel(level, dx, CV_32F, 1, 0, 1, 0.5);
    cv::Sobel(level, dy, CV_32F, 0, 1, 1, 0.5);
    pyramid.intensity.push_back(level);
    pyramid.gradient_x.push_back(dx);
    pyramid.gradient_y.push_back(dy);
  }
  return pyramid;
}

void PhotometricRefinement::Params::validate() const {
  const ParamRangeCheck require("PhotometricRefinement::Params");
  require(levels >= 1 && levels <= 6, "levels", "[1, 6]", levels);
  require(max_iterations >= 1 && max_iterations <= 100, "max_iterations", "[1, 100]",
          max_iterations);
  require(max_points >= 10 && max_points <= 1000000, "max_points", "[10, 1e6]", max_points);
  require(min_gradient >= 0 && min_gradient <= 255, "min_gradient", "[0, 255]", min_gradient);
  require(huber > 0 && huber <= 255, "huber", "(0, 255]", huber);
  require(min_points >= 6 && min_points <= max_points, "min_points", "[6, max_points]", min_points);
  require(max_translation > 0 && max_translation <= 10, "max_translation", "(0, 10] m",
          max_translation);
  require(max_rotation > 0 && max_rotation <= 3.2, "max_rotation", "(0, 3.2] rad", max_rotation);
  require(convergence_translation > 0 && convergence_translation < 1, "convergence_translation",
          "(0, 1) m", convergence_translation);
  require(convergence_rotation > 0 && convergence_rotation < 1, "convergence_rotation",
          "(0, 1) rad", convergence_rotation);
}

PhotometricRefinement::PhotometricRefinement(const Params& params) : params_(params) {
  params_.validate();
}

PhotometricRefinement::Result PhotometricRefinement::refine(
    const IntensityPyramid& reference, const IntensityPyramid& current, const Cloud& current_cloud,
    const CameraIntrinsics& intrinsics, const Eigen::Isometry3d& T_reference_current,
    const Directions& free, const Matrix6d& prior_information) const {
  Result result;
  result.T_reference_current = T_reference_current;
  const int k = static_cast<int>(free.cols());
  if (k < 1 || k > 6) {
    result.message = "no free direction to refine";
    return result;
  }
  if (static_cast<int>(reference.intensity.size()) < params_.levels ||
      static_cast<int>(current.intensity.size()) < params_.levels ||
      reference.width() != current.width() || reference.height() != current.height()) {
    result.message = "the keyframe's and the frame's intensity pyramids differ";
    return result;
  }
  if (current_cloud.width == 0 || current_cloud.height <= 1 ||
      current.width() % static_cast<int>(current_cloud.width) != 0 ||
      current.width() / static_cast<int>(current_cloud.width) !=
          current.height() / static_cast<int>(current_cloud.height)) {
    result.message = "the cloud is no integer decimation of the image";
    return result;
  }

  Eigen::Isometry3d T = T_reference_current;
  Eigen::VectorXd moved = Eigen::VectorXd::Zero(k);  // accumulated step along free
  double offset = 0;  // brightness offset, grey levels (kept from level to level)
  // The prior on the step from the start, in the coordinates of `free`.
  const Eigen::MatrixXd prior = free.transpose() * prior_information * free;
  const bool has_prior = prior.squaredNorm() > 0;
  for (int level = params_.levels - 1; level >= 0; --level) {
    const std::vector<PhotometricPoint> points =
        levelPoints(current, current_cloud, level, params_);
    const LevelCamera camera(intrinsics, level);
    const cv::Mat& intensity = reference.intensity[level];
    const cv::Mat& gx = reference.gradient_x[level];
    const cv::Mat& gy = reference.gradient_y[level];
    if (level == 0) {
      const Normal start = normalEquations(points, intensity, gx, gy, camera, T_reference_current,
                                           0.0, free, params_.huber);
      result.rms_before = std::sqrt(start.meanSquare());
    }
    Normal n = normalEquations(points, intensity, gx, gy, camera, T, offset, free, params_.huber);
    // The intensities' normal equations are in grey levels; with a prior they are scaled to
    // information by the level's residual variance at its start (fixed over its iterations), and
    // the cost compared between steps is the prior's plus the scaled residuals'.
    const double to_information = has_prior ? 1.0 / std::max(1e-6, n.meanSquare()) : 1.0;
    const double count = std::max(1, n.used);
    auto cost = [&](const Normal& normal, const Eigen::VectorXd& step) {
      double c = to_information * count * normal.meanSquare();
      if (has_prior)
        c += step.dot(prior * step);
      return c;
    };
    for (int iteration = 0; iteration < params_.max_iterations && n.used > k; ++iteration) {
      Eigen::MatrixXd H = to_information * n.H;
      Eigen::VectorXd g = to_information * n.g;
      if (has_prior) {
        H.topLeftCorner(k, k) += prior;
        g.head(k) += prior * moved;
      }
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
      if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0))
        break;
      Eigen::VectorXd delta = -ldlt.solve(g);
      // A Gauss-Newton step can overshoot where the image is far from linear over the step;
      // halved up to kMaxHalvings times before the level counts as converged.
      constexpr int kMaxHalvings = 3;
      bool decreased = false;
      Eigen::Isometry3d candidate;
      Normal next;
      const double current_cost = cost(n, moved);
      for (int halving = 0; halving <= kMaxHalvings && !decreased; ++halving) {
        if (halving > 0)
          delta *= 0.5;
        candidate = pose_math::orthonormalized(pose_math::retractLeft(free * delta.head(k), T));
        next = normalEquations(points, intensity, gx, gy, camera, candidate, offset + delta(k),
                               free, params_.huber);
        decreased = next.used > k && cost(next, moved + delta.head(k)) < current_cost;
      }
      if (!decreased)
        break;  // this level has converged (or the step left the image)
      const Vector6d xi = free * delta.head(k);
      T = candidate;
      offset += delta(k);
      moved += delta.head(k);
      n = next;
      if (xi.head<3>().norm() < params_.convergence_translation &&
          xi.tail<3>().norm() < params_.convergence_rotation)
        break;
    }
    if (level == 0) {
      result.points = n.used;
      result.rms_after = std::sqrt(n.meanSquare());
      result.brightness_offset = offset;
      const double sigma2 = std::max(1e-6, n.meanSquare());
      // The pose's information with the offset marginalised (Schur complement).
      const Eigen::MatrixXd H_pp = n.H.topLeftCorner(k, k);
      const Eigen::VectorXd H_pb = n.H.topRightCorner(k, 1);
      const double H_bb = n.H(k, k);
      result.information =
          (H_bb > 0 ? Eigen::MatrixXd(H_pp - H_pb * H_pb.transpose() / H_bb) : H_pp) / sigma2;
      if (has_prior)
        result.information += prior;
    }
  }
  const Vector6d total = free * moved;
  if (result.points < params_.min_points) {
    result.message = "too few textured pixels (" + std::to_string(result.points) + ")";
  } else if (total.head<3>().norm() > params_.max_translation ||
             total.tail<3>().norm() > params_.max_rotation) {
    result.message = "the intensities moved the pose too far from the depth alignment";
  } else if (!(result.rms_after < result.rms_before)) {
    result.message = "the intensities do not fit better than at the start";
  } else {
    result.T_reference_current = T;
    result.refined = true;
  }
  return result;
}

namespace {

// The covariance's eigenvectors whose variance is at least (free = true) or below (free = false)
// fraction x degenerate_variance, as columns.
PhotometricRefinement::Directions eigenvectorsOnOneSide(const Matrix6d& covariance,
                                                        double degenerate_variance, double fraction,
                                                        bool free) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(0.5 * (covariance + covariance.transpose()));
  std::vector<int> columns;
  for (int i = 0; i < 6; ++i)
    if ((eigen.eigenvalues()(i) >= fraction * degenerate_variance) == free)
      columns.push_back(i);
  PhotometricRefinement::Directions out(6, static_cast<int>(columns.size()));
  for (std::size_t j = 0; j < columns.size(); ++j)
    out.col(static_cast<int>(j)) = eigen.eigenvectors().col(columns[j]);
  return out;
}

}  // namespace

PhotometricRefinement::Directions freeDirections(const Matrix6d& covariance,
                                                 double degenerate_variance, double fraction) {
  return eigenvectorsOnOneSide(covariance, degenerate_variance, fraction, true);
}

Matrix6d measuredInformation(const Matrix6d& covariance, double degenerate_variance,
                             double fraction, const Matrix6d& floor) {
  const PhotometricRefinement::Directions measured =
      eigenvectorsOnOneSide(covariance, degenerate_variance, fraction, false);
  if (measured.cols() == 0)
    return Matrix6d::Zero();
  const Eigen::MatrixXd restricted = measured.transpose() * (covariance + floor) * measured;
  const Eigen::MatrixXd inverse =
      restricted.ldlt().solve(Eigen::MatrixXd::Identity(restricted.rows(), restricted.cols()));
  return measured * inverse * measured.transpose();
}

}  // namespace quadric_slam
