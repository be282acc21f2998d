// The segmenter's parameter table: config/segmentation.yaml holds every key with the code's
// defaults, values round-trip through the table, and bad files/keys are reported.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <set>
#include <string>

#include "quadric_slam/pipeline/segmenter_params.h"

namespace qs = quadric_slam;

TEST(SegmenterParams, ConfigFileHasEveryKeyWithTheCodeDefaults) {
  const std::string path = std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/segmentation.yaml";
  const qs::QuadricSegmenter::Params from_file = qs::loadSegmenterParams(path);
  const qs::QuadricSegmenter::Params defaults;
  std::ifstream in(path);
  std::set<std::string> keys;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#' && line.find(':') != std::string::npos)
      keys.insert(line.substr(0, line.find(':')));
  for (const std::string& name : qs::segmenterParamNames()) {
    EXPECT_TRUE(keys.count(name)) << name << " missing from " << path;
    EXPECT_DOUBLE_EQ(qs::getSegmenterParam(from_file, name), qs::getSegmenterParam(defaults, name))
        << name;
  }
}

TEST(SegmenterParams, SetAndGetRoundTripAndUnknownKeysThrow) {
  qs::QuadricSegmenter::Params p;
  qs::setSegmenterParam(p, "cgal_stride", 5);
  EXPECT_EQ(p.cgal_stride, 5);
  qs::setSegmenterParam(p, "distance_factor", 0.01);
  EXPECT_DOUBLE_EQ(p.planes.distance_factor, 0.01);
  qs::setSegmenterParam(p, "detect_cones", 0);
  EXPECT_FALSE(p.detect_cones);
  EXPECT_DOUBLE_EQ(qs::getSegmenterParam(p, "detect_cones"), 0.0);
  EXPECT_THROW(qs::setSegmenterParam(p, "no_such_key", 1), std::invalid_argument);
  // The nodelet reads each key with its type: booleans must not be read as numbers.
  EXPECT_EQ(qs::segmenterParamType("detect_cones"), qs::SegmenterParamType::kBool);
  EXPECT_EQ(qs::segmenterParamType("cgal_stride"), qs::SegmenterParamType::kInteger);
  EXPECT_EQ(qs::segmenterParamType("distance_factor"), qs::SegmenterParamType::kReal);

  const std::string bad = testing::TempDir() + "/bad_segmentation.yaml";
  std::ofstream(bad) << "cgal_stride: 3\nbogus: 1\n";
  EXPECT_THROW(qs::loadSegmenterParams(bad), std::invalid_argument);
  std::ofstream(bad) << "cgal_stride: 0\n";
  EXPECT_THROW(qs::loadSegmenterParams(bad), std::invalid_argument);  // validate()
  std::remove(bad.c_str());
}
