#include "quadric_slam/ros/tf_lookup.h"

#include <tf2_eigen/tf2_eigen.h>

#include <algorithm>

#include "quadric_slam/ros/frame_ids.h"

namespace quadric_slam {

std::optional<Eigen::Isometry3d> lookupIsometry(const tf2_ros::Buffer& buffer,
                                                const std::string& target_frame,
                                                const std::string& source_frame,
                                                const ros::Time& stamp, std::string* error) {
  const std::string target = withoutLeadingSlash(target_frame);
  const std::string source = withoutLeadingSlash(source_frame);
  if (!buffer.canTransform(target, source, stamp, error))
    return std::nullopt;
  return tf2::transformToEigen(buffer.lookupTransform(target, source, stamp));
}

void PendingTfLookups::add(const ros::Time& stamp, std::vector<TfLookup> lookups) {
  newest_ = std::max(newest_, stamp);
  pending_.push_back({stamp, std::move(lookups)});
}

std::vector<PendingTfLookups::Resolved> PendingTfLookups::resolve(const tf2_ros::Buffer& buffer,
                                                                  bool final) {
  std::vector<Resolved> resolved;
  while (!pending_.empty()) {
    const Pending& next = pending_.front();
    Resolved result{next.stamp, {}};
    std::string error;
    for (const TfLookup& lookup : next.lookups) {
      const std::optional<Eigen::Isometry3d> T =
          lookupIsometry(buffer, lookup.target_frame, lookup.source_frame, next.stamp, &error);
      if (!T)
        break;
      result.transforms.push_back(*T);
    }
    if (result.transforms.size() == next.lookups.size()) {
      resolved.push_back(std::move(result));
    } else if (final || (newest_ - next.stamp).toSec() > max_delay_) {
      ++given_up_;
      last_error_ = error;
    } else {
      break;  // its transforms may still come
    }
    pending_.pop_front();
  }
  return resolved;
}

}  // namespace quadric_slam
