#include "quadric_slam/io/trajectory_io.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace quadric_slam {
namespace {

[[noreturn]] void fail(const std::string& source, std::size_t line, const std::string& problem) {
  throw std::runtime_error(source + ":" + std::to_string(line) + ": " + problem);
}

double parseNumber(const std::string& field, const std::string& source, std::size_t line,
                   const char* name) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(field.c_str(), &end);
  if (end == field.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(value)) {
    fail(source, line, std::string(name) + " is not a finite number: '" + field + "'");
  }
  return value;
}

}  // namespace

Trajectory parseTumTrajectory(std::istream& in, const std::string& source_name) {
  static const char* const kNames[8] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  Trajectory trajectory;
  std::string text;
  std::size_t line_number = 0;
  while (std::getline(in, text)) {
    ++line_number;
    if (!text.empty() && text.back() == '\r')
      text.pop_back();
    for (char& c : text) {
      if (c == ',' || c == '\t')
        c = ' ';
    }
    const std::size_t first = text.find_first_not_of(' ');
    if (first == std::string::npos || text[first] == '#')
      continue;
    std::istringstream fields(text);
    std::vector<std::string> values;
    for (std::string field; fields >> field;)
      values.push_back(field);
    if (values.size() != 8) {
      fail(source_name, line_number,
           "expected 8 fields 'timestamp tx ty tz qx qy qz qw', got " +
               std::to_string(values.size()));
    }
    double v[8];
    for (int k = 0; k < 8; ++k)
      v[k] = parseNumber(values[k], source_name, line_number, kNames[k]);
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (!(q.norm() > 1e-9))
      fail(source_name, line_number, "quaternion has zero length");
    q.normalize();
    StampedPose pose;
    pose.stamp = v[0];
    pose.T_world_sensor.linear() = q.toRotationMatrix();
    pose.T_world_sensor.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    trajectory.push_back(pose);
  }
  return trajectory;
}

Trajectory readTumTrajectory(const std::string& path) {
  std::ifstream in(path);
  if (!in)
    throw std::runtime_error(path + ": cannot open trajectory file");
  return parseTumTrajectory(in, path);
}

namespace {

void writeTumHeader(std::ostream& out, const std::string& comment) {
  if (!comment.empty())
    out << "# " << comment << "\n";
  out << "# timestamp tx ty tz qx qy qz qw\n";
}

void writeTumPose(std::ostream& out, const StampedPose& pose) {
  char buffer[256];
  const Eigen::Vector3d t = pose.T_world_sensor.translation();
  const Eigen::Quaterniond q(pose.T_world_sensor.rotation());
  std::snprintf(buffer, sizeof(buffer), "%.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", pose.stamp,
                t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  out << buffer;
}

}  // namespace

void writeTumTrajectory(const Trajectory& trajectory, std::ostream& out,
                        const std::string& comment) {
  writeTumHeader(out, comment);
  for (const StampedPose& pose : trajectory)
    writeTumPose(out, pose);
}

void writeTumTrajectory(const Trajectory& trajectory, const std::string& path,
                        const std::string& comment) {
  std::ofstream out(path);
  if (!out)
    throw std::runtime_error(path + ": cannot open for writing");
  writeTumTrajectory(trajectory, out, comment);
  out.flush();
  if (!out)
    throw std::runtime_error(path + ": write failed");
}

TumTrajectoryWriter::TumTrajectoryWriter(const std::string& path, const std::string& comment)
    : path_(path), out_(path) {
  if (!out_)
    throw std::runtime_error(path + ": cannot open for writing");
  writeTumHeader(out_, comment);
  out_.flush();
}

void TumTrajectoryWriter::append(const StampedPose& pose) {
  writeTumPose(out_, pose);
  out_.flush();
  if (!out_)
    throw std::runtime_error(path_ + ": write failed");
}

}  // namespace quadric_slam
