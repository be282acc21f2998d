#include "quadric_slam/sim/trajectory.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "quadric_slam/sim/random.h"

namespace quadric_slam {

Trajectory readDrivingTrajectory(const std::string& path) {
  const Trajectory read = readTumTrajectory(path);
  Trajectory poses;
  for (const StampedPose& pose : read) {
    // The official files repeat a stamp now and then (4-decimal rounding): keep the first.
    if (!poses.empty() && pose.stamp == poses.back().stamp)
      continue;
    if (!poses.empty() && pose.stamp < poses.back().stamp) {
      throw std::runtime_error(path + ": stamps must not decrease (" + std::to_string(pose.stamp) +
                               " after " + std::to_string(poses.back().stamp) + ")");
    }
    poses.push_back(pose);
  }
  if (poses.size() < 2)
    throw std::runtime_error(path + ": fewer than two poses");
  return poses;
}

Eigen::Isometry3d interpolatePose(const std::vector<StampedPose>& trajectory, double stamp) {
  if (trajectory.empty() || stamp < trajectory.front().stamp || stamp > trajectory.back().stamp)
    throw std::out_of_range("interpolatePose: stamp outside the trajectory");
  std::size_t hi = 1;
  // Binary search for the first sample with stamp >= the query.
  std::size_t lo = 0, end = trajectory.size();
  while (lo < end) {
    const std::size_t mid = (lo + end) / 2;
    if (trajectory[mid].stamp < stamp)
      lo = mid + 1;
    else
      end = mid;
  }
  hi = std::max<std::size_t>(lo, 1);
  const StampedPose& a = trajectory[hi - 1];
  const StampedPose& b = trajectory[hi];
  const double s = (stamp - a.stamp) / (b.stamp - a.stamp);
  const Eigen::Quaterniond qa(a.T_world_sensor.rotation()), qb(b.T_world_sensor.rotation());
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = qa.slerp(s, qb).normalized().toRotationMatrix();
  pose.translation() =
      (1.0 - s) * a.T_world_sensor.translation() + s * b.T_world_sensor.translation();
  return pose;
}

std::vector<StampedPose> resampleTrajectory(const std::vector<StampedPose>& trajectory, double rate,
                                            double seconds) {
  if (!(rate > 0.0))
    throw std::invalid_argument("resampleTrajectory: rate must be > 0 Hz");
  std::vector<StampedPose> frames;
  if (trajectory.empty())
    return frames;
  const double start = trajectory.front().stamp;
  const long count = std::lround(std::floor(seconds * rate + 1e-9));
  for (long k = 0; k < count; ++k) {
    const double stamp = start + static_cast<double>(k) / rate;
    if (stamp > trajectory.back().stamp)
      break;
    frames.push_back({stamp, interpolatePose(trajectory, stamp)});
  }
  return frames;
}

Eigen::Isometry3d lookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target,
                         const Eigen::Vector3d& world_up) {
  const Eigen::Vector3d z = (target - position).normalized();
  Eigen::Vector3d x = z.cross(world_up);
  if (x.norm() < 1e-9)
    x = z.unitOrthogonal();
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = x;
  pose.linear().col(1) = y;
  pose.linear().col(2) = z;
  pose.translation() = position;
  return pose;
}

void HandheldTrajectory::Params::validate() const {
  auto require = [](bool ok, const char* field, const char* range) {
    if (!ok) {
      throw std::invalid_argument(std::string("HandheldTrajectory::Params::") + field +
                                  " must be " + range);
    }
  };
  require(distance > 0.1, "distance", "> 0.1 m");
  require(std::abs(height) < 10.0, "height", "in (-10, 10) m");
  require(std::isfinite(azimuth), "azimuth", "finite (rad)");
  require(sweep >= 0.0 && sweep <= M_PI, "sweep", "in [0, pi] rad");
  require(sweep_period > 0.0, "sweep_period", "> 0 s");
  require(wobble >= 0.0 && wobble < distance / 2, "wobble", "in [0, distance / 2) m");
  require(gaze_wobble >= 0.0 && gaze_wobble < 1.0, "gaze_wobble", "in [0, 1) m");
  require(roll_wobble >= 0.0 && roll_wobble < 0.5, "roll_wobble", "in [0, 0.5) rad");
  require(start_stamp > 0.0, "start_stamp", "> 0 s");
}

HandheldTrajectory::HandheldTrajectory(const Params& params) : params_(params) {
  params_.validate();
}

namespace {

// A smooth random signal in [-1, 1]: three sinusoids with seeded frequencies (0.05 - 0.5 Hz)
// and phases, normalised by the sum of their amplitudes.
struct Wobble {
  double frequency[3], phase[3], amplitude[3];
  explicit Wobble(SimRandom& random) {
    for (int i = 0; i < 3; ++i) {
      frequency[i] = 0.05 + 0.45 * random.uniform();
      phase[i] = 2.0 * M_PI * random.uniform();
      amplitude[i] = 1.0 / (i + 1);
    }
  }
  double operator()(double t) const {
    double sum = 0.0, norm = 0.0;
    for (int i = 0; i < 3; ++i) {
      sum += amplitude[i] * std::sin(2.0 * M_PI * frequency[i] * t + phase[i]);
      norm += amplitude[i];
    }
    return sum / norm;
  }
};

}  // namespace

std::vector<StampedPose> HandheldTrajectory::generate(const Eigen::Vector3d& centre, double rate,
                                                      double seconds, std::uint64_t seed) const {
  if (!(rate > 0.0) || !(seconds >= 0.0))
    throw std::invalid_argument("HandheldTrajectory::generate: rate > 0 Hz and seconds >= 0");
  SimRandom random(seed, 0x7a1, 0);
  Wobble position_wobble[3] = {Wobble(random), Wobble(random), Wobble(random)};
  Wobble gaze[3] = {Wobble(random), Wobble(random), Wobble(random)};
  Wobble roll(random);
  const double phase = 2.0 * M_PI * random.uniform();
  std::vector<StampedPose> frames;
  const long count = std::lround(std::floor(seconds * rate + 1e-9));
  for (long k = 0; k < count; ++k) {
    const double t = static_cast<double>(k) / rate;
    // The swing starts at `azimuth` (sin(phase) removed so that t = 0 is at azimuth).
    const double azimuth =
        params_.azimuth +
        params_.sweep * (std::sin(2.0 * M_PI * t / params_.sweep_period + phase) - std::sin(phase));
    Eigen::Vector3d position =
        centre + Eigen::Vector3d(params_.distance * std::cos(azimuth),
                                 params_.distance * std::sin(azimuth), params_.height);
    Eigen::Vector3d target = centre;
    for (int i = 0; i < 3; ++i) {
      position[i] += params_.wobble * position_wobble[i](t);
      target[i] += params_.gaze_wobble * gaze[i](t);
    }
    StampedPose pose;
    pose.stamp = params_.start_stamp + t;
    pose.T_world_sensor = lookAt(position, target);
    pose.T_world_sensor.linear() =
        pose.T_world_sensor.linear() *
        Eigen::AngleAxisd(params_.roll_wobble * roll(t), Eigen::Vector3d::UnitZ())
            .toRotationMatrix();
    frames.push_back(pose);
  }
  return frames;
}

}  // namespace quadric_slam
