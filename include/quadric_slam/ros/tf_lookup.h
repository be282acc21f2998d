// tf2 lookups at message stamps, for the tools that record or show a trajectory from tf
// (record_trajectory, groundtruth_path): frame ids without a leading '/' (ros/frame_ids.h), and
// stamps that wait for their transforms, resolved in order.
#pragma once

#include <ros/time.h>
#include <tf2_ros/buffer.h>
#include <Eigen/Geometry>

#include <cstddef>
#include <deque>
#include <optional>
#include <string>
#include <vector>

namespace quadric_slam {

// T_target_source at `stamp` (it maps points from source_frame into target_frame), the frame ids
// taken without a leading '/'; nullopt, with tf2's reason in *error when given, while tf2 cannot
// give it (not yet arrived, or never).
std::optional<Eigen::Isometry3d> lookupIsometry(const tf2_ros::Buffer& buffer,
                                                const std::string& target_frame,
                                                const std::string& source_frame,
                                                const ros::Time& stamp, std::string* error);

struct TfLookup {
  std::string target_frame, source_frame;
};

// Stamps whose transforms are looked up once tf has delivered them. A tool sees a message (an
// odometry, say) before the transforms at its stamp reach its buffer, so each stamp waits, and the
// stamps are resolved in the order they were added (a recorded trajectory stays in time order). A
// stamp whose transforms have not arrived when the newest added stamp is more than max_delay
// seconds (message time) younger is given up: tf will not bring them (a gap, a dropped frame).
class PendingTfLookups {
 public:
  struct Resolved {
    ros::Time stamp;
    std::vector<Eigen::Isometry3d> transforms;  // T_target_source, one per lookup, same order
  };

  explicit PendingTfLookups(double max_delay) : max_delay_(max_delay) {}

  // Waits for all of `lookups` at `stamp` (frame ids normalised when looked up).
  void add(const ros::Time& stamp, std::vector<TfLookup> lookups);

  // Resolves the waiting stamps in order, up to the first one that may still get its transforms;
  // with `final` (no more transforms will come), gives up on whatever cannot be resolved now.
  std::vector<Resolved> resolve(const tf2_ros::Buffer& buffer, bool final);

  ros::Time newest() const { return newest_; }
  std::size_t waiting() const { return pending_.size(); }
  std::size_t givenUp() const { return given_up_; }
  // tf2's reason for the latest stamp given up ("" before any).
  const std::string& lastError() const { return last_error_; }

 private:
  struct Pending {
    ros::Time stamp;
    std::vector<TfLookup> lookups;
  };

  double max_delay_;
  std::deque<Pending> pending_;
  ros::Time newest_;
  std::size_t given_up_ = 0;
  std::string last_error_;
};

}  // namespace quadric_slam
