#include "quadric_slam/ros/map_publisher.h"

#include <quadric_slam/QuadricMap.h>
#include <visualization_msgs/MarkerArray.h>

#include "quadric_slam/ros/conversions.h"

namespace quadric_slam {

QuadricMapPublisher::QuadricMapPublisher(ros::NodeHandle& nh, const std::string& map_topic,
                                         const std::string& markers_topic, const MarkerStyle& style)
    : style_(style) {
  style_.validate();
  map_pub_ = nh.advertise<QuadricMap>(map_topic, 1, true);
  markers_pub_ = nh.advertise<visualization_msgs::MarkerArray>(markers_topic, 1, true);
}

void QuadricMapPublisher::publish(const std::vector<QuadricLandmark>& landmarks,
                                  const std_msgs::Header& header,
                                  const std::map<int, int>& merged_into) {
  auto map = boost::make_shared<QuadricMap>();
  map->header = header;
  map->quadrics.reserve(landmarks.size());
  for (const QuadricLandmark& landmark : landmarks)
    map->quadrics.push_back(toLandmarkMsg(landmark));
  for (const auto& [merged, survivor] : merged_into) {
    map->merged_ids.push_back(static_cast<std::uint32_t>(merged));
    map->merged_into.push_back(static_cast<std::uint32_t>(survivor));
  }
  map_pub_.publish(map);
  markers_pub_.publish(boost::make_shared<visualization_msgs::MarkerArray>(
      quadricMarkers(landmarks, header, style_)));
}

}  // namespace quadric_slam
