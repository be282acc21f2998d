// The pipeline passes the tracker's increment covariance to the mapper (mapping.yaml
// odometry_increment_covariance): the odometry factor between two keyframes then carries exactly
// the tracker's increments since the previous keyframe, composed (right perturbations:
// C <- Ad(T_pc^-1) C Ad(T_pc^-1)^T + C_pc), each step the mapper takes within the camera's speed
// bound (mapping.yaml max_camera_speed); across a loss of tracking the mapper's own model; with the
// key off the mapper's own odometry_* model is used instead. The key is read from mapping.yaml.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "quadric_slam/geometry/se3.h"
#include "quadric_slam/mapping/motion_bound.h"
#include "quadric_slam/pipeline/quadric_slam.h"
#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/synthetic_frame_source.h"

namespace qs = quadric_slam;

namespace {

const std::string kConfigDir = std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config";

struct PipelineRun {
  std::vector<qs::Matrix6d>
      recorded;  // the recorded keyframes' odometry covariances (from the 2nd)
  std::vector<qs::Matrix6d> composed;  // the tracker's increments composed between them
  std::vector<bool> across_loss;       // the interval held a lost frame
  int lost = 0;
};

// A rendered desk sequence at 10 Hz whose depth is blanked for frames [20, 23) (lost frames, the
// tracker's pose kept) through the pipeline with the batch recorder on (it keeps every keyframe's
// odometry factor).
PipelineRun runPipeline(bool use_increment_covariance) {
  qs::SlamParams params = qs::loadSlamParams(kConfigDir);
  params.batch_refinement = true;
  params.odometry_increment_covariance = use_increment_covariance;
  qs::QuadricSlam slam(params);
  qs::SyntheticFrameSource::Params source_params;
  source_params.seconds = 5.0;
  source_params.rate = 10.0;
  source_params.seed = 5;
  source_params.rgb = false;
  qs::SyntheticFrameSource source(qs::readSceneYaml(kConfigDir + "/scenes/desk.yaml"),
                                  source_params);
  PipelineRun out;
  // The tracker's increments since the frame the mapper last took, and since the last keyframe.
  qs::Matrix6d since_mapped = qs::Matrix6d::Zero(), composed = qs::Matrix6d::Zero();
  Eigen::Isometry3d T_since_mapped = Eigen::Isometry3d::Identity();
  double mapped_stamp = std::numeric_limits<double>::quiet_NaN();
  bool after_keyframe = false, lost_since_keyframe = false;
  qs::RgbdFrame frame;
  for (int k = 0; source.next(frame); ++k) {
    if (k >= 20 && k < 23)
      frame.depth_m.setTo(std::numeric_limits<float>::quiet_NaN());
    const qs::SlamFrameResult result = slam.process(frame);
    if (!result.tracking)
      continue;
    const bool lost = result.odometry.status == qs::TrackingStatus::kLost;
    out.lost += lost;
    lost_since_keyframe = lost_since_keyframe || lost;
    const qs::Matrix6d ad = qs::adjointSE3(result.odometry.increment.inverse());
    since_mapped = ad * since_mapped * ad.transpose() + result.odometry.increment_covariance;
    T_since_mapped = T_since_mapped * result.odometry.increment;
    if (!result.mapped)
      continue;
    // What the mapper receives over the time since the frame it took before, within the camera's
    // speed bound (mapping/motion_bound.h: the lost frames' 1 m^2 is clamped there).
    const qs::Matrix6d received =
        std::isfinite(mapped_stamp)
            ? qs::boundIncrementCovariance(since_mapped, frame.stamp - mapped_stamp,
                                           params.mapping.max_camera_speed,
                                           params.mapping.max_camera_angular_speed)
            : since_mapped;
    const qs::Matrix6d ad_mapped = qs::adjointSE3(T_since_mapped.inverse());
    composed = ad_mapped * composed * ad_mapped.transpose() + received;
    since_mapped.setZero();
    T_since_mapped.setIdentity();
    mapped_stamp = frame.stamp;
    if (result.mapping.keyframe) {
      if (after_keyframe) {
        out.composed.push_back(composed);
        out.across_loss.push_back(lost_since_keyframe);
      }
      lost_since_keyframe = false;
      composed.setZero();
      after_keyframe = true;
    }
  }
  const auto& keyframes = slam.batchRecorder().keyframes();
  for (size_t i = 1; i < keyframes.size(); ++i)
    out.recorded.push_back(keyframes[i].increment_covariance);
  return out;
}

bool sameCovariance(const qs::Matrix6d& a, const qs::Matrix6d& b) {
  return (a - b).norm() <= 1e-6 * b.norm();
}

}  // namespace

TEST(QuadricSlamIncrementCovariance, OdometryFactorsCarryTheTrackersComposedIncrements) {
  const PipelineRun on = runPipeline(true);
  ASSERT_GT(on.lost, 0) << "the blanked frames no longer lose tracking: the test proves less";
  ASSERT_GE(on.recorded.size(), 3u);
  ASSERT_EQ(on.recorded.size(), on.composed.size());
  int relocalised = 0, compared = 0, across_loss = 0;
  for (size_t i = 0; i < on.recorded.size(); ++i) {
    // After the loss the mapper may relocalise: that keyframe's factor is its 1e4 "unknown".
    if (on.recorded[i].isApprox(1e4 * qs::Matrix6d::Identity())) {
      ++relocalised;
      continue;
    }
    if (on.across_loss[i]) {
      // A lost frame's increment (1 m^2, 1 rad^2) does not reach the factor: the step after the
      // loss takes the mapper's own odometry model.
      ++across_loss;
      EXPECT_LT(on.recorded[i].diagonal().maxCoeff(), 0.01)
          << "keyframe " << i + 1 << " carries the lost frames' increments\n"
          << on.recorded[i];
      continue;
    }
    ++compared;
    EXPECT_TRUE(sameCovariance(on.recorded[i], on.composed[i]))
        << "keyframe " << i + 1 << "\nrecorded\n"
        << on.recorded[i] << "\ncomposed\n"
        << on.composed[i];
  }
  EXPECT_LE(relocalised, 1);
  EXPECT_GE(compared, 2);
  EXPECT_GE(across_loss + relocalised, 1) << "no keyframe interval held the loss";

  const PipelineRun off = runPipeline(false);
  ASSERT_GE(off.recorded.size(), 3u);
  int same = 0;
  for (size_t i = 0; i < std::min(off.recorded.size(), off.composed.size()); ++i)
    same += sameCovariance(off.recorded[i], off.composed[i]);
  EXPECT_EQ(same, 0) << "with the key off the mapper must use its own odometry_* model";
}

TEST(QuadricSlamIncrementCovariance, KeyIsReadFromMappingYaml) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "qs_increment_covariance_key";
  std::filesystem::create_directories(dir);
  {
    std::ofstream yaml(dir / "mapping.yaml");
    yaml << "odometry_increment_covariance: false\n";
  }
  EXPECT_FALSE(qs::loadSlamParams(dir.string()).odometry_increment_covariance);
  {
    std::ofstream yaml(dir / "mapping.yaml");
    yaml << "odometry_increment_covariance: true\n";
  }
  EXPECT_TRUE(qs::loadSlamParams(dir.string()).odometry_increment_covariance);
  {
    std::ofstream yaml(dir / "mapping.yaml");
    yaml << "odometry_increment_covariance: 3.5\n";  // not a bool
  }
  EXPECT_THROW(qs::loadSlamParams(dir.string()), std::invalid_argument);
  {
    std::ofstream yaml(dir / "odometry.yaml");
    yaml << "increment_covariance_scale: -1\n";
  }
  std::filesystem::remove(dir / "mapping.yaml");
  try {
    qs::loadSlamParams(dir.string());
    ADD_FAILURE() << "a negative increment_covariance_scale was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("increment_covariance_scale"), std::string::npos)
        << e.what();
  }
  std::filesystem::remove_all(dir);
}
