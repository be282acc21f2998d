// Publishes the landmarks as the quadric map (quadric_slam/QuadricMap) and its rviz markers
// (visualization_msgs/MarkerArray, ros/markers.h), both latched, with one header.
#pragma once

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <std_msgs/Header.h>

#include <map>
#include <string>
#include <vector>

#include "quadric_slam/mapping/landmark.h"
#include "quadric_slam/ros/markers.h"

namespace quadric_slam {

class QuadricMapPublisher {
 public:
  QuadricMapPublisher() = default;
  // Advertises both topics on nh, latched. Throws std::invalid_argument for an invalid style.
  QuadricMapPublisher(ros::NodeHandle& nh, const std::string& map_topic,
                      const std::string& markers_topic, const MarkerStyle& style = MarkerStyle());

  // merged_into: landmark id merged away -> the landmark holding its surface now
  // (LandmarkRegistry::mergedInto), published as QuadricMap.merged_ids / merged_into.
  void publish(const std::vector<QuadricLandmark>& landmarks, const std_msgs::Header& header,
               const std::map<int, int>& merged_into = {});

 private:
  MarkerStyle style_;
  ros::Publisher map_pub_, markers_pub_;
};

}  // namespace quadric_slam
