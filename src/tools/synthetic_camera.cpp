// synthetic_camera: a live depth camera made of the simulator. It renders a scene
// (config/scenes/*.yaml) along its seeded hand-held motion and publishes each frame when its time
// comes, stamped with the wall clock, as a TUM-layout camera would: a 32FC1 depth image (metres,
// NaN = no data) and its camera_info. For long runs of the live pipeline without a bag of that
// length on disk (scripts/long_run): 20 minutes at 10 Hz would be a 7 GB bag.
//
//   rosrun quadric_slam synthetic_camera _scene:=FILE _rate:=10 _seconds:=1200
//
// Private parameters:
//   ~scene        scene YAML; default config/scenes/desk.yaml of the package
//   ~rate         frames per second (Hz); default 10. A frame that is late (rendering slower than
//                 the rate) is published late, never skipped: the sequence stays the same.
//   ~seconds      length of the motion (s); default 60. The node exits after the last frame.
//   ~seed         seed of the depth noise and the motion; default 1
//   ~frame_id     frame id of the images; default openni_rgb_optical_frame
//   ~groundtruth  a file for the camera poses in TUM format with the published stamps (optional)
// Topics (relative, remap them): camera/depth/image, camera/depth/camera_info.
#include <cv_bridge/cv_bridge.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>

#include <cstdio>
#include <exception>
#include <string>

#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/ros/tum_bag_writer.h"
#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/synthetic_frame_source.h"

namespace qs = quadric_slam;

int main(int argc, char** argv) {
  ros::init(argc, argv, "synthetic_camera");
  ros::NodeHandle nh, private_nh("~");
  std::string scene_path = std::string(QUADRIC_SLAM_CONFIG_DIR) + "/scenes/desk.yaml";
  std::string frame_id = "openni_rgb_optical_frame", groundtruth_path;
  double rate = 10.0, seconds = 60.0;
  int seed = 1;
  private_nh.param("scene", scene_path, scene_path);
  private_nh.param("rate", rate, rate);
  private_nh.param("seconds", seconds, seconds);
  private_nh.param("seed", seed, seed);
  private_nh.param("frame_id", frame_id, frame_id);
  private_nh.param("groundtruth", groundtruth_path, groundtruth_path);
  try {
    if (seed < 0)
      throw std::invalid_argument("~seed must be >= 0");
    qs::SyntheticFrameSource::Params params;
    params.rate = rate;
    params.seconds = seconds;
    params.seed = static_cast<std::uint64_t>(seed);
    params.rgb = false;
    qs::SyntheticFrameSource source(qs::readSceneYaml(scene_path), params);

    ros::Publisher depth_pub = nh.advertise<sensor_msgs::Image>("camera/depth/image", 5);
    ros::Publisher info_pub = nh.advertise<sensor_msgs::CameraInfo>("camera/depth/camera_info", 5);
    ROS_INFO("synthetic_camera: %s, %zu frames at %.1f Hz (%.0f s)", scene_path.c_str(),
             source.size(), rate, seconds);

    qs::Trajectory published;  // ground truth with the published stamps
    const ros::WallTime start = ros::WallTime::now();
    qs::RgbdFrame frame;
    std::size_t index = 0;
    while (ros::ok() && source.next(frame)) {
      // Frame k is due k / rate after the start; rendering happens before its time comes.
      const ros::WallTime due = start + ros::WallDuration(index / rate);
      const ros::WallDuration wait = due - ros::WallTime::now();
      if (wait > ros::WallDuration(0))
        wait.sleep();
      std_msgs::Header header;
      header.stamp = ros::Time::now();
      header.frame_id = frame_id;
      sensor_msgs::CameraInfo info = qs::TumBagWriter::cameraInfo(frame.intrinsics);
      info.header = header;
      depth_pub.publish(
          cv_bridge::CvImage(header, sensor_msgs::image_encodings::TYPE_32FC1, frame.depth_m)
              .toImageMsg());
      info_pub.publish(info);
      if (!groundtruth_path.empty())
        published.push_back({header.stamp.toSec(), source.groundTruth()[index].T_world_sensor});
      ++index;
      ros::spinOnce();
    }
    if (!groundtruth_path.empty())
      qs::writeTumTrajectory(published, groundtruth_path,
                             "quadric_slam synthetic_camera: camera poses at the published stamps");
    std::printf("synthetic_camera: published %zu frames in %.1f s\n", index,
                (ros::WallTime::now() - start).toSec());
  } catch (const std::exception& e) {
    ROS_FATAL("synthetic_camera: %s", e.what());
    return 1;
  }
  return 0;
}
