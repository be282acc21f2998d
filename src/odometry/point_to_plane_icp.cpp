#include "quadric_slam/odometry/point_to_plane_icp.h"

#include "quadric_slam/odometry/constrained_directions.h"
#include "quadric_slam/types/param_checks.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace quadric_slam {
const char* toString(TrackingStatus status) {
  switch (status) {
    case TrackingStatus::kOk:
      return "ok";
    case TrackingStatus::kDegenerate:
      return "degenerate";
    case TrackingStatus::kLost:
      return "lost";
  }
  return "unknown";
}

int organizedCloudDecimation(const CameraIntrinsics& intrinsics, int cloud_width, int cloud_height,
                             std::string* problem) {
  std::ostringstream why;
  const std::string intrinsics_problem = intrinsics.problem();
  if (!intrinsics_problem.empty()) {
    why << "invalid intrinsics: " << intrinsics_problem;
  } else if (cloud_width <= 0 || cloud_height <= 1) {
    why << "cloud is not organized (" << cloud_width << " x " << cloud_height << ")";
  } else {
    const int d = static_cast<int>(
        std::lround(static_cast<double>(intrinsics.width) / static_cast<double>(cloud_width)));
    if (d >= 1 && intrinsics.width / d == cloud_width && intrinsics.height / d == cloud_height)
      return d;
    why << "cloud is " << cloud_width << " x " << cloud_height
        << ", which is no integer decimation of the " << intrinsics.width << " x "
        << intrinsics.height << " image of the intrinsics";
  }
  if (problem)
    *problem = why.str();
  return 0;
}

void PointToPlaneIcp::Params::validate() const {
  const ParamRangeCheck require("PointToPlaneIcp::Params");
  require(pyramid_levels >= 1 && pyramid_levels <= 6, "pyramid_levels", "[1, 6]", pyramid_levels);
  require(finest_stride >= 1 && finest_stride <= 32, "finest_stride", "[1, 32]", finest_stride);
  require(reference_stride >= 1 && reference_stride <= 16, "reference_stride", "[1, 16]",
          reference_stride);
  require(max_iterations >= 1 && max_iterations <= 100, "max_iterations", "[1, 100]",
          max_iterations);
  require(max_correspondence_distance > 0 && max_correspondence_distance <= 10,
          "max_correspondence_distance", "(0, 10] m", max_correspondence_distance);
  require(coarse_distance_factor >= 1 && coarse_distance_factor <= 10, "coarse_distance_factor",
          "[1, 10]", coarse_distance_factor);
  require(gate_growth_depth > 0 && gate_growth_depth <= 100, "gate_growth_depth", "(0, 100] m",
          gate_growth_depth);
  require(max_normal_angle > 0 && max_normal_angle <= M_PI, "max_normal_angle", "(0, pi] rad",
          max_normal_angle);
  require(huber_delta > 0 && huber_delta <= 1, "huber_delta", "(0, 1] m", huber_delta);
  require(convergence_translation > 0 && std::isfinite(convergence_translation),
          "convergence_translation", "(0, inf) m", convergence_translation);
  require(convergence_rotation > 0 && std::isfinite(convergence_rotation), "convergence_rotation",
          "(0, inf) rad", convergence_rotation);
  require(min_correspondences >= 6 && min_correspondences <= 10000000, "min_correspondences",
          "[6, 1e7]", min_correspondences);
  require(min_eigenvalue_ratio > 0 && min_eigenvalue_ratio < 1, "min_eigenvalue_ratio", "(0, 1)",
          min_eigenvalue_ratio);
  require(noise_information_factor >= 0 && noise_information_factor <= 1000,
          "noise_information_factor", "[0, 1000]", noise_information_factor);
  require(noise_information_min_depth >= 0 && noise_information_min_depth <= 100,
          "noise_information_min_depth", "[0, 100] m", noise_information_min_depth);
  require(degenerate_variance > 0 && std::isfinite(degenerate_variance), "degenerate_variance",
          "(0, inf)", degenerate_variance);
  require(max_translation_from_guess > 0 && std::isfinite(max_translation_from_guess),
          "max_translation_from_guess", "(0, inf) m", max_translation_from_guess);
  require(max_rotation_from_guess > 0 && max_rotation_from_guess <= M_PI, "max_rotation_from_guess",
          "(0, pi] rad", max_rotation_from_guess);
  require(min_overlap_inlier_fraction >= 0 && min_overlap_inlier_fraction <= 1,
          "min_overlap_inlier_fraction", "[0, 1]", min_overlap_inlier_fraction);
  require(max_rms_residual > 0 && max_rms_residual <= 1, "max_rms_residual", "(0, 1] m",
          max_rms_residual);
}

PointToPlaneIcp::PointToPlaneIcp(const Params& params) : params_(params) {
  params_.validate();
  cos_max_normal_angle_ = std::cos(params_.max_normal_angle);
}

void PointToPlaneIcp::setReference(const Cloud& reference, const CameraIntrinsics& intrinsics) {
  std::string problem;
  const int d = organizedCloudDecimation(intrinsics, static_cast<int>(reference.width),
                                         static_cast<int>(reference.height), &problem);
  if (d == 0)
    throw std::invalid_argument("PointToPlaneIcp::setReference: " + problem);
  // Cloud point (col, row) was back-projected from pixel (col * d, row * d) (frame.h); grid cell
  // (i, j) holds cloud point (i * rs, j * rs).
  const int rs = params_.reference_stride;
  const double pixels_per_cell = static_cast<double>(d) * rs;
  fx_ = static_cast<float>(intrinsics.fx / pixels_per_cell);
  fy_ = static_cast<float>(intrinsics.fy / pixels_per_cell);
  cx_ = static_cast<float>(intrinsics.cx / pixels_per_cell);
  cy_ = static_cast<float>(intrinsics.cy / pixels_per_cell);
  const int w = static_cast<int>(reference.width), h = static_cast<int>(reference.height);
  ref_w_ = (w + rs - 1) / rs;
  ref_h_ = (h + rs - 1) / rs;
  reference_.resize(static_cast<std::size_t>(ref_w_) * ref_h_);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int j = 0; j < ref_h_; ++j) {
    for (int i = 0; i < ref_w_; ++i) {
      const pcl::PointNormal& q = reference.points[static_cast<std::size_t>(j * rs) * w + i * rs];
      RefPoint& r = reference_[static_cast<std::size_t>(j) * ref_w_ + i];
      const bool ok = std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
                      std::isfinite(q.normal_x) && std::isfinite(q.normal_y) &&
                      std::isfinite(q.normal_z);
      r = {q.x, q.y, ok ? q.z : nan, q.normal_x, q.normal_y, q.normal_z};
    }
  }
  has_reference_ = true;
}

namespace {
bool usable(const pcl::PointNormal& q) {
  return std::isfinite(q.z) && std::isfinite(q.x) && std::isfinite(q.y) &&
         std::isfinite(q.normal_x) && std::isfinite(q.normal_y) && std::isfinite(q.normal_z);
}
}  // namespace

void PointToPlaneIcp::sampleFinest(const Cloud& current) {
  finest_samples_.clear();
  if (!current.isOrganized() || current.empty())
    return;
  const int stride = params_.finest_stride;
  const int w = static_cast<int>(current.width), h = static_cast<int>(current.height);
  finest_samples_.reserve(static_cast<std::size_t>((w / stride + 1) * (h / stride + 1)));
  for (int row = 0, gv = 0; row < h; row += stride, ++gv) {
    const pcl::PointNormal* line = &current.points[static_cast<std::size_t>(row) * w];
    for (int col = 0, gu = 0; col < w; col += stride, ++gu) {
      const pcl::PointNormal& q = line[col];
      if (usable(q))
        finest_samples_.push_back({q.getVector3fMap(), q.getNormalVector3fMap(), gu, gv});
    }
  }
}

// Level l keeps the finest-grid samples on every 2^l-th row and column.
void PointToPlaneIcp::selectLevel(int level) {
  const int mask = (1 << level) - 1;
  samples_.clear();
  for (const Sample& s : finest_samples_) {
    if ((s.grid_u & mask) == 0 && (s.grid_v & mask) == 0)
      samples_.push_back(s);
  }
}

int PointToPlaneIcp::usablePoints(const Cloud& current) const {
  if (!current.isOrganized() || current.empty())
    return 0;
  const int stride = params_.finest_stride;
  const int w = static_cast<int>(current.width), h = static_cast<int>(current.height);
  int count = 0;
  for (int row = 0; row < h; row += stride) {
    for (int col = 0; col < w; col += stride)
      count += usable(current.points[static_cast<std::size_t>(row) * w + col]) ? 1 : 0;
  }
  return count;
}

// Point-to-plane residual r = n_ref . (R p + t - q_ref) (the linearised ICP of Low 2004); with the
// left perturbation p' <- p' + omega x p' + v its Jacobian is J = [n_ref ; p' x n_ref].
// The noise part of H (constrained_directions.h): with n_ref = n_true + e, H holds J_e J_e^T,
// J_e = [e ; p' x e]. The tangential difference d of the two normals (keyframe and rotated
// current) has E[d d^T] = 2 E[e e^T] when both have the same noise, so it adds J_d J_d^T / 2.
void PointToPlaneIcp::accumulate(const Eigen::Isometry3d& T, double max_distance,
                                 Normals& eq) const {
  eq.H.setZero();
  eq.noise.setZero();
  eq.b.setZero();
  eq.weighted_sq = 0;
  eq.count = 0;
  eq.projected = 0;
  eq.near = 0;
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  const int w = ref_w_, h = ref_h_;
  const float w_f = static_cast<float>(w), h_f = static_cast<float>(h);
  const float max_sq = static_cast<float>(max_distance * max_distance);
  const float inv_growth_sq =
      static_cast<float>(1.0 / (params_.gate_growth_depth * params_.gate_growth_depth));
  const float min_cos = static_cast<float>(cos_max_normal_angle_);
  const double huber = params_.huber_delta;
  const bool noise_weighting = params_.depth_noise_weighting;
  const float noise_min_depth = static_cast<float>(params_.noise_information_min_depth);
  // Upper triangle of H as 21 sums and b, accumulated in double.
  double h_acc[21] = {0};
  double noise_acc[21] = {0};
  double b_acc[6] = {0};
  for (const Sample& s : samples_) {
    const Eigen::Vector3f p = R * s.p + t;
    if (!(p.z() > 1e-3f))
      continue;
    const float inv_z = 1.0f / p.z();
    // Nearest pixel; the range test comes first so the truncation below rounds non-negatives.
    const float u = fx_ * p.x() * inv_z + cx_ + 0.5f;
    const float v = fy_ * p.y() * inv_z + cy_ + 0.5f;
    if (!(u >= 0.0f && v >= 0.0f && u < w_f && v < h_f))
      continue;
    const int col = static_cast<int>(u), row = static_cast<int>(v);
    const RefPoint& ref = reference_[static_cast<std::size_t>(row) * w + col];
    if (!(ref.z == ref.z))  // NaN: no point or no normal there
      continue;
    ++eq.projected;
    const Eigen::Vector3f q(ref.x, ref.y, ref.z);
    const Eigen::Vector3f n(ref.nx, ref.ny, ref.nz);
    const Eigen::Vector3f diff = p - q;
    // Gate (max_distance * g)^2 with g = max(1, (z / gate_growth_depth)^2): noise grows as z^2.
    const float growth = std::max(1.0f, ref.z * ref.z * inv_growth_sq);
    if (diff.squaredNorm() > max_sq * growth * growth)
      continue;
    ++eq.near;
    const Eigen::Vector3f n_current = R * s.n;
    if (n.dot(n_current) < min_cos)
      continue;
    // Depth-noise normalisation: r and J divided by s = (z_ref / 1 m)^2 (sigma(z) ~ z^2).
    const float z_eff = std::max(ref.z, 0.5f);
    const double inv_s = noise_weighting ? 1.0 / (double(z_eff) * z_eff) : 1.0;
    const double r = n.dot(diff) * inv_s;
    const double abs_r = std::abs(r);
    const double weight = abs_r <= huber ? 1.0 : huber / abs_r;  // Huber IRLS weight
    const Eigen::Vector3f pxn = p.cross(n);
    const double J[6] = {n.x() * inv_s,   n.y() * inv_s,   n.z() * inv_s,
                         pxn.x() * inv_s, pxn.y() * inv_s, pxn.z() * inv_s};
    int k = 0;
    for (int i = 0; i < 6; ++i) {
      const double wji = weight * J[i];
      for (int j = i; j < 6; ++j)
        h_acc[k++] += wji * J[j];
      b_acc[i] += wji * r;
    }
    if (ref.z >= noise_min_depth) {
      Eigen::Vector3f d = n_current - n;
      d -= n.dot(d) * n;  // tangential: the tilt of one normal against the other
      const Eigen::Vector3f pxd = p.cross(d);
      const double Jd[6] = {d.x() * inv_s,   d.y() * inv_s,   d.z() * inv_s,
                            pxd.x() * inv_s, pxd.y() * inv_s, pxd.z() * inv_s};
      k = 0;
      for (int i = 0; i < 6; ++i) {
        const double wji = 0.5 * weight * Jd[i];
        for (int j = i; j < 6; ++j)
          noise_acc[k++] += wji * Jd[j];
      }
    }
    eq.weighted_sq += weight * r * r;
    ++eq.count;
  }
  int k = 0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i; j < 6; ++j, ++k) {
      eq.H(i, j) = eq.H(j, i) = h_acc[k];
      eq.noise(i, j) = eq.noise(j, i) = noise_acc[k];
    }
    eq.b(i) = b_acc[i];
  }
}

PointToPlaneIcp::Result PointToPlaneIcp::align(const Cloud& current,
                                               const Eigen::Isometry3d& T_reference_current_guess) {
  Result result;
  result.T_reference_current = T_reference_current_guess;
  result.covariance = Matrix6::Identity() * params_.degenerate_variance;
  if (!has_reference_) {
    result.message = "no reference cloud";
    return result;
  }
  if (!current.isOrganized() || current.empty()) {
    result.message = "current cloud is empty or not organized";
    return result;
  }

  Eigen::Isometry3d T = pose_math::orthonormalized(T_reference_current_guess);
  Normals eq;
  bool finest_ok = false;
  sampleFinest(current);
  for (int level = params_.pyramid_levels - 1; level >= 0; --level) {
    selectLevel(level);
    const int needed = std::max(12, params_.min_correspondences >> (2 * level));
    if (level == 0)
      result.candidate_points = static_cast<int>(samples_.size());
    const double max_distance =
        params_.max_correspondence_distance * std::pow(params_.coarse_distance_factor, level);
    // A level with 4^l times fewer points only needs (and reaches) a coarser fixed point.
    const double convergence_scale = static_cast<double>(1 << (2 * level));
    for (int iteration = 0; iteration < params_.max_iterations; ++iteration) {
      accumulate(T, max_distance, eq);
      if (eq.count < needed)
        break;
      // Degeneracy: directions with too little information, or no more than the normals' noise
      // explains, keep the prior (solution remapping); otherwise the full 6x6 normal equations.
      const ConstrainedDirections directions(eq.H, eq.noise, params_.min_eigenvalue_ratio,
                                             params_.noise_information_factor);
      const int constrained = directions.constrained();
      const Vector6 delta = directions.step(eq.b);
      T = pose_math::retractLeft(delta, T);
      ++result.iterations;
      if (level == 0) {
        finest_ok = true;
        result.correspondences = eq.count;
        result.projected_points = eq.projected;
        result.overlap_near_fraction = eq.projected > 0 ? double(eq.near) / eq.projected : 0.0;
        result.constrained_dof = constrained;
        result.eigenvalue_ratio = directions.eigenvalueRatio();
        result.information_over_noise = ConstrainedDirections::informationOverNoise(eq.H, eq.noise);
        const double dof = std::max(1, eq.count - 6);
        const double sigma2 = eq.weighted_sq / dof;
        result.rms_residual = std::sqrt(eq.weighted_sq / eq.count);
        // Covariance sigma^2 H^-1 of the Gauss-Newton estimate; unconstrained directions get the
        // degenerate_variance.
        result.covariance = directions.covariance(sigma2, params_.degenerate_variance);
      }
      if (delta.head<3>().norm() < params_.convergence_translation * convergence_scale &&
          delta.tail<3>().norm() < params_.convergence_rotation * convergence_scale)
        break;
    }
  }

  if (!finest_ok) {
    std::ostringstream why;
    why << "too few correspondences (" << eq.count << " of " << result.candidate_points
        << " usable points; need " << params_.min_correspondences << ")";
    result.message = why.str();
    result.covariance = Matrix6::Identity() * params_.degenerate_variance;
    result.correspondences = eq.count;
    return result;
  }
  result.inlier_fraction =
      result.candidate_points > 0 ? double(result.correspondences) / result.candidate_points : 0.0;
  result.overlap_inlier_fraction =
      result.projected_points > 0 ? double(result.correspondences) / result.projected_points : 0.0;
  const Eigen::Isometry3d change = T * T_reference_current_guess.inverse();
  const double moved = change.translation().norm();
  const double turned = pose_math::rotationAngle(change);
  if (!(moved <= params_.max_translation_from_guess) ||
      !(turned <= params_.max_rotation_from_guess) || !T.matrix().allFinite()) {
    std::ostringstream why;
    why << "implausible result: " << moved << " m and " << turned << " rad from the initial guess";
    result.message = why.str();
    result.covariance = Matrix6::Identity() * params_.degenerate_variance;
    return result;
  }
  if (result.overlap_near_fraction < params_.min_overlap_inlier_fraction ||
      !(result.rms_residual <= params_.max_rms_residual)) {
    // The data say the alignment is wrong: surfaces the two views share do not meet.
    std::ostringstream why;
    why << "alignment rejected: " << result.overlap_near_fraction << " of "
        << result.projected_points << " overlapping points within the distance gate (need "
        << params_.min_overlap_inlier_fraction << "), residual RMS " << result.rms_residual
        << " (at most " << params_.max_rms_residual << ")";
    result.message = why.str();
    result.covariance = Matrix6::Identity() * params_.degenerate_variance;
    return result;
  }
  result.T_reference_current = pose_math::orthonormalized(T);
  if (result.constrained_dof < 6) {
    result.status = TrackingStatus::kDegenerate;
    std::ostringstream why;
    why << "degenerate geometry: only " << result.constrained_dof
        << " of 6 degrees of freedom constrained; the others keep the prior";
    result.message = why.str();
  } else {
    result.status = TrackingStatus::kOk;
  }
  return result;
}

}  // namespace quadric_slam
