#include "quadric_slam/odometry/corner_pair_geometry.h"

#include <cmath>

#include <ceres/ceres.h>
#include <ceres/rotation.h>

namespace quadric_slam {
namespace {

// A corner this close to a camera's plane (m) does not reproject into it.
constexpr double kMinProjectedDepth = 0.05;
// The depth gate spans this many standard deviations of the depth noise.
constexpr double kDepthGateSigmas = 3.0;
// Iterations of the refinement (Levenberg-Marquardt from a start within the gates).
constexpr int kRefinementIterations = 20;
// Central-difference step of the information's Jacobian (m, rad).
constexpr double kInformationStep = 1e-6;

double depthGate(double z, const CornerPairGates& gates) {
  return gates.depth + gates.depth_per_z2 * z * z;
}

// The corner `point` (seen by the other camera), moved into this camera, lies near the corner
// observed here (pixel, depth).
bool agreesInCamera(const Eigen::Vector3d& moved, const Eigen::Vector2d& pixel, double pixel_scale,
                    double observed_depth, const CameraIntrinsics& k,
                    const CornerPairGates& gates) {
  if (moved.z() < kMinProjectedDepth)
    return false;
  if (std::abs(moved.z() - observed_depth) >= depthGate(observed_depth, gates))
    return false;
  const Eigen::Vector2d projected(k.fx * moved.x() / moved.z() + k.cx,
                                  k.fy * moved.y() / moved.z() + k.cy);
  const double gate = gates.pixels * pixel_scale;
  return (projected - pixel).squaredNorm() < gate * gate;
}

// One corner seen from the other camera: the residuals (reprojection in pixels, depth along the
// ray), each over its standard deviation. The pose is T_reference_current as an angle-axis and
// a translation; `into_reference` moves a current corner by it, otherwise a reference corner by
// its inverse.
struct CornerSeenFromOtherCamera {
  Eigen::Vector3d point;  // the corner in its own camera
  Eigen::Vector2d pixel;  // where the other camera saw its match
  double depth;           // and at what depth
  double pixel_sigma, depth_sigma;
  double fx, fy, cx, cy;
  bool into_reference;

  template <typename T>
  bool operator()(const T* rotation, const T* translation, T* residuals) const {
    const T p[3] = {T(point.x()), T(point.y()), T(point.z())};
    T moved[3];
    if (into_reference) {
      ceres::AngleAxisRotatePoint(rotation, p, moved);
      for (int i = 0; i < 3; ++i)
        moved[i] += translation[i];
    } else {
      const T shifted[3] = {p[0] - translation[0], p[1] - translation[1], p[2] - translation[2]};
      const T inverse[3] = {-rotation[0], -rotation[1], -rotation[2]};
      ceres::AngleAxisRotatePoint(inverse, shifted, moved);
    }
    if (moved[2] < T(kMinProjectedDepth))
      return false;  // the step is rejected
    residuals[0] = (T(fx) * moved[0] / moved[2] + T(cx) - T(pixel.x())) / T(pixel_sigma);
    residuals[1] = (T(fy) * moved[1] / moved[2] + T(cy) - T(pixel.y())) / T(pixel_sigma);
    residuals[2] = (moved[2] - T(depth)) / T(depth_sigma);
    return true;
  }
};

CornerSeenFromOtherCamera seenFromOther(const MatchedCorners& from, const MatchedCorners& seen_by,
                                        int i, bool into_reference, const CornerPairGates& gates) {
  const double depth = seen_by.points(2, i);
  const CameraIntrinsics& k = seen_by.intrinsics;
  return {from.points.col(i),
          seen_by.pixels.col(i),
          depth,
          seen_by.pixel_scales(i),
          depthGate(depth, gates) / kDepthGateSigmas,
          k.fx,
          k.fy,
          k.cx,
          k.cy,
          into_reference};
}

// Every used pair's six residuals (both cameras) at T, each block of three scaled by its weight.
Eigen::VectorXd weightedResiduals(const MatchedCorners& reference, const MatchedCorners& current,
                                  const std::vector<int>& used, const Eigen::Isometry3d& T,
                                  const std::vector<double>& weights,
                                  const CornerPairGates& gates) {
  const Eigen::AngleAxisd angle_axis(T.rotation());
  const Eigen::Vector3d rotation = angle_axis.angle() * angle_axis.axis();
  const Eigen::Vector3d translation = T.translation();
  Eigen::VectorXd out = Eigen::VectorXd::Zero(6 * static_cast<Eigen::Index>(used.size()));
  for (size_t j = 0; j < used.size(); ++j) {
    for (int side = 0; side < 2; ++side) {
      const CornerSeenFromOtherCamera residual =
          side == 0 ? seenFromOther(current, reference, used[j], true, gates)
                    : seenFromOther(reference, current, used[j], false, gates);
      double r[3] = {0, 0, 0};
      if (residual(rotation.data(), translation.data(), r))
        for (int c = 0; c < 3; ++c)
          out(6 * static_cast<Eigen::Index>(j) + 3 * side + c) = weights[2 * j + side] * r[c];
    }
  }
  return out;
}

}  // namespace

std::vector<int> cornerPairsAgreeing(const MatchedCorners& reference, const MatchedCorners& current,
                                     const Eigen::Isometry3d& T_reference_current,
                                     const CornerPairGates& gates) {
  const Eigen::Isometry3d T_current_reference = T_reference_current.inverse();
  std::vector<int> agreeing;
  for (int i = 0; i < static_cast<int>(reference.points.cols()); ++i) {
    if (agreesInCamera(T_reference_current * current.points.col(i), reference.pixels.col(i),
                       reference.pixel_scales(i), reference.points(2, i), reference.intrinsics,
                       gates) &&
        agreesInCamera(T_current_reference * reference.points.col(i), current.pixels.col(i),
                       current.pixel_scales(i), current.points(2, i), current.intrinsics, gates))
      agreeing.push_back(i);
  }
  return agreeing;
}

Eigen::Isometry3d refineCornerPairPose(const MatchedCorners& reference,
                                       const MatchedCorners& current, const std::vector<int>& used,
                                       const Eigen::Isometry3d& T_reference_current,
                                       const CornerPairGates& gates) {
  const Eigen::AngleAxisd start(T_reference_current.rotation());
  Eigen::Vector3d rotation = start.angle() * start.axis();
  Eigen::Vector3d translation = T_reference_current.translation();
  ceres::Problem problem;
  const auto add = [&](const MatchedCorners& from, const MatchedCorners& seen_by, int i,
                       bool into_reference) {
    auto* cost = new ceres::AutoDiffCostFunction<CornerSeenFromOtherCamera, 3, 3, 3>(
        new CornerSeenFromOtherCamera(seenFromOther(from, seen_by, i, into_reference, gates)));
    problem.AddResidualBlock(cost, new ceres::HuberLoss(1.0), rotation.data(), translation.data());
  };
  for (const int i : used) {
    add(current, reference, i, true);
    add(reference, current, i, false);
  }
  if (used.empty())
    return T_reference_current;
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = kRefinementIterations;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable() || !rotation.allFinite() || !translation.allFinite())
    return T_reference_current;
  Eigen::Isometry3d refined = Eigen::Isometry3d::Identity();
  const double angle = rotation.norm();
  if (angle > 0)
    refined.linear() = Eigen::AngleAxisd(angle, rotation / angle).toRotationMatrix();
  refined.translation() = translation;
  return refined;
}

Matrix6d cornerPairInformation(const MatchedCorners& reference, const MatchedCorners& current,
                               const std::vector<int>& used,
                               const Eigen::Isometry3d& T_reference_current,
                               const CornerPairGates& gates) {
  if (used.empty())
    return Matrix6d::Zero();
  // The Huber weights at the pose (loss at one standard deviation): a block of norm s > 1 has its
  // squared residual counted 1 / s, so its residuals 1 / sqrt(s).
  std::vector<double> weights(2 * used.size(), 1.0);
  const Eigen::VectorXd unweighted =
      weightedResiduals(reference, current, used, T_reference_current, weights, gates);
  for (size_t block = 0; block < weights.size(); ++block) {
    const double norm = unweighted.segment<3>(3 * static_cast<Eigen::Index>(block)).norm();
    weights[block] = norm > 1.0 ? 1.0 / std::sqrt(norm) : 1.0;
  }
  Eigen::MatrixXd jacobian(unweighted.size(), 6);
  for (int d = 0; d < 6; ++d) {
    Vector6d step = Vector6d::Zero();
    step(d) = kInformationStep;
    jacobian.col(d) = (weightedResiduals(reference, current, used,
                                         expSE3(step) * T_reference_current, weights, gates) -
                       weightedResiduals(reference, current, used,
                                         expSE3(-step) * T_reference_current, weights, gates)) /
                      (2 * kInformationStep);
  }
  return jacobian.transpose() * jacobian;
}

}  // namespace quadric_slam
