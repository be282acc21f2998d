// TUM trajectory files: one pose per line, `timestamp tx ty tz qx qy qz qw` (s, m, unit quaternion
// of T_world_sensor), '#' starts a comment line. Commas and tabs count as separators (as in TUM's
// associate.py).
#pragma once

#include <Eigen/Geometry>
#include <iosfwd>
#include <fstream>
#include <string>
#include <vector>

namespace quadric_slam {

struct StampedPose {
  double stamp = 0.0;                                                // s
  Eigen::Isometry3d T_world_sensor = Eigen::Isometry3d::Identity();  // maps sensor points to world
};

using Trajectory = std::vector<StampedPose>;

// Poses in file order (not sorted, duplicates kept); quaternions are normalised. Throws
// std::runtime_error "<source>:<line>: <problem>" on a malformed line (field count, a field that is
// not a finite number, a zero quaternion), or naming the file when it cannot be opened.
Trajectory readTumTrajectory(const std::string& path);
Trajectory parseTumTrajectory(std::istream& in, const std::string& source_name);

// Writes `timestamp tx ty tz qx qy qz qw` lines (stamp with 6 decimals, the rest with 9
// significant digits) after an optional '#' comment; throws std::runtime_error when the file cannot
// be written.
void writeTumTrajectory(const Trajectory& trajectory, const std::string& path,
                        const std::string& comment = "");
void writeTumTrajectory(const Trajectory& trajectory, std::ostream& out,
                        const std::string& comment = "");

// The same file written one pose at a time, so a long run need not keep its trajectory in memory.
// The header goes out on construction; each append() is flushed to the line. Throws
// std::runtime_error when the file cannot be opened or written.
class TumTrajectoryWriter {
 public:
  TumTrajectoryWriter(const std::string& path, const std::string& comment = "");
  void append(const StampedPose& pose);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ofstream out_;
};

}  // namespace quadric_slam
