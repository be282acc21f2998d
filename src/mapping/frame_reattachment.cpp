#include "quadric_slam/mapping/frame_reattachment.h"

#include <Eigen/Cholesky>
#include <stdexcept>

#include "quadric_slam/geometry/se3.h"

namespace quadric_slam {

namespace {

// Relinearisations of the chain: its corrections are centimetres and fractions of a degree, where
// the first solve is already within micrometres.
constexpr int kChainIterations = 3;
// A disagreement beyond this is no small correction of the odometry (a relocalisation the
// odometry did not follow, a lost stretch): the chain is not spread but hangs from its start.
constexpr double kMaxChainRotation = 0.5;     // rad
constexpr double kMaxChainTranslation = 1.0;  // m

bool smallCorrection(const Vector6d& delta) {
  return delta.head<3>().norm() <= kMaxChainTranslation &&
         delta.tail<3>().norm() <= kMaxChainRotation;
}

Eigen::Isometry3d chainEnd(const Eigen::Isometry3d& X_start,
                           const std::vector<Eigen::Isometry3d>& steps) {
  Eigen::Isometry3d X = X_start;
  for (const Eigen::Isometry3d& step : steps)
    X = X * step;
  return X;
}

std::vector<Eigen::Isometry3d> composeChain(const Eigen::Isometry3d& X_start,
                                            const std::vector<Eigen::Isometry3d>& steps) {
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(steps.size());
  Eigen::Isometry3d X = X_start;
  for (const Eigen::Isometry3d& step : steps) {
    X = X * step;
    poses.push_back(X);
  }
  return poses;
}

}  // namespace

std::vector<Eigen::Isometry3d> smoothOdometryChain(const Eigen::Isometry3d& X_start,
                                                   const std::vector<Eigen::Isometry3d>& increments,
                                                   const std::vector<Matrix6d>& covariances,
                                                   const Eigen::Isometry3d& X_end) {
  if (increments.size() != covariances.size())
    throw std::invalid_argument("smoothOdometryChain: one covariance per increment is needed");
  const std::size_t n = increments.size();
  if (n == 0)
    return {};
  // steps[i] = Z_i exp(xi_i^): the increments corrected so far; xi[i] their corrections.
  std::vector<Eigen::Isometry3d> steps = increments;
  std::vector<Vector6d> xi(n, Vector6d::Zero());
  std::vector<Matrix6d> J(n);
  for (int iteration = 0; iteration < kChainIterations; ++iteration) {
    const Vector6d delta = logSE3(chainEnd(X_start, steps).inverse() * X_end);
    if (delta.norm() < 1e-12)
      break;
    // J_i = Ad(P_i^-1): a perturbation right of step i seen at the chain's end.
    Eigen::Isometry3d after = Eigen::Isometry3d::Identity();  // P_i
    Matrix6d M = Matrix6d::Zero();
    Vector6d J_xi = Vector6d::Zero();
    for (std::size_t k = n; k-- > 0;) {
      J[k] = adjointSE3(after.inverse());
      M += J[k] * covariances[k] * J[k].transpose();
      J_xi += J[k] * xi[k];
      after = steps[k] * after;
    }
    const Eigen::LLT<Matrix6d> llt(M);
    if (llt.info() != Eigen::Success)
      return composeChain(X_start, increments);
    // The new corrections xi + d minimise sum |xi_i + d_i|^2_Sigma_i subject to sum J_i d_i =
    // delta.
    const Vector6d lambda = llt.solve(delta + J_xi);
    for (std::size_t k = 0; k < n; ++k) {
      const Vector6d d = covariances[k] * J[k].transpose() * lambda - xi[k];
      steps[k] = steps[k] * expSE3(d);
      xi[k] = logSE3(increments[k].inverse() * steps[k]);
    }
  }
  return composeChain(X_start, steps);
}

std::vector<RefinedPose> reattachFrames(const BatchRecorder& recorder,
                                        const std::vector<Eigen::Isometry3d>& keyframe_poses) {
  if (keyframe_poses.size() != recorder.keyframes().size())
    throw std::invalid_argument("reattachFrames: one pose per recorded keyframe is needed");
  const std::vector<RecordedFrame>& frames = recorder.frames();
  std::vector<RefinedPose> out;
  out.reserve(frames.size());
  for (const RecordedFrame& frame : frames) {
    RefinedPose pose{frame.stamp, frame.T_map_camera};
    if (frame.keyframe >= 0) {
      const RecordedKeyframe& keyframe = recorder.keyframes()[frame.keyframe];
      // The mapper's prediction (quadric_mapper.h, step 1) from the refined keyframe pose.
      pose.T_map_camera =
          keyframe_poses[frame.keyframe] * keyframe.T_odom_camera.inverse() * frame.T_odom_camera;
    }
    out.push_back(pose);
  }

  // Spread each pair of consecutive keyframes' disagreement with the odometry over its frames.
  std::size_t start = frames.size();  // the latest keyframe's frame
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (!frames[f].is_keyframe || frames[f].keyframe < 0)
      continue;
    if (start < frames.size() && frames[start].keyframe + 1 == frames[f].keyframe) {
      std::vector<Eigen::Isometry3d> increments;
      std::vector<Matrix6d> covariances;
      for (std::size_t k = start + 1; k <= f; ++k) {
        increments.push_back(frames[k - 1].T_odom_camera.inverse() * frames[k].T_odom_camera);
        covariances.push_back(frames[k].increment_covariance);
      }
      const Eigen::Isometry3d& X_start = keyframe_poses[frames[start].keyframe];
      const Eigen::Isometry3d& X_end = keyframe_poses[frames[f].keyframe];
      if (smallCorrection(logSE3(chainEnd(X_start, increments).inverse() * X_end))) {
        const std::vector<Eigen::Isometry3d> chain =
            smoothOdometryChain(X_start, increments, covariances, X_end);
        for (std::size_t k = start + 1; k < f; ++k)
          out[k].T_map_camera = chain[k - start - 1];
      }
    }
    start = f;
  }
  return out;
}

}  // namespace quadric_slam
