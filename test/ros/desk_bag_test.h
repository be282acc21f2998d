// Shared by the rostest checkers that play a rendered desk sequence frame by frame: a gtest
// fixture that renders the bag into its own temporary folder (synthetic_bag.h), reads its depth
// frames back, and removes the folder afterwards.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "synthetic_bag.h"

namespace quadric_slam::test {

class DeskBagTest : public ::testing::Test {
 protected:
  // name: the temporary folder's prefix; rate (Hz), seconds and seed: as writeDeskBag's.
  DeskBagTest(std::string name, double rate, double seconds, std::uint64_t seed)
      : name_(std::move(name)), rate_(rate), seconds_(seconds), seed_(seed) {}

  void SetUp() override {
    dir_ = std::filesystem::path(testing::TempDir()) / (name_ + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    bag_path_ = (dir_ / "desk.bag").string();
    const SyntheticBag bag = writeDeskBag(bag_path_, rate_, seconds_, seed_);
    scene_ = bag.scene;
    truth_ = bag.truth;
    BagDepthFrames frames = readBagDepthFrames(bag_path_);
    info_ = frames.info;
    depths_ = std::move(frames.depths);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path dir_;
  std::string bag_path_;
  Scene scene_;
  Trajectory truth_;  // one pose per depth frame
  sensor_msgs::CameraInfoConstPtr info_;
  std::vector<sensor_msgs::ImageConstPtr> depths_;

 private:
  std::string name_;
  double rate_, seconds_;
  std::uint64_t seed_;
};

}  // namespace quadric_slam::test
