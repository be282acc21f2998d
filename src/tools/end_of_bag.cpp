// end_of_bag: ends a run on a played rosbag cleanly. It watches the simulated clock (use_sim_time,
// `rosbag play --clock`); once the clock has run and then stood still for ~idle_timeout wall
// seconds (the bag has ended, and the pipeline has had that long to finish its last frames), it
// saves the map through the mapper's SaveMap service (when ~map_file is set) and, with ~shutdown,
// exits ~linger wall seconds later. Mark it required="true" in a launch file and the whole launch
// ends with it, while every node is still alive to save: the recorders write their files at
// shutdown.
//
//   rosrun quadric_slam end_of_bag _map_file:=/tmp/map.yaml
//
// Private parameters:
//   ~idle_timeout      wall s the clock must stand still; default 3.0
//   ~map_file          "" (default): no map is saved; else the path handed to the service
//   ~save_map_service  default "mapping/save_map" (quadric_slam/SaveMap)
//   ~service_timeout   wall s to wait for that service to exist; default 5.0
//   ~shutdown          exit after the end (default true); false keeps it (and the launch) running
//   ~linger            wall s between the end and the exit; default 0.0
#include <ros/ros.h>

#include "quadric_slam/SaveMap.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "end_of_bag");
  ros::NodeHandle nh, private_nh("~");
  double idle_timeout = 3.0, service_timeout = 5.0, linger = 0.0;
  std::string map_file, service = "mapping/save_map";
  bool shutdown = true;
  private_nh.param("idle_timeout", idle_timeout, idle_timeout);
  private_nh.param("map_file", map_file, map_file);
  private_nh.param("save_map_service", service, service);
  private_nh.param("service_timeout", service_timeout, service_timeout);
  private_nh.param("shutdown", shutdown, shutdown);
  private_nh.param("linger", linger, linger);
  if (!ros::Time::isSimTime()) {
    ROS_ERROR("end_of_bag: use_sim_time is not set, so there is no bag clock to watch; idle");
    ros::spin();
    return 0;
  }

  ros::Time start, last;
  ros::WallTime last_progress = ros::WallTime::now();
  bool ended = false;
  ros::WallTimer exit_timer;
  ros::WallTimer timer =
      nh.createWallTimer(ros::WallDuration(0.25), [&](const ros::WallTimerEvent&) {
        if (ended)
          return;
        const ros::Time now = ros::Time::now();
        if (now != last) {
          if (start.isZero())
            start = now;
          last = now;
          last_progress = ros::WallTime::now();
          return;
        }
        if (start.isZero() || (ros::WallTime::now() - last_progress).toSec() < idle_timeout)
          return;
        ended = true;
        std::printf("end_of_bag: the bag ended at t = %.3f s (%.1f s played)\n", last.toSec(),
                    (last - start).toSec());
        std::fflush(stdout);
        if (!map_file.empty()) {
          const std::string resolved = nh.resolveName(service);
          quadric_slam::SaveMap save;
          save.request.path = map_file;
          if (!ros::service::waitForService(resolved, ros::Duration(service_timeout))) {
            ROS_WARN("end_of_bag: no service %s: the map is not saved", resolved.c_str());
          } else if (!ros::service::call(resolved, save)) {
            ROS_ERROR("end_of_bag: calling %s failed", resolved.c_str());
          } else if (!save.response.success) {
            ROS_ERROR("end_of_bag: %s: %s", resolved.c_str(), save.response.message.c_str());
          } else {
            std::printf("end_of_bag: map with %u quadrics saved: %s\n", save.response.num_quadrics,
                        save.response.message.c_str());
            std::fflush(stdout);
          }
        }
        if (shutdown) {
          exit_timer = nh.createWallTimer(
              ros::WallDuration(std::max(linger, 0.01)),
              [](const ros::WallTimerEvent&) { ros::shutdown(); }, true);
        }
      });
  ROS_INFO("end_of_bag: waiting for the bag's clock to stop for %.1f s%s", idle_timeout,
           map_file.empty() ? "" : (", then saving the map to " + map_file).c_str());
  ros::spin();
  return 0;
}
