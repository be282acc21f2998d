// The mapping nodelet's saved maps (ros/map_files.h) and reconstruction cloud
// (ros/reconstruction_cloud.h), without a master: a map of every class goes through the YAML and
// PCD files and comes back with the same ids, classes, poses, scales and counts, extents from the
// PCD points (or the YAML's); what cannot be loaded is refused with a message naming the file; the
// cloud has the documented fields and the landmarks' marker colours.
#include <gtest/gtest.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <typeinfo>

#include "../fuzz_mutations.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/geometry/surface_distance.h"
#include "quadric_slam/ros/map_files.h"
#include "quadric_slam/ros/markers.h"
#include "quadric_slam/ros/reconstruction_cloud.h"

namespace qs = quadric_slam;
namespace fs = std::filesystem;

namespace {

qs::QuadricLandmark landmark(int id, const qs::QuadricModel& quadric, int observations) {
  qs::QuadricLandmark l;
  l.id = id;
  l.quadric_map = quadric;
  l.observations = observations;
  l.covariance = Eigen::MatrixXd::Identity(qs::minimalDimension(quadric.quadricClass()),
                                           qs::minimalDimension(quadric.quadricClass()));
  return l;
}

std::vector<qs::QuadricLandmark> everyClass() {
  const Eigen::Isometry3d ellipsoid_pose(Eigen::Translation3d(0.5, 0.2, 1.0) *
                                         Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  return {
      landmark(3, qs::quadricFromShape(qs::PlaneShape{Eigen::Vector3d(0, 0, 1), 0.7}), 12),
      landmark(5, qs::quadricFromShape(qs::SphereShape{Eigen::Vector3d(0, 1, 0.85), 0.15}), 7),
      landmark(8,
               qs::quadricFromShape(qs::CylinderShape{Eigen::Vector3d(0.4, 0.5, 0.74),
                                                      Eigen::Vector3d(1, 0.3, 0), 0.04}),
               9),
      landmark(9,
               qs::quadricFromShape(qs::ConeShape{Eigen::Vector3d(0.75, 1.05, 1.25),
                                                  Eigen::Vector3d(0, 0, -1), 0.45}),
               5),
      landmark(11,
               qs::QuadricModel(qs::QuadricClass::kGeneral, ellipsoid_pose,
                                Eigen::Vector3d(1 / 0.13, 1 / 0.08, 1 / 0.07),
                                Eigen::Vector4d(1, 1, 1, -1)),
               6),
  };
}

// Points on each landmark's surface (projected from a small grid around its origin), label = id.
pcl::PointCloud<pcl::PointXYZRGBL> surfacePoints(
    const std::vector<qs::QuadricLandmark>& landmarks) {
  pcl::PointCloud<pcl::PointXYZRGBL> cloud;
  const qs::SurfaceProjector projector;
  for (const qs::QuadricLandmark& l : landmarks) {
    for (int i = -2; i <= 2; ++i)
      for (int j = -2; j <= 2; ++j) {
        const Eigen::Vector3d near_q(0.05 * i, 0.05 * j, 0.1 + 0.02 * (i + j));
        const Eigen::Vector3d p = projector.project(l.quadric_map, l.quadric_map.pose() * near_q);
        pcl::PointXYZRGBL point;
        point.rgba = 0;  // uncoloured: the landmark's colour
        point.x = static_cast<float>(p.x());
        point.y = static_cast<float>(p.y());
        point.z = static_cast<float>(p.z());
        point.label = static_cast<std::uint32_t>(l.id);
        cloud.push_back(point);
      }
  }
  return cloud;
}

class MapFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / "map_files_test";
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(MapFilesTest, ReconstructionPathBesideTheMap) {
  EXPECT_EQ(qs::reconstructionPathFor("/a/b/desk.yaml"), "/a/b/desk.pcd");
  EXPECT_EQ(qs::reconstructionPathFor("/a/b/desk"), "/a/b/desk.pcd");
  EXPECT_EQ(qs::reconstructionPathFor("map.v2.yaml"), "map.v2.pcd");
}

TEST_F(MapFilesTest, SaveAndLoadGiveTheSameLandmarksWithExtentsFromThePoints) {
  const std::vector<qs::QuadricLandmark> landmarks = everyClass();
  const pcl::PointCloud<pcl::PointXYZRGBL> points = surfacePoints(landmarks);
  std_msgs::Header header;
  header.frame_id = "map";
  const std::string path = (dir_ / "maps" / "desk.yaml").string();  // the directory is created
  qs::saveMapFiles(path, landmarks, "map", qs::reconstructionCloudMsg(points, header));
  ASSERT_TRUE(fs::exists(path));
  ASSERT_TRUE(fs::exists(dir_ / "maps" / "desk.pcd"));

  const qs::LoadedMap loaded = qs::loadMapFiles(path);
  EXPECT_EQ(loaded.frame_id, "map");
  EXPECT_EQ(loaded.reconstruction_path, (dir_ / "maps" / "desk.pcd").string());
  EXPECT_EQ(loaded.reconstruction.size(), points.size());
  ASSERT_EQ(loaded.landmarks.size(), landmarks.size());
  for (std::size_t i = 0; i < landmarks.size(); ++i) {
    const qs::QuadricLandmark &a = landmarks[i], &b = loaded.landmarks[i];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.observations, b.observations);
    EXPECT_EQ(a.quadric_map.quadricClass(), b.quadric_map.quadricClass()) << a.id;
    EXPECT_EQ(a.quadric_map.signature(), b.quadric_map.signature()) << a.id;
    EXPECT_TRUE(a.quadric_map.pose().isApprox(b.quadric_map.pose(), 1e-7)) << a.id;
    EXPECT_TRUE(a.quadric_map.scale().isApprox(b.quadric_map.scale(), 1e-7)) << a.id;
    EXPECT_EQ(b.covariance.size(), 0) << "covariances are not saved";
    // The extent is the box of the landmark's points in its quadric frame.
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
    for (const pcl::PointXYZRGBL& p : points) {
      if (static_cast<int>(p.label) != a.id)
        continue;
      const Eigen::Vector3d q = a.quadric_map.pose().inverse() * Eigen::Vector3d(p.x, p.y, p.z);
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
    EXPECT_LT((b.extent_min - lo).norm(), 1e-5) << a.id;
    EXPECT_LT((b.extent_max - hi).norm(), 1e-5) << a.id;
  }

  // Without the PCD: the same landmarks, extents unknown, no reconstruction.
  fs::remove(dir_ / "maps" / "desk.pcd");
  const qs::LoadedMap bare = qs::loadMapFiles(path);
  EXPECT_EQ(bare.landmarks.size(), landmarks.size());
  EXPECT_TRUE(bare.reconstruction_path.empty());
  EXPECT_TRUE(bare.reconstruction.empty());
  for (const qs::QuadricLandmark& l : bare.landmarks)
    EXPECT_TRUE(l.extent_min.isZero() && l.extent_max.isZero()) << l.id;

  // Landmarks that know their extent write it into the YAML: without the PCD they keep it.
  std::vector<qs::QuadricLandmark> bounded = landmarks;
  bounded[0].extent_min = Eigen::Vector3d(-0.01, -0.6, -0.4);
  bounded[0].extent_max = Eigen::Vector3d(0.01, 0.6, 0.4);
  qs::saveMapFiles(path, bounded, "map", qs::reconstructionCloudMsg({}, header));
  const qs::LoadedMap yaml_only = qs::loadMapFiles(path);
  EXPECT_TRUE(yaml_only.landmarks[0].extent_min.isApprox(bounded[0].extent_min, 1e-9));
  EXPECT_TRUE(yaml_only.landmarks[0].extent_max.isApprox(bounded[0].extent_max, 1e-9));
  EXPECT_TRUE(yaml_only.landmarks[1].extent_max.isZero()) << "unknown stays unknown";

  // An empty reconstruction writes no PCD (and removes a stale one).
  qs::saveMapFiles(path, landmarks, "map", qs::reconstructionCloudMsg(points, header));
  ASSERT_TRUE(fs::exists(dir_ / "maps" / "desk.pcd"));
  qs::saveMapFiles(path, landmarks, "map", qs::reconstructionCloudMsg({}, header));
  EXPECT_FALSE(fs::exists(dir_ / "maps" / "desk.pcd"));
}

TEST_F(MapFilesTest, WhatCannotBeLoadedIsRefusedNamingTheFile) {
  fs::create_directories(dir_);
  const std::string missing = (dir_ / "missing.yaml").string();
  try {
    qs::loadMapFiles(missing);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  // A general quadric: the schema does not hold its signature.
  const std::string general = (dir_ / "general.yaml").string();
  std::ofstream(general) << "frame_id: map\nquadrics:\n  - id: 4\n    class: general\n"
                            "    pose: {position: [0, 0, 0], orientation: [0, 0, 0, 1]}\n"
                            "    scale: [1, 2, 3]\n";
  try {
    qs::loadMapFiles(general);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("quadric 4"), std::string::npos) << e.what();
  }
  // The same id twice.
  const std::string twice = (dir_ / "twice.yaml").string();
  std::ofstream(twice) << "quadrics:\n"
                          "  - {id: 2, class: sphere, pose: {position: [0, 0, 0], orientation: "
                          "[0, 0, 0, 1]}, scale: [2, 2, 2]}\n"
                          "  - {id: 2, class: sphere, pose: {position: [1, 0, 0], orientation: "
                          "[0, 0, 0, 1]}, scale: [2, 2, 2]}\n";
  EXPECT_THROW(qs::loadMapFiles(twice), std::runtime_error);
  // A PCD without labels beside a good map.
  const std::string good = (dir_ / "good.yaml").string();
  std_msgs::Header header;
  qs::saveMapFiles(good, everyClass(), "map", qs::reconstructionCloudMsg({}, header));
  std::ofstream(dir_ / "good.pcd") << "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
                                      "COUNT 1 1 1\nWIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
                                      "POINTS 1\nDATA ascii\n0 0 0\n";
  EXPECT_THROW(qs::loadMapFiles(good), std::runtime_error);
}

std::string fileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

// Seeded fuzzing of a saved map (issue 14): the YAML and the binary PCD beside it, mutated a few
// bytes at a time. Every case must either be refused with std::runtime_error (the documented
// error) or load landmarks the mapper can use: finite poses, positive finite scales, ids >= 1,
// reconstruction points with finite coordinates and a known label. No other exception, no crash.
TEST_F(MapFilesTest, FuzzedMapFilesAreRefusedOrLoadValidLandmarks) {
  const std::vector<qs::QuadricLandmark> landmarks = everyClass();
  std_msgs::Header header;
  header.frame_id = "map";
  const fs::path original = dir_ / "original.yaml";
  qs::saveMapFiles(original.string(), landmarks, "map",
                   qs::reconstructionCloudMsg(surfacePoints(landmarks), header));
  const std::string yaml = fileBytes(original), pcd = fileBytes(dir_ / "original.pcd");
  ASSERT_FALSE(yaml.empty());
  ASSERT_FALSE(pcd.empty());

  const int kCases = qs::test::fuzzCases(1500);
  int refused = 0, loaded_cases = 0;
  std::map<std::string, int> reasons;
  qs::test::FuzzMutator mutator(20261201);
  for (int k = 0; k < kCases; ++k) {
    // Two cases in three mutate the YAML, one in three the PCD (with the original YAML).
    const bool mutate_yaml = k % 3 != 2;
    const fs::path path = dir_ / ("case" + std::to_string(k) + ".yaml");
    std::ofstream(path, std::ios::binary) << (mutate_yaml ? mutator.mutate(yaml) : yaml);
    std::ofstream(dir_ / ("case" + std::to_string(k) + ".pcd"), std::ios::binary)
        << (mutate_yaml ? pcd : mutator.mutate(pcd));
    try {
      const qs::LoadedMap map = qs::loadMapFiles(path.string());
      ++loaded_cases;
      std::set<int> ids;
      for (const qs::QuadricLandmark& l : map.landmarks) {
        ids.insert(l.id);
        EXPECT_GE(l.id, 1) << "case " << k;
        EXPECT_TRUE(l.quadric_map.pose().matrix().allFinite()) << "case " << k;
        EXPECT_TRUE(l.quadric_map.scale().allFinite() && (l.quadric_map.scale().array() > 0).all())
            << "case " << k << ": scale " << l.quadric_map.scale().transpose();
      }
      for (const auto& p : map.reconstruction) {
        EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) << "case " << k;
        EXPECT_TRUE(ids.count(static_cast<int>(p.label))) << "case " << k;
      }
    } catch (const std::runtime_error& e) {
      ++refused;
      const std::string what = e.what();
      ++reasons[what.substr(
          0, std::min<std::size_t>(what.find(':') == std::string::npos ? 40 : what.find(':'), 40))];
    } catch (const std::exception& e) {
      ADD_FAILURE() << "case " << k << ": " << typeid(e).name() << ": " << e.what();
    }
    fs::remove(path);
    fs::remove(dir_ / ("case" + std::to_string(k) + ".pcd"));
  }
  std::printf("fuzzed map files: %d cases, %d loaded, %d refused with std::runtime_error\n", kCases,
              loaded_cases, refused);
  EXPECT_GT(refused, kCases / 10) << "the mutations hardly ever break the files";
  EXPECT_GT(loaded_cases, 0);
}

TEST(ReconstructionCloud, FieldsAndLandmarkColours) {
  pcl::PointCloud<pcl::PointXYZRGBL> points;
  for (std::uint32_t label : {3u, 3u, 7u}) {
    pcl::PointXYZRGBL p;
    p.rgba = 0;
    p.x = 0.1f * label;
    p.y = 0.2f;
    p.z = 1.5f;
    p.label = label;
    points.push_back(p);
  }
  std_msgs::Header header;
  header.frame_id = "map";
  header.stamp = ros::Time(3.5);
  const sensor_msgs::PointCloud2 msg = qs::reconstructionCloudMsg(points, header);
  EXPECT_EQ(msg.header.frame_id, "map");
  EXPECT_EQ(msg.header.stamp, ros::Time(3.5));
  EXPECT_EQ(msg.width, 3u);
  EXPECT_EQ(msg.height, 1u);
  EXPECT_TRUE(msg.is_dense);
  std::vector<std::string> names;
  for (const auto& f : msg.fields)
    names.push_back(f.name);
  EXPECT_EQ(names, (std::vector<std::string>{"x", "y", "z", "rgb", "label"}));
  sensor_msgs::PointCloud2ConstIterator<float> x(msg, "x"), rgb(msg, "rgb");
  sensor_msgs::PointCloud2ConstIterator<std::uint32_t> label(msg, "label");
  for (std::size_t i = 0; i < points.size(); ++i, ++x, ++rgb, ++label) {
    EXPECT_FLOAT_EQ(x[0], points[i].x);
    EXPECT_FLOAT_EQ(x[2], 1.5f);
    EXPECT_EQ(*label, points[i].label);
    std::uint32_t bits;
    const float packed = *rgb;
    std::memcpy(&bits, &packed, sizeof(bits));
    const std_msgs::ColorRGBA c = qs::landmarkColour(static_cast<int>(points[i].label), 1.0);
    EXPECT_NEAR(((bits >> 16) & 0xff) / 255.0, c.r, 0.003);
    EXPECT_NEAR(((bits >> 8) & 0xff) / 255.0, c.g, 0.003);
    EXPECT_NEAR((bits & 0xff) / 255.0, c.b, 0.003);
  }
  EXPECT_EQ(qs::reconstructionCloudMsg({}, header).width, 0u);
}

// A point with a colour from the RGB image keeps it (alpha 255), beside an uncoloured point of the
// same landmark drawn in the landmark's colour (alpha 0); both survive a save and a load.
TEST_F(MapFilesTest, RgbColoursSurviveTheMessageAndTheFiles) {
  const std::vector<qs::QuadricLandmark> landmarks = everyClass();
  pcl::PointCloud<pcl::PointXYZRGBL> points = surfacePoints(landmarks);
  ASSERT_GE(points.size(), 2u);
  points[0].rgba = 0xFF123456u;  // coloured; points[1] stays uncoloured
  ASSERT_EQ(points[1].rgba, 0u);
  std_msgs::Header header;
  header.frame_id = "map";
  const sensor_msgs::PointCloud2 msg = qs::reconstructionCloudMsg(points, header);
  sensor_msgs::PointCloud2ConstIterator<std::uint32_t> rgb(msg, "rgb");
  EXPECT_EQ(rgb[0], 0xFF123456u);
  const std_msgs::ColorRGBA c = qs::landmarkColour(static_cast<int>(points[1].label), 1.0);
  const std::uint32_t landmark_bits = (*(rgb + 1));
  EXPECT_EQ(landmark_bits >> 24, 0u);
  EXPECT_NEAR(((landmark_bits >> 16) & 0xff) / 255.0, c.r, 0.003);

  const std::string path = (dir_ / "rgb.yaml").string();
  qs::saveMapFiles(path, landmarks, "map", msg);
  const qs::LoadedMap loaded = qs::loadMapFiles(path);
  ASSERT_EQ(loaded.reconstruction.size(), points.size());
  EXPECT_EQ(loaded.reconstruction[0].rgba, 0xFF123456u);
  EXPECT_EQ(loaded.reconstruction[1].rgba >> 24, 0u);
}

}  // namespace
