// Test support: the real 7-Scenes kitchen (../shared/data/7scenes_redkitchen, research use only;
// 585 px focal length, depth only) tracked by runTracker, every `every`-th frame up to max_frames.
#pragma once

#include <string>

#include "../test_data.h"
#include "quadric_slam/io/tum_folder_reader.h"
#include "tracking_run.h"

namespace quadric_slam {
namespace test {

inline const std::string kKitchen = "7scenes_redkitchen";

inline TrackingRun runKitchen(int every, int max_frames, const SlamParams& params) {
  TumFolderReader::Params reader;
  reader.load_rgb = false;
  reader.keep_frames_without_rgb = true;
  reader.intrinsics.fx = 585;
  reader.intrinsics.fy = 585;
  reader.intrinsics.cx = 320;
  reader.intrinsics.cy = 240;
  TumFolderReader source(sharedData(kKitchen).string(), reader);
  const Trajectory truth = readTumTrajectory(sharedData(kKitchen + "/groundtruth.txt"));
  return runTracker(source, truth, params, every, max_frames);
}

}  // namespace test
}  // namespace quadric_slam
