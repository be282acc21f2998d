// Configuration profiles (config/profiles/NAME): files holding only the keys they change, loaded
// over config/*.yaml by loadSlamParams (run_bag --profile) as the launch files' `profile` argument
// loads them over the nodelets' parameters.
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include "quadric_slam/io/param_reader.h"
#include "quadric_slam/pipeline/quadric_slam.h"

namespace qs = quadric_slam;
namespace fs = std::filesystem;

namespace {

const std::string kConfigDir = std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config";

}  // namespace

TEST(ConfigProfiles, OverridesReplaceAndAddKeysAndKeepTheRest) {
  const qs::YamlParamReader base(YAML::Load("{a: 1, b: 2.5, name: base}"));
  const qs::YamlParamReader merged =
      base.withOverrides(qs::YamlParamReader(YAML::Load("{b: 7.0, c: true}")));
  int a = 0;
  double b = 0.0;
  bool c = false;
  std::string name;
  EXPECT_TRUE(merged.get("a", a));
  EXPECT_TRUE(merged.get("b", b));
  EXPECT_TRUE(merged.get("c", c));
  EXPECT_TRUE(merged.get("name", name));
  EXPECT_EQ(a, 1);
  EXPECT_DOUBLE_EQ(b, 7.0);
  EXPECT_TRUE(c);
  EXPECT_EQ(name, "base");
  // The base itself is unchanged.
  EXPECT_TRUE(base.get("b", b));
  EXPECT_DOUBLE_EQ(b, 2.5);
  // An empty profile file changes nothing; a list is not a profile.
  EXPECT_TRUE(base.withOverrides(qs::YamlParamReader(YAML::Node())).get("a", a));
  EXPECT_EQ(a, 1);
  EXPECT_THROW(base.withOverrides(qs::YamlParamReader(YAML::Load("[1, 2]"))), std::runtime_error);
}

TEST(ConfigProfiles, ProfileNamesResolveUnderTheConfigDirectory) {
  EXPECT_EQ(qs::profileDirectory("/c", "qvga"), "/c/profiles/qvga");
  EXPECT_EQ(qs::profileDirectory("/c", "/elsewhere/mine"), "/elsewhere/mine");
  EXPECT_EQ(qs::profileDirectory("/c", ""), "");
  EXPECT_THROW(qs::loadSlamParams(kConfigDir, nullptr, kConfigDir + "/profiles/no_such_profile"),
               std::runtime_error);
}

// A key a profile misspells would silently change nothing: every key of every shipped profile
// file must be a key of the file it overrides.
TEST(ConfigProfiles, ShippedProfilesOnlyOverrideKnownKeys) {
  int files = 0;
  for (const auto& profile : fs::directory_iterator(kConfigDir + "/profiles")) {
    for (const auto& file : fs::directory_iterator(profile.path())) {
      const std::string name = file.path().filename().string();
      ASSERT_TRUE(fs::exists(kConfigDir + "/" + name))
          << file.path() << " overrides no file of config/";
      const YAML::Node base = YAML::LoadFile(kConfigDir + "/" + name);
      const YAML::Node overrides = YAML::LoadFile(file.path().string());
      ASSERT_TRUE(overrides.IsMap()) << file.path();
      for (const auto& entry : overrides)
        EXPECT_TRUE(base[entry.first.as<std::string>()])
            << file.path() << ": key '" << entry.first.as<std::string>() << "' is not in config/"
            << name;
      ++files;
    }
  }
  EXPECT_GE(files, 4);
}

// The qvga profile: a 320x240 cloud, segmented without a second decimation, with the point counts
// and strides of the default's coarse grid; everything it does not name stays as config/ says.
TEST(ConfigProfiles, QvgaProfileScalesTheFrontEndAndLeavesTheRest) {
  const qs::SlamParams base = qs::loadSlamParams(kConfigDir);
  const qs::SlamParams qvga =
      qs::loadSlamParams(kConfigDir, nullptr, qs::profileDirectory(kConfigDir, "qvga"));
  EXPECT_EQ(base.back_projection.decimation, 1);
  EXPECT_EQ(qvga.back_projection.decimation, 2);
  EXPECT_EQ(base.segmentation.decimation, 2);
  EXPECT_EQ(qvga.segmentation.decimation, 1);
  EXPECT_EQ(qvga.segmentation.planes.min_points * 4, base.segmentation.planes.min_points);
  EXPECT_EQ(qvga.segmentation.planes.cell_size * 2, base.segmentation.planes.cell_size);
  EXPECT_DOUBLE_EQ(qvga.segmentation.planes.correlated_points * 4,
                   base.segmentation.planes.correlated_points);
  EXPECT_EQ(qvga.odometry.icp.finest_stride * 2, base.odometry.icp.finest_stride);
  EXPECT_EQ(qvga.recovery.relocaliser.min_plane_points * 4,
            base.recovery.relocaliser.min_plane_points);
  // Keys the profile does not name.
  EXPECT_DOUBLE_EQ(qvga.segmentation.max_range, base.segmentation.max_range);
  EXPECT_DOUBLE_EQ(qvga.segmentation.cgal_epsilon, base.segmentation.cgal_epsilon);
  EXPECT_DOUBLE_EQ(qvga.mapping.keyframe_translation, base.mapping.keyframe_translation);
  EXPECT_EQ(qvga.max_support_points, base.max_support_points);
}
