// QuadricSlam with a depth correction (SlamParams::depth_correction, frontend/depth_correction.h):
// every frame's points are moved along their rays to the corrected depth before the normals, and a
// correction made for another image size is the frame's problem, not a crash.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "quadric_slam/pipeline/quadric_slam.h"
#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/synthetic_frame_source.h"

namespace qs = quadric_slam;

namespace {

const std::string kConfigDir = std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config";

qs::RgbdFrame deskFrame() {
  qs::SyntheticFrameSource::Params params;
  params.seconds = 0.2;
  params.rate = 10.0;
  params.rgb = false;
  qs::SyntheticFrameSource source(qs::readSceneYaml(kConfigDir + "/scenes/desk.yaml"), params);
  qs::RgbdFrame frame;
  EXPECT_TRUE(source.next(frame));
  frame.depth_m = frame.depth_m.clone();
  return frame;
}

}  // namespace

TEST(QuadricSlamDepthCorrection, PointsMoveToTheCorrectedDepthBeforeTheNormals) {
  const qs::RgbdFrame frame = deskFrame();
  qs::SlamParams params = qs::loadSlamParams(kConfigDir);
  params.mapping_enabled = false;
  const qs::QuadricSlam plain(params);
  qs::FrontEndFrame uncorrected;
  plain.frontEnd(frame, &uncorrected);
  ASSERT_TRUE(uncorrected.problem.empty()) << uncorrected.problem;

  // Offsets growing left to right and top to bottom (a bowl would do as well: any offsets apply).
  const int cols = 5, rows = 4;
  std::vector<double> offsets;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      offsets.push_back(0.1 * (c * c + r) / (cols * cols));
  const double focal_baseline = frame.intrinsics.fx * 0.075;
  params.depth_correction = qs::DepthCorrection(frame.intrinsics.width, frame.intrinsics.height,
                                                cols, rows, offsets, focal_baseline);
  const qs::QuadricSlam corrected_slam(params);
  qs::FrontEndFrame corrected;
  corrected_slam.frontEnd(frame, &corrected);
  ASSERT_TRUE(corrected.problem.empty()) << corrected.problem;
  int compared = 0;
  for (int v = 0; v < static_cast<int>(corrected.cloud.height); v += 37) {
    for (int u = 0; u < static_cast<int>(corrected.cloud.width); u += 41) {
      const pcl::PointNormal& a = uncorrected.cloud(u, v);
      const pcl::PointNormal& b = corrected.cloud(u, v);
      if (!std::isfinite(a.z)) {
        EXPECT_FALSE(std::isfinite(b.z));
        continue;
      }
      const double expected =
          focal_baseline / (focal_baseline / a.z + params.depth_correction.offsetAt(u, v));
      EXPECT_NEAR(b.z, expected, 1e-5 * a.z) << "pixel " << u << ", " << v;
      EXPECT_NEAR(b.x / b.z, a.x / a.z, 1e-6);  // along the ray
      ++compared;
    }
  }
  EXPECT_GT(compared, 50);

  // A correction for another image size: the frame is not used, and says why.
  params.depth_correction = qs::DepthCorrection(320, 240, cols, rows, offsets, focal_baseline);
  const qs::QuadricSlam wrong_size(params);
  qs::FrontEndFrame refused;
  wrong_size.frontEnd(frame, &refused);
  EXPECT_NE(refused.problem.find("depth correction"), std::string::npos) << refused.problem;
}
