// Two real fr1_xyz frames of the TUM RGB-D benchmark shipped in test/data (depth registered to
// colour, 0.1 s apart: 2.6 cm and 2 degrees of hand-held motion) and the motion-capture ground
// truth around them.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "../test_data.h"
#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/io/tum_folder_reader.h"

namespace quadric_slam {
namespace test {

inline constexpr double kFr1XyzDepthStampA = 1305031102.160407;
inline constexpr double kFr1XyzDepthStampB = 1305031102.262886;
inline constexpr char kFr1XyzDepthA[] = "tum_frames/fr1_xyz/1305031102.160407.png";
inline constexpr char kFr1XyzDepthB[] = "tum_frames/fr1_xyz/1305031102.262886.png";
// The colour images TUM's associate.py pairs with them (15 and 12 ms after the depth).
inline constexpr double kFr1XyzRgbStampA = 1305031102.175304;
inline constexpr double kFr1XyzRgbStampB = 1305031102.275326;
inline constexpr char kFr1XyzRgbA[] = "tum_frames/fr1_xyz/1305031102.175304.png";
inline constexpr char kFr1XyzRgbB[] = "tum_frames/fr1_xyz/1305031102.275326.png";
inline constexpr char kFr1XyzGroundTruth[] =
    "tum_groundtruth/rgbd_dataset_freiburg1_xyz-groundtruth.txt";

// Freiburg 1 intrinsics (test/data/README.md), VGA.
inline CameraIntrinsics fr1Intrinsics() {
  return tumIntrinsicsForSequence("fr1_xyz");
}

// Ground-truth pose (T_world_camera, colour optical frame) at time t, interpolated linearly in
// position and by slerp in orientation between the two bracketing motion-capture samples of the
// shipped excerpt. False when t is outside it.
inline bool fr1XyzGroundTruthAt(double t, Eigen::Isometry3d* pose) {
  const Trajectory truth = readTumTrajectory(shippedData(kFr1XyzGroundTruth).string());
  for (std::size_t i = 1; i < truth.size(); ++i) {
    const StampedPose& a = truth[i - 1];
    const StampedPose& b = truth[i];
    if (a.stamp <= t && t <= b.stamp) {
      const double s = (t - a.stamp) / (b.stamp - a.stamp);
      const Eigen::Quaterniond qa(a.T_world_sensor.linear()), qb(b.T_world_sensor.linear());
      pose->setIdentity();
      pose->linear() = qa.slerp(s, qb).toRotationMatrix();
      pose->translation() =
          (1 - s) * a.T_world_sensor.translation() + s * b.T_world_sensor.translation();
      return true;
    }
  }
  return false;
}

// The true motion T_a_b between the camera at stamps a and b.
inline bool fr1XyzTrueMotion(double stamp_a, double stamp_b, Eigen::Isometry3d* T_a_b) {
  Eigen::Isometry3d T_world_a, T_world_b;
  if (!fr1XyzGroundTruthAt(stamp_a, &T_world_a) || !fr1XyzGroundTruthAt(stamp_b, &T_world_b))
    return false;
  *T_a_b = T_world_a.inverse() * T_world_b;
  return true;
}

}  // namespace test
}  // namespace quadric_slam
