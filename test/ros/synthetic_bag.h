// Shared by the rostest checkers: a short synthetic TUM rosbag of config/scenes/desk.yaml made by
// the project's generator (the scene's seeded hand-held motion), and its depth frames read back
// in the order a player would send them.
#pragma once

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <cstdint>
#include <string>
#include <vector>

#include "quadric_slam/ros/tum_bag_writer.h"
#include "quadric_slam/sim/renderer.h"
#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/sequence_generator.h"
#include "quadric_slam/sim/surfaces.h"
#include "quadric_slam/sim/trajectory.h"

namespace quadric_slam::test {

struct SyntheticBag {
  Scene scene;
  Trajectory truth;  // the camera's optical frame in the scene's world, one pose per frame
};

// Renders `seconds` of the desk scene at `rate` Hz (hand-held motion and depth noise from
// `seed`) into a TUM-layout bag at bag_path. The depth model defaults to the independent-noise
// `nguyen` preset, not the scene's harsh default: these rostests check the nodelets' plumbing
// and trajectory/map accuracy within tight tolerances, not the segmenter's robustness to the
// sensor (that is measured by eval_segmentation on harsh sequences).
inline SyntheticBag writeDeskBag(const std::string& bag_path, double rate, double seconds,
                                 std::uint64_t seed, const std::string& depth_model = "nguyen") {
  SyntheticBag out;
  out.scene = readSceneYaml(std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/desk.yaml");
  KinectDepthModel::applyModel(depth_model, &out.scene.depth);
  out.truth = HandheldTrajectory(out.scene.handheld)
                  .generate(out.scene.centre_of_interest, rate, seconds, seed);
  const Renderer renderer(buildSurfaces(out.scene), out.scene.camera, out.scene.depth, {},
                          out.scene.background);
  TumBagWriter bag(bag_path, out.scene.camera, {});
  SequenceGenerator(renderer, {})
      .run(
          out.truth, [](std::size_t, const StampedPose&, const RenderedFrame&) {},
          [&](std::size_t, const StampedPose& pose, const RenderedFrame& frame) {
            bag.write(pose, frame);
          });
  bag.close();
  return out;
}

struct BagDepthFrames {
  sensor_msgs::CameraInfoConstPtr info;  // the first depth camera_info
  std::vector<sensor_msgs::ImageConstPtr> depths;
};

// The depth images and the depth camera_info of a TUM-layout bag.
inline BagDepthFrames readBagDepthFrames(const std::string& bag_path) {
  BagDepthFrames out;
  rosbag::Bag reader(bag_path, rosbag::bagmode::Read);
  rosbag::View view(reader, rosbag::TopicQuery(std::vector<std::string>{
                                "/camera/depth/image", "/camera/depth/camera_info"}));
  for (const rosbag::MessageInstance& m : view) {
    if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      if (!out.info)
        out.info = info;
    } else if (auto depth = m.instantiate<sensor_msgs::Image>()) {
      out.depths.push_back(depth);
    }
  }
  return out;
}

}  // namespace quadric_slam::test
