#include "quadric_slam/eval/trajectory_metrics.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

namespace quadric_slam {
namespace {

// evaluate_rpe.py's find_closest_index: a binary search that also tracks the closest element seen.
std::size_t findClosestIndex(const std::vector<double>& sorted, double t) {
  std::size_t beginning = 0, end = sorted.size(), best = 0;
  double difference = std::abs(sorted[0] - t);
  while (beginning < end) {
    const std::size_t middle = (end + beginning) / 2;
    if (std::abs(sorted[middle] - t) < difference) {
      difference = std::abs(sorted[middle] - t);
      best = middle;
    }
    if (t == sorted[middle])
      return middle;
    if (sorted[middle] > t) {
      end = middle;
    } else {
      beginning = middle + 1;
    }
  }
  return best;
}

double median(std::vector<double> values) {  // numpy.median: mean of the two middle values
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::vector<double> stampsOf(const Trajectory& trajectory) {
  std::vector<double> stamps;
  stamps.reserve(trajectory.size());
  for (const StampedPose& pose : trajectory)
    stamps.push_back(pose.stamp);
  return stamps;
}

}  // namespace

Trajectory uniqueSortedByStamp(const Trajectory& trajectory) {
  std::map<double, Eigen::Isometry3d> by_stamp;
  for (const StampedPose& pose : trajectory)
    by_stamp[pose.stamp] = pose.T_world_sensor;
  Trajectory result;
  result.reserve(by_stamp.size());
  for (const auto& entry : by_stamp)
    result.push_back({entry.first, entry.second});
  return result;
}

Eigen::Isometry3d alignRigid(const std::vector<Eigen::Vector3d>& model,
                             const std::vector<Eigen::Vector3d>& data) {
  if (model.size() != data.size() || model.empty()) {
    throw std::invalid_argument("alignRigid needs two non-empty point lists of equal size");
  }
  const double n = static_cast<double>(model.size());
  Eigen::Vector3d model_mean = Eigen::Vector3d::Zero(), data_mean = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < model.size(); ++k) {
    model_mean += model[k];
    data_mean += data[k];
  }
  model_mean /= n;
  data_mean /= n;
  // Horn's closed form as evaluate_ate.py's align(): W = sum (m - m_mean)(d - d_mean)^T,
  // U S V^T = svd(W^T), R = U diag(1, 1, +-1) V^T.
  Eigen::Matrix3d W = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < model.size(); ++k) {
    W += (model[k] - model_mean) * (data[k] - data_mean).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(W.transpose(),
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0)
    S(2, 2) = -1;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = svd.matrixU() * S * svd.matrixV().transpose();
  T.translation() = data_mean - T.linear() * model_mean;
  return T;
}

ErrorStatistics errorStatistics(const std::vector<double>& errors) {
  ErrorStatistics s;
  if (errors.empty())
    return s;
  const double n = static_cast<double>(errors.size());
  double sum = 0, sum_sq = 0;
  for (double e : errors) {
    sum += e;
    sum_sq += e * e;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  double var = 0;
  for (double e : errors)
    var += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(var / n);
  s.median = median(errors);
  s.min = *std::min_element(errors.begin(), errors.end());
  s.max = *std::max_element(errors.begin(), errors.end());
  return s;
}

AbsoluteTrajectoryError::AbsoluteTrajectoryError(const Params& params) : params_(params) {
  params_.validate();
}

AteResult AbsoluteTrajectoryError::evaluate(const Trajectory& groundtruth,
                                            const Trajectory& estimate) const {
  const Trajectory gt = uniqueSortedByStamp(groundtruth);
  const Trajectory est = uniqueSortedByStamp(estimate);
  const auto matches = associateStamps(stampsOf(gt), stampsOf(est), params_.association);
  if (matches.size() < 3) {
    throw std::runtime_error("only " + std::to_string(matches.size()) +
                             " pose pairs associate within " +
                             std::to_string(params_.association.max_difference) +
                             " s (need >= 3): do the stamps of the two trajectories overlap?");
  }
  AteResult result;
  std::vector<Eigen::Vector3d> gt_xyz, est_xyz;
  for (const auto& match : matches) {
    result.stamp_pairs.emplace_back(gt[match.first].stamp, est[match.second].stamp);
    gt_xyz.push_back(gt[match.first].T_world_sensor.translation());
    est_xyz.push_back(est[match.second].T_world_sensor.translation());
  }
  result.T_gt_est = alignRigid(est_xyz, gt_xyz);
  for (std::size_t k = 0; k < gt_xyz.size(); ++k) {
    result.errors.push_back((result.T_gt_est * est_xyz[k] - gt_xyz[k]).norm());
  }
  result.statistics = errorStatistics(result.errors);
  return result;
}

void RelativePoseError::Params::validate() const {
  if (!(delta > 0.0) || !std::isfinite(delta)) {
    throw std::invalid_argument("delta must be in (0, inf) s, got " + std::to_string(delta));
  }
  if (!std::isfinite(offset)) {
    throw std::invalid_argument("offset must be finite (s), got " + std::to_string(offset));
  }
}

RelativePoseError::RelativePoseError(const Params& params) : params_(params) {
  params_.validate();
}

RpeResult RelativePoseError::evaluate(const Trajectory& groundtruth,
                                      const Trajectory& estimate) const {
  const Trajectory gt = uniqueSortedByStamp(groundtruth);
  const Trajectory est = uniqueSortedByStamp(estimate);
  if (gt.size() < 2 || est.size() < 2) {
    throw std::runtime_error("RPE needs at least 2 poses in each trajectory");
  }
  const std::vector<double> stamps_gt = stampsOf(gt), stamps_est = stampsOf(est);
  const double offset = params_.offset;

  // evaluate_rpe.py's overlap check: distinct estimate stamps reached by a round trip via gt.
  std::vector<double> returned;
  for (double t_est : stamps_est) {
    const double t_gt = stamps_gt[findClosestIndex(stamps_gt, t_est + offset)];
    const double t_back = stamps_est[findClosestIndex(stamps_est, t_gt - offset)];
    if (std::find(returned.begin(), returned.end(), t_back) == returned.end()) {
      returned.push_back(t_back);
      if (returned.size() >= 2)
        break;
    }
  }
  if (returned.size() < 2) {
    throw std::runtime_error(
        "number of overlapping timestamps is too small: do the two trajectories cover the same "
        "time span?");
  }

  std::vector<double> intervals;
  for (std::size_t k = 1; k < stamps_gt.size(); ++k) {
    intervals.push_back(stamps_gt[k] - stamps_gt[k - 1]);
  }
  const double gt_max_time_difference = 2.0 * median(intervals);

  RpeResult result;
  for (std::size_t i = 0; i < stamps_est.size(); ++i) {
    const std::size_t j = findClosestIndex(stamps_est, stamps_est[i] + params_.delta);
    if (j == stamps_est.size() - 1)
      continue;  // evaluate_rpe.py drops pairs ending at the last pose
    const double t0 = stamps_est[i], t1 = stamps_est[j];
    const std::size_t g0 = findClosestIndex(stamps_gt, t0 + offset);
    const std::size_t g1 = findClosestIndex(stamps_gt, t1 + offset);
    if (std::abs(stamps_gt[g0] - (t0 + offset)) > gt_max_time_difference ||
        std::abs(stamps_gt[g1] - (t1 + offset)) > gt_max_time_difference) {
      continue;
    }
    // error = ominus(ominus(E_j, E_i), ominus(G_j, G_i)) with ominus(a, b) = a^-1 b.
    const Eigen::Isometry3d est_motion = est[j].T_world_sensor.inverse() * est[i].T_world_sensor;
    const Eigen::Isometry3d gt_motion = gt[g1].T_world_sensor.inverse() * gt[g0].T_world_sensor;
    const Eigen::Isometry3d error = est_motion.inverse() * gt_motion;
    const double cos_angle = std::min(1.0, std::max(-1.0, (error.linear().trace() - 1.0) / 2.0));
    result.estimate_stamp_pairs.emplace_back(t0, t1);
    result.translation_errors.push_back(error.translation().norm());
    result.rotation_errors.push_back(std::acos(cos_angle));
  }
  if (result.pairs() < 2) {
    throw std::runtime_error("fewer than 2 pose pairs " + std::to_string(params_.delta) +
                             " s apart match the ground truth: is the estimate long enough?");
  }
  result.translation = errorStatistics(result.translation_errors);
  result.rotation = errorStatistics(result.rotation_errors);
  return result;
}

}  // namespace quadric_slam
