// Camera trajectories for the simulator: TUM ground-truth files resampled at the frame rate
// (linear position, slerp orientation), and a seeded smooth hand-held motion around a point.
// Poses are T_world_camera of the optical frame (x right, y down, z forward).
#pragma once

#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

#include "quadric_slam/io/trajectory_io.h"

namespace quadric_slam {

// A TUM ground-truth file as a driving trajectory (io/trajectory_io.h's reader): a line repeating
// the previous stamp (as in the official fr2_desk file) is dropped, keeping the first. Throws
// std::runtime_error naming the file on a stamp smaller than its predecessor or fewer than two
// poses.
Trajectory readDrivingTrajectory(const std::string& path);

// Pose at `stamp` (linear in position, slerp in orientation) between the bracketing samples.
// Throws std::out_of_range when stamp lies outside the trajectory.
Eigen::Isometry3d interpolatePose(const std::vector<StampedPose>& trajectory, double stamp);

// Frames at stamps first_stamp + k / rate for k = 0 .. while k < seconds * rate and the stamp
// lies within the trajectory.
std::vector<StampedPose> resampleTrajectory(const std::vector<StampedPose>& trajectory, double rate,
                                            double seconds);

// Camera looking from `position` at `target` with the image's up as close to world +z as
// possible (optical frame: z forward, x right, y down).
Eigen::Isometry3d lookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target,
                         const Eigen::Vector3d& world_up = Eigen::Vector3d::UnitZ());

// A smooth hand-held motion: the camera swings along an arc around the centre of interest at
// roughly constant distance and height, with seeded low-frequency wobble of position, gaze and
// roll, always looking near the centre.
class HandheldTrajectory {
 public:
  struct Params {
    double distance = 1.6;       // horizontal distance from the centre of interest (m)
    double height = 0.8;         // camera height above the centre of interest (m)
    double azimuth = -1.0;       // direction from the centre to the camera at t = 0 (rad, about z)
    double sweep = 0.6;          // amplitude of the swing of the azimuth (rad)
    double sweep_period = 16.0;  // period of the swing (s)
    double wobble = 0.06;        // amplitude of the position wobble (m)
    double gaze_wobble = 0.08;   // amplitude of the look-at point's wobble (m)
    double roll_wobble = 0.05;   // amplitude of the roll about the optical axis (rad)
    double start_stamp = 1500000000.0;  // stamp of the first frame (s)

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  explicit HandheldTrajectory(const Params& params);
  std::vector<StampedPose> generate(const Eigen::Vector3d& centre_of_interest, double rate,
                                    double seconds, std::uint64_t seed) const;

 private:
  Params params_;
};

}  // namespace quadric_slam
