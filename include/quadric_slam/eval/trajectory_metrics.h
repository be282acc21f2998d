// Trajectory error against ground truth, following TUM's benchmark tools exactly:
// - AbsoluteTrajectoryError = evaluate_ate.py with default options: associate.py pairs
//   (offset 0, max_difference 0.02 s), rigid alignment without scale of the estimate onto the
//   ground truth (Horn's closed form via SVD, with the reflection fix), RMSE of the translational
//   residuals.
// - RelativePoseError = evaluate_rpe.py --fixed_delta --delta 1 --delta_unit s (no random
//   sub-sampling): for each estimate stamp t_i, j = the estimate stamp closest to t_i + delta
//   (pairs whose j is the last estimate are dropped, as in evaluate_rpe.py), both ends mapped to
//   the closest ground-truth stamps (skipped if either is more than twice the median ground-truth
//   interval away), error = (E_j^-1 E_i)^-1 (G_j^-1 G_i); translational RMSE over pairs = drift in
//   m per delta seconds (m/s for delta = 1 s), rotational RMSE in rad per delta.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <utility>
#include <vector>

#include "quadric_slam/io/stamp_association.h"
#include "quadric_slam/io/trajectory_io.h"

namespace quadric_slam {

// A trajectory as TUM's tools see it (a dict keyed by stamp): sorted by stamp, a repeated stamp
// keeps its last pose.
Trajectory uniqueSortedByStamp(const Trajectory& trajectory);

// Rigid transform (no scale) minimising sum |T model_k - data_k|^2 (Horn 1987 / Umeyama without
// scale, as evaluate_ate.py's align()): R = U diag(1, 1, det(U V^T)) V^T from the SVD of the
// cross-covariance, t = mean(data) - R mean(model). Needs >= 3 non-collinear points for a unique R.
Eigen::Isometry3d alignRigid(const std::vector<Eigen::Vector3d>& model,
                             const std::vector<Eigen::Vector3d>& data);

struct ErrorStatistics {
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0;
};
ErrorStatistics errorStatistics(const std::vector<double>& errors);  // std as numpy.std (1/n)

struct AteResult {
  std::vector<std::pair<double, double>> stamp_pairs;  // (ground-truth stamp, estimate stamp)
  Eigen::Isometry3d T_gt_est = Eigen::Isometry3d::Identity();  // estimate frame -> gt frame
  std::vector<double> errors;                                  // per pair, m
  ErrorStatistics statistics;                                  // of errors, m
  std::size_t pairs() const { return errors.size(); }
  double rmse() const { return statistics.rmse; }
};

class AbsoluteTrajectoryError {
 public:
  struct Params {
    StampAssociationParams association;  // evaluate_ate.py defaults: offset 0 s, max 0.02 s
    void validate() const { association.validate(); }
  };

  AbsoluteTrajectoryError() : AbsoluteTrajectoryError(Params{}) {}
  explicit AbsoluteTrajectoryError(const Params& params);

  // Throws std::runtime_error when fewer than 3 pose pairs associate.
  AteResult evaluate(const Trajectory& groundtruth, const Trajectory& estimate) const;

 private:
  Params params_;
};

struct RpeResult {
  std::vector<std::pair<double, double>> estimate_stamp_pairs;  // (t_i, t_j)
  std::vector<double> translation_errors;                       // m per delta
  std::vector<double> rotation_errors;                          // rad per delta
  ErrorStatistics translation, rotation;
  std::size_t pairs() const { return translation_errors.size(); }
};

class RelativePoseError {
 public:
  struct Params {
    double delta = 1.0;   // time between the two poses of a pair (s)
    double offset = 0.0;  // added to estimate stamps before looking up ground truth (s)
    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  RelativePoseError() : RelativePoseError(Params{}) {}
  explicit RelativePoseError(const Params& params);

  // Throws std::runtime_error (with evaluate_rpe.py's reasons) when fewer than 2 stamps overlap or
  // fewer than 2 pairs survive.
  RpeResult evaluate(const Trajectory& groundtruth, const Trajectory& estimate) const;

 private:
  Params params_;
};

}  // namespace quadric_slam
