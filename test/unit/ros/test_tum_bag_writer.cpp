#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "quadric_slam/io/tum_folder_reader.h"
#include "quadric_slam/ros/tum_bag_reader.h"
#include "quadric_slam/ros/tum_bag_writer.h"
#include "quadric_slam/sim/sequence_generator.h"
#include "quadric_slam/sim/surfaces.h"
#include "quadric_slam/sim/tum_folder_writer.h"

using namespace quadric_slam;

namespace {

Eigen::Isometry3d fromMsg(const geometry_msgs::Transform& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z);
  return T;
}

// A small scene (sphere on a plane), 8 hand-held frames at 30 Hz written as bag and folder.
class TumBagWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::TempDir() + "/tum_bag_writer_test";
    std::filesystem::remove_all(dir_);
    Scene scene;
    scene.camera = {262.5, 262.5, 159.5, 119.5, 320, 240};
    PrimitiveSpec ball;
    ball.name = "ball";
    ball.type = PrimitiveType::kSphere;
    ball.radius = 0.2;
    ball.T_world_primitive.translation() = Eigen::Vector3d(0, 0, 0.9);
    scene.primitives.push_back(ball);
    PrimitiveSpec floor;
    floor.name = "floor";
    floor.type = PrimitiveType::kRectangle;
    floor.size = Eigen::Vector3d(0, 6, 6);
    floor.T_world_primitive.linear() =
        Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
    floor.T_world_primitive.translation() = Eigen::Vector3d(0, 0, 0.7);
    scene.primitives.push_back(floor);
    camera_ = scene.camera;
    poses_ = HandheldTrajectory({}).generate(Eigen::Vector3d(0, 0, 0.8), 30.0, 8.0 / 30.0, 3);
    ASSERT_EQ(poses_.size(), 8u);
    const Renderer renderer(buildSurfaces(scene), scene.camera, {}, {});
    TumFolderWriter::Params folder_params;
    folder_params.sequence_name = "unit";
    const TumFolderWriter folder(dir_, folder_params);
    TumBagWriter bag(dir_ + "/unit.bag", scene.camera, {});
    SequenceGenerator(renderer, {})
        .run(
            poses_,
            [&](std::size_t, const StampedPose& p, const RenderedFrame& f) {
              folder.writeFrame(p, f);
            },
            [&](std::size_t, const StampedPose& p, const RenderedFrame& f) {
              bag.write(p, f);
              depths_.push_back(f.depth.clone());
            });
    bag.close();
    folder.finish(poses_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string dir_;
  CameraIntrinsics camera_;
  std::vector<StampedPose> poses_;
  std::vector<cv::Mat> depths_;
};

}  // namespace

TEST_F(TumBagWriterTest, HasTumTopicsTypesAndFrameIds) {
  rosbag::Bag bag(dir_ + "/unit.bag", rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::map<std::string, std::string> types, md5s;
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    types[c->topic] = c->datatype;
    md5s[c->topic] = c->md5sum;
  }
  EXPECT_EQ(types["/camera/depth/image"], "sensor_msgs/Image");
  EXPECT_EQ(types["/camera/rgb/image_color"], "sensor_msgs/Image");
  EXPECT_EQ(types["/camera/depth/camera_info"], "sensor_msgs/CameraInfo");
  EXPECT_EQ(types["/camera/rgb/camera_info"], "sensor_msgs/CameraInfo");
  EXPECT_EQ(types["/tf"], "tf2_msgs/TFMessage");
  EXPECT_EQ(md5s["/tf"], "94810edda583a504dfda3829e70d7eec");  // = tf/tfMessage
  EXPECT_EQ(types.size(), 5u);
  std::map<std::string, int> counts;
  for (const rosbag::MessageInstance& m : view) {
    ++counts[m.getTopic()];
    if (auto image = m.instantiate<sensor_msgs::Image>()) {
      EXPECT_EQ(image->header.frame_id, "/openni_rgb_optical_frame");
      EXPECT_EQ(image->width, 320u);
      EXPECT_EQ(image->height, 240u);
      EXPECT_EQ(image->header.stamp, m.getTime());  // record time = stamp
      if (m.getTopic() == "/camera/depth/image") {
        EXPECT_EQ(image->encoding, "32FC1");
        EXPECT_EQ(image->step, 320u * 4);
      } else {
        EXPECT_EQ(image->encoding, "rgb8");
        EXPECT_EQ(image->step, 320u * 3);
      }
    }
    if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      EXPECT_EQ(info->header.frame_id, "/openni_rgb_optical_frame");
      EXPECT_EQ(info->distortion_model, "plumb_bob");
      EXPECT_EQ(info->K[0], 262.5);
      EXPECT_EQ(info->K[2], 159.5);
      EXPECT_EQ(info->K[5], 119.5);
      EXPECT_EQ(info->P[0], 262.5);
      EXPECT_EQ(info->P[3], 0.0);
      for (double d : info->D)
        EXPECT_EQ(d, 0.0);
    }
  }
  for (const char* topic : {"/camera/depth/image", "/camera/rgb/image_color",
                            "/camera/depth/camera_info", "/camera/rgb/camera_info", "/tf"})
    EXPECT_EQ(counts[topic], 8) << topic;
}

TEST_F(TumBagWriterTest, TfChainComposesToGroundTruthAndStampsAre30Hz) {
  const std::vector<StampedPose> gt = readTumTrajectory(dir_ + "/groundtruth.txt");
  ASSERT_EQ(gt.size(), 8u);
  rosbag::Bag bag(dir_ + "/unit.bag", rosbag::bagmode::Read);
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{"/tf"}));
  std::size_t k = 0;
  for (const rosbag::MessageInstance& m : view) {
    const auto tf = m.instantiate<tf2_msgs::TFMessage>();
    ASSERT_TRUE(tf);
    ASSERT_LT(k, gt.size());
    EXPECT_NEAR(m.getTime().toSec(), gt[k].stamp, 1e-6);
    EXPECT_NEAR(m.getTime().toSec(), gt[0].stamp + k / 30.0, 1e-6);
    // parent of each child, then walk from the optical frame up to /world.
    std::map<std::string, std::pair<std::string, Eigen::Isometry3d>> parent;
    for (const geometry_msgs::TransformStamped& t : tf->transforms) {
      EXPECT_EQ(t.header.stamp, m.getTime());
      parent[t.child_frame_id] = {t.header.frame_id, fromMsg(t.transform)};
    }
    ASSERT_EQ(parent.size(), 6u);
    EXPECT_EQ(parent["/kinect"].first, "/world");
    EXPECT_EQ(parent["/openni_depth_optical_frame"].first, "/openni_depth_frame");
    std::string frame = "/openni_rgb_optical_frame";
    Eigen::Isometry3d T_world_optical = Eigen::Isometry3d::Identity();
    int depth = 0;
    while (frame != "/world" && depth++ < 10) {
      ASSERT_TRUE(parent.count(frame)) << frame;
      T_world_optical = parent[frame].second * T_world_optical;
      frame = parent[frame].first;
    }
    EXPECT_EQ(frame, "/world");
    EXPECT_EQ(depth, 4);  // optical -> rgb_frame -> openni_camera -> kinect -> world
    EXPECT_NEAR((T_world_optical.translation() - gt[k].T_world_sensor.translation()).norm(), 0,
                1e-6);
    EXPECT_NEAR(
        Eigen::AngleAxisd(T_world_optical.linear().transpose() * gt[k].T_world_sensor.linear())
            .angle(),
        0, 1e-6);
    ++k;
  }
  EXPECT_EQ(k, 8u);
}

TEST_F(TumBagWriterTest, FolderMatchesTheBag) {
  std::ifstream depth_txt(dir_ + "/depth.txt");
  std::string line;
  std::vector<std::string> files;
  while (std::getline(depth_txt, line)) {
    if (line.empty() || line[0] == '#')
      continue;
    const auto space = line.find(' ');
    files.push_back(line.substr(space + 1));
    EXPECT_EQ(line.substr(0, space), TumFolderWriter::stampString(poses_[files.size() - 1].stamp));
  }
  ASSERT_EQ(files.size(), 8u);
  rosbag::Bag bag(dir_ + "/unit.bag", rosbag::bagmode::Read);
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{"/camera/depth/image"}));
  std::size_t k = 0;
  int valid = 0;
  for (const rosbag::MessageInstance& m : view) {
    const auto image = m.instantiate<sensor_msgs::Image>();
    ASSERT_TRUE(image);
    const cv::Mat png = cv::imread(dir_ + "/" + files[k], cv::IMREAD_UNCHANGED);
    ASSERT_EQ(png.type(), CV_16UC1) << files[k];
    const cv::Mat labels = cv::imread(dir_ + "/labels/" + files[k].substr(6), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(labels.type(), CV_16UC1);
    for (int v = 0; v < png.rows; v += 2)
      for (int u = 0; u < png.cols; u += 2) {
        float z;
        std::memcpy(&z, &image->data[v * image->step + u * 4], 4);
        const std::uint16_t units = png.at<std::uint16_t>(v, u);
        EXPECT_EQ(std::isnan(z), units == 0);
        EXPECT_EQ(std::isnan(z), labels.at<std::uint16_t>(v, u) == 0);
        if (!std::isnan(z)) {
          EXPECT_NEAR(units / 5000.0, z, 0.5 / 5000 + 1e-6);
          ++valid;
        }
      }
    ++k;
  }
  EXPECT_EQ(k, 8u);
  EXPECT_GT(valid, 8 * 160 * 120 / 2);
}

// The round trip users rely on: what the generator writes, our readers give back unchanged.
TEST_F(TumBagWriterTest, ReadBackByTheReadersGivesTheSameFrames) {
  auto expectSameDepth = [](const cv::Mat& read, const cv::Mat& written, double tolerance) {
    ASSERT_EQ(read.size(), written.size());
    int valid = 0;
    for (int v = 0; v < read.rows; ++v) {
      for (int u = 0; u < read.cols; ++u) {
        const float a = read.at<float>(v, u), b = written.at<float>(v, u);
        ASSERT_EQ(std::isnan(a), std::isnan(b) || b == 0.0f) << u << ", " << v;
        if (std::isnan(a))
          continue;
        ++valid;
        ASSERT_NEAR(a, b, tolerance) << u << ", " << v;
      }
    }
    EXPECT_GT(valid, read.rows * read.cols / 2);
  };

  TumBagReader bag(dir_ + "/unit.bag");
  ASSERT_EQ(bag.size(), poses_.size());
  RgbdFrame frame;
  for (std::size_t k = 0; k < poses_.size(); ++k) {
    SCOPED_TRACE("bag frame " + std::to_string(k));
    ASSERT_TRUE(bag.next(frame));
    EXPECT_NEAR(frame.stamp, poses_[k].stamp, 1e-6);
    EXPECT_EQ(frame.intrinsics.fx, camera_.fx);
    EXPECT_EQ(frame.intrinsics.cy, camera_.cy);
    EXPECT_EQ(frame.intrinsics.width, camera_.width);
    EXPECT_FALSE(frame.rgb.empty());
    expectSameDepth(frame.depth_m, depths_[k], 0.0);  // 32FC1: bit-exact
  }
  EXPECT_FALSE(bag.next(frame));

  TumFolderReader::Params folder_params;
  folder_params.intrinsics = camera_;  // a synthetic folder has no Freiburg name to go by
  TumFolderReader folder(dir_, folder_params);
  ASSERT_EQ(folder.size(), poses_.size());
  EXPECT_EQ(folder.groundtruth().size(), poses_.size());
  for (std::size_t k = 0; k < poses_.size(); ++k) {
    SCOPED_TRACE("folder frame " + std::to_string(k));
    ASSERT_TRUE(folder.next(frame));
    EXPECT_NEAR(frame.stamp, poses_[k].stamp, 1e-6);
    expectSameDepth(frame.depth_m, depths_[k], 0.5 / 5000.0 + 1e-6);  // 16-bit PNG, 5000 per m
  }
}
