#include "quadric_slam/frontend/depth_correction_estimator.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <stdexcept>
#include <string>

namespace quadric_slam {

void DepthCorrectionEstimator::Params::validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok)
      throw std::invalid_argument("DepthCorrectionEstimator::Params::" + what);
  };
  require(cols >= 3 && rows >= 3 && cols <= 100 && rows <= 100, "cols, rows must be in [3, 100]");
  require(smoothness > 0.0 && std::isfinite(smoothness), "smoothness must be > 0");
  require(min_pixels >= 10, "min_pixels must be >= 10");
  require(pixel_stride >= 1 && pixel_stride <= 16, "pixel_stride must be in [1, 16]");
  require(outlier_sigmas > 0.0, "outlier_sigmas must be > 0");
}

DepthCorrectionEstimator::DepthCorrectionEstimator(int width, int height, double focal_baseline,
                                                   const Params& params)
    : width_(width), height_(height), focal_baseline_(focal_baseline), params_(params) {
  params_.validate();
  if (width < params_.cols || height < params_.rows)
    throw std::invalid_argument("DepthCorrectionEstimator: image smaller than the grid");
  if (!(focal_baseline > 0.0))
    throw std::invalid_argument("DepthCorrectionEstimator: focal_baseline must be > 0 (px m)");
  nodes_ = params_.cols * params_.rows;
  information_ = Eigen::MatrixXd::Zero(nodes_, nodes_);
  vector_ = Eigen::VectorXd::Zero(nodes_);
}

int DepthCorrectionEstimator::addPlane(const std::vector<Eigen::Vector2d>& pixels,
                                       const std::vector<double>& depths) {
  if (pixels.size() != depths.size())
    throw std::invalid_argument("DepthCorrectionEstimator::addPlane: pixels and depths differ");
  // Pixel coordinates scaled to about [-1, 1] keep the 3 x 3 plane blocks well conditioned.
  const double su = 2.0 / width_, sv = 2.0 / height_;
  std::vector<int> used;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const Eigen::Vector2d& p = pixels[i];
    if (static_cast<long>(std::lround(p.x())) % params_.pixel_stride != 0 ||
        static_cast<long>(std::lround(p.y())) % params_.pixel_stride != 0)
      continue;
    if (!(depths[i] > 0.0) || !std::isfinite(depths[i]))
      continue;
    used.push_back(static_cast<int>(i));
  }
  auto features = [&](int i) {
    return Eigen::Vector3d(1.0, pixels[i].x() * su - 1.0, pixels[i].y() * sv - 1.0);
  };
  auto disparity = [&](int i) { return focal_baseline_ / depths[i]; };
  // First plane fit, to leave out what is not on the plane (edges, another surface's pixels).
  for (int round = 0; round < 2; ++round) {
    if (static_cast<int>(used.size()) < params_.min_pixels)
      return 0;
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (int i : used) {
      const Eigen::Vector3d f = features(i);
      a += f * f.transpose();
      b += f * disparity(i);
    }
    const Eigen::Vector3d plane = a.ldlt().solve(b);
    std::vector<double> residuals(used.size());
    double sum_sq = 0.0;
    for (std::size_t k = 0; k < used.size(); ++k) {
      residuals[k] = disparity(used[k]) - features(used[k]).dot(plane);
      sum_sq += residuals[k] * residuals[k];
    }
    const double limit = params_.outlier_sigmas * std::sqrt(sum_sq / used.size());
    std::vector<int> kept;
    for (std::size_t k = 0; k < used.size(); ++k)
      if (std::abs(residuals[k]) <= limit)
        kept.push_back(used[k]);
    used.swap(kept);
  }
  if (static_cast<int>(used.size()) < params_.min_pixels)
    return 0;
  // Normal equations of [plane (3); D (nodes)] for y = f.plane - w.D, then the plane eliminated.
  Eigen::Matrix3d h_pp = Eigen::Matrix3d::Zero();
  Eigen::MatrixXd h_dp = Eigen::MatrixXd::Zero(nodes_, 3);
  Eigen::Vector3d b_p = Eigen::Vector3d::Zero();
  double sum_y2 = 0.0;
  for (int i : used) {
    const Eigen::Vector3d f = features(i);
    const double y = disparity(i);
    const GridWeights g =
        gridWeights(pixels[i].x(), pixels[i].y(), width_, height_, params_.cols, params_.rows);
    h_pp += f * f.transpose();
    b_p += f * y;
    sum_y2 += y * y;
    for (int k = 0; k < 4; ++k) {
      const int n = g.nodes[k];
      const double w = g.weights[k];
      h_dp.row(n) -= w * f.transpose();
      vector_[n] -= w * y;
      for (int l = 0; l < 4; ++l)
        information_(n, g.nodes[l]) += w * g.weights[l];
    }
  }
  const Eigen::LDLT<Eigen::Matrix3d> pp(h_pp);
  information_ -= h_dp * pp.solve(h_dp.transpose());
  vector_ -= h_dp * pp.solve(b_p);
  reduced_sum_sq_ += sum_y2 - b_p.dot(pp.solve(b_p));
  ++segments_;
  pixels_ += static_cast<long long>(used.size());
  return static_cast<int>(used.size());
}

DepthCorrection DepthCorrectionEstimator::solve() const {
  if (segments_ == 0)
    throw std::runtime_error("DepthCorrectionEstimator::solve: no planar segment was added");
  const int cols = params_.cols, rows = params_.rows;
  Eigen::MatrixXd h = information_;
  // Second differences along rows and columns.
  auto addDifference = [&](int a, int b, int c) {
    const int idx[3] = {a, b, c};
    const double coef[3] = {1.0, -2.0, 1.0};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        h(idx[i], idx[j]) += params_.smoothness * coef[i] * coef[j];
  };
  for (int r = 0; r < rows; ++r)
    for (int c = 1; c + 1 < cols; ++c)
      addDifference(r * cols + c - 1, r * cols + c, r * cols + c + 1);
  for (int r = 1; r + 1 < rows; ++r)
    for (int c = 0; c < cols; ++c)
      addDifference((r - 1) * cols + c, r * cols + c, (r + 1) * cols + c);
  // The affine part (1, x, y over the nodes) is fixed to zero: a strong penalty on its projection.
  Eigen::MatrixXd affine(nodes_, 3);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      affine.row(r * cols + c) << 1.0, 2.0 * c / (cols - 1) - 1.0, 2.0 * r / (rows - 1) - 1.0;
  const double gauge = 1e3 * (h.diagonal().maxCoeff() + 1.0);
  h += gauge * affine * affine.transpose();
  const Eigen::VectorXd d = h.ldlt().solve(vector_);
  // Remove what remains of the affine part exactly (least-squares projection onto its complement).
  const Eigen::VectorXd affine_coefficients =
      (affine.transpose() * affine).ldlt().solve(affine.transpose() * d);
  const Eigen::VectorXd offsets = d - affine * affine_coefficients;
  return DepthCorrection(width_, height_, cols, rows,
                         std::vector<double>(offsets.data(), offsets.data() + offsets.size()),
                         focal_baseline_);
}

DepthCorrectionEstimator::Fit DepthCorrectionEstimator::fit(
    const DepthCorrection& correction) const {
  Fit result;
  if (pixels_ == 0)
    return result;
  result.rms_before = std::sqrt(std::max(0.0, reduced_sum_sq_) / pixels_);
  // Residual sum with D: S(D) = S(0) + 2 D.vector' ... in the reduced form: S(0) - 2 b.D + D.H.D
  // with b, H the reduced normal equations (b = vector_ holds -sum w y; sign as accumulated).
  const Eigen::Map<const Eigen::VectorXd> d(correction.offsets().data(),
                                            static_cast<Eigen::Index>(correction.offsets().size()));
  if (d.size() != nodes_)
    return result;
  const double s = reduced_sum_sq_ - 2.0 * vector_.dot(d) + d.dot(information_ * d);
  result.rms_after = std::sqrt(std::max(0.0, s) / pixels_);
  return result;
}

}  // namespace quadric_slam
