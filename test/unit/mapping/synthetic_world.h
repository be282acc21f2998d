// Synthetic worlds for the mapping tests and bench_mapping: true quadric landmarks of every class
// with the boxes of their surfaces, a camera trajectory, a visibility test, noisy measurements
// (z = h(T_WC, pi) [+] nu, nu ~ N(0, Sigma), eq. 18, re-expressed in a random frame of the same
// surface) and drifting odometry.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "../test_support.h"
#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/geometry/quadric_classes.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/geometry/symmetry.h"
#include "quadric_slam/io/map_yaml.h"
#include "quadric_slam/mapping/extent_box.h"
#include "quadric_slam/mapping/landmark.h"
#include "quadric_slam/types/observation.h"

namespace quadric_slam {
namespace test {

struct TrueLandmark {
  QuadricModel quadric_world;
  ExtentBox extent;  // the surface patch, in the quadric frame (m)
};

// A plane with normal = quadric x through `centre`, in-plane axes u (quadric y) and n x u.
inline TrueLandmark plane(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal,
                          const Eigen::Vector3d& u, double half_u, double half_v) {
  Eigen::Matrix3d R;
  R.col(0) = normal.normalized();
  R.col(1) = (u - u.dot(R.col(0)) * R.col(0)).normalized();
  R.col(2) = R.col(0).cross(R.col(1));
  TrueLandmark l{
      QuadricModel(QuadricClass::kPlane, makeIsometry(R, centre), Eigen::Vector3d::Ones()), {}};
  l.extent = {Eigen::Vector3d(-0.01, -half_u, -half_v), Eigen::Vector3d(0.01, half_u, half_v)};
  return l;
}
inline TrueLandmark sphere(const Eigen::Vector3d& centre, double radius) {
  return {quadricFromShape(SphereShape{centre, radius}),
          {Eigen::Vector3d::Constant(-radius), Eigen::Vector3d::Constant(radius)}};
}
// Axis through `centre` (the middle of the patch), half_length along it.
inline TrueLandmark cylinder(const Eigen::Vector3d& centre, const Eigen::Vector3d& axis,
                             double radius, double half_length) {
  return {quadricFromShape(CylinderShape{centre, axis, radius}),
          {Eigen::Vector3d(-radius, -radius, -half_length),
           Eigen::Vector3d(radius, radius, half_length)}};
}
// Surface from the apex to `length` along the axis (into the opening).
inline TrueLandmark cone(const Eigen::Vector3d& apex, const Eigen::Vector3d& axis,
                         double half_angle, double length) {
  const double r = length * std::tan(half_angle);
  return {quadricFromShape(ConeShape{apex, axis, half_angle}),
          {Eigen::Vector3d(-r, -r, 0.05), Eigen::Vector3d(r, r, length)}};
}

// A 10 x 10 m room, 3 m high: floor, four walls, two table tops 3 cm apart in height (inside each
// other's association gate: only their extents tell them apart; not exactly equal so that the map
// evaluator, which compares infinite planes, can tell which is which), three spheres, three
// cylinders (one horizontal), three cones.
inline std::vector<TrueLandmark> roomWorld() {
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(),
                        Z = Eigen::Vector3d::UnitZ();
  return {
      plane(Eigen::Vector3d(0, 0, 0), Z, X, 5, 5),
      plane(Eigen::Vector3d(5, 0, 1.5), -X, Y, 5, 1.5),
      plane(Eigen::Vector3d(-5, 0, 1.5), X, Y, 5, 1.5),
      plane(Eigen::Vector3d(0, 5, 1.5), -Y, X, 5, 1.5),
      plane(Eigen::Vector3d(0, -5, 1.5), Y, X, 5, 1.5),
      plane(Eigen::Vector3d(3.6, 1.2, 0.75), Z, X, 0.5, 0.4),
      plane(Eigen::Vector3d(-3.6, -1.2, 0.72), Z, X, 0.5, 0.4),
      sphere(Eigen::Vector3d(3.4, -1.6, 0.3), 0.3),
      sphere(Eigen::Vector3d(-1.2, 3.6, 0.25), 0.25),
      sphere(Eigen::Vector3d(0.8, -3.5, 1.0), 0.2),
      cylinder(Eigen::Vector3d(2.6, 3.0, 1.5), Z, 0.15, 1.5),
      cylinder(Eigen::Vector3d(-3.3, 2.2, 0.5), Z, 0.2, 0.5),
      cylinder(Eigen::Vector3d(-1.0, -4.0, 0.5), X, 0.1, 1.0),
      cone(Eigen::Vector3d(3.5, -3.3, 0.7), -Z, 0.35, 0.6),
      cone(Eigen::Vector3d(-3.7, -1.0 + 2.5, 1.6), -Z, 0.4, 0.5),
      cone(Eigen::Vector3d(1.2, 3.8, 0.8), -Z, 0.3, 0.6),
  };
}

// A corridor: a floor and a wall 30 m long and `objects` objects (spheres, cylinders, cones in
// turn) one metre apart from x = 2 m on, alternately left and right. The map grows with the
// distance travelled.
inline std::vector<TrueLandmark> corridorWorld(int objects) {
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Z = Eigen::Vector3d::UnitZ();
  const double length = objects + 4.0;
  std::vector<TrueLandmark> world = {
      plane(Eigen::Vector3d(0.5 * length, 0, 0), Z, X, 0.5 * length + 1, 3),
      plane(Eigen::Vector3d(0.5 * length, 2, 1.5), -Eigen::Vector3d::UnitY(), X, 0.5 * length + 1,
            1.5)};
  for (int j = 0; j < objects; ++j) {
    const double x = 2.0 + j;
    const double y = (j % 2 == 0) ? -0.8 : 1.0;
    switch (j % 3) {
      case 0:
        world.push_back(sphere(Eigen::Vector3d(x, y, 0.25), 0.2 + 0.01 * (j % 5)));
        break;
      case 1:
        world.push_back(cylinder(Eigen::Vector3d(x, y, 0.4), Z, 0.12, 0.4));
        break;
      default:
        world.push_back(cone(Eigen::Vector3d(x, y, 0.6), -Z, 0.35, 0.5));
    }
  }
  return world;
}

// Optical camera frame (x right, y down, z forward) at `position` looking along `forward`.
inline Eigen::Isometry3d lookAlong(const Eigen::Vector3d& position,
                                   const Eigen::Vector3d& forward) {
  const Eigen::Vector3d f = forward.normalized();
  const Eigen::Vector3d right = f.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Matrix3d R;
  R << right, f.cross(right), f;
  return makeIsometry(R, position);
}

// `laps` circles of radius 2 m at 1.3 m height, `frames_per_lap` frames each, looking outward
// (0.5 rad ahead of radial) and 0.3 rad down.
inline std::vector<Eigen::Isometry3d> circleTrajectory(int frames_per_lap, double laps) {
  std::vector<Eigen::Isometry3d> poses;
  const int n = static_cast<int>(std::lround(frames_per_lap * laps));
  for (int i = 0; i < n; ++i) {
    const double theta = 2 * M_PI * i / frames_per_lap;
    const Eigen::Vector3d p(2.0 * std::cos(theta), 2.0 * std::sin(theta), 1.3);
    const double heading = theta + 0.5;
    const Eigen::Vector3d forward(std::cos(0.3) * std::cos(heading),
                                  std::cos(0.3) * std::sin(heading), -std::sin(0.3));
    poses.push_back(lookAlong(p, forward));
  }
  return poses;
}

// `frames` frames down the corridor at 3 cm per frame, weaving slightly.
inline std::vector<Eigen::Isometry3d> corridorTrajectory(int frames) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < frames; ++i)
    poses.push_back(lookAlong(Eigen::Vector3d(0.03 * i, 0.1 * std::sin(0.05 * i), 1.2),
                              Eigen::Vector3d(1, 0.2 * std::sin(0.03 * i), -0.35)));
  return poses;
}

// Visible when a point of the patch (a 5x5x5 grid over its box) lies in the 57 x 43 deg frustum
// between 0.3 and 5 m.
inline bool visible(const TrueLandmark& l, const Eigen::Isometry3d& T_world_camera) {
  const Eigen::Isometry3d T_camera_quadric = T_world_camera.inverse() * l.quadric_world.pose();
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      for (int k = 0; k < 5; ++k) {
        const Eigen::Vector3d f(i / 4.0, j / 4.0, k / 4.0);
        const Eigen::Vector3d p_q = l.extent.min + f.cwiseProduct(l.extent.max - l.extent.min);
        const Eigen::Vector3d p = T_camera_quadric * p_q;
        if (p.z() < 0.3 || p.norm() > 5.0)
          continue;
        if (std::abs(p.x() / p.z()) < std::tan(0.497) && std::abs(p.y() / p.z()) < std::tan(0.375))
          return true;
      }
  return false;
}

// The stated measurement noise (1-sigma, minimal space): 5 mm on translation entries, 0.005 rad on
// rotation entries, 2% of the true scale on scale entries; diagonal.
inline Eigen::MatrixXd measurementCovariance(const QuadricModel& q) {
  const QuadricClassDefinition& def = classDefinition(q.quadricClass());
  const int k = def.minimal_dimension;
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(k, k);
  for (int j = 0; j < k; ++j) {
    int row = 0;
    def.basis.col(j).cwiseAbs().maxCoeff(&row);
    const double s = row < 3 ? 0.005 : row < 6 ? 0.005 : 0.02 * q.scale()[row - 6];
    c(j, j) = s * s;
  }
  return c;
}

// z = h(T_WC, pi) [+] nu (eq. 18) with nu ~ N(0, measurementCovariance), re-expressed by a random
// symmetry G of the surface (covariance M Sigma M^T, M = minimalAdjoint(G^-1)); extent = the true
// patch box moved into z's frame.
inline QuadricMeasurement measure(const TrueLandmark& l, const Eigen::Isometry3d& T_world_camera,
                                  std::mt19937& rng, double noise_scale = 1.0) {
  const QuadricClass c = l.quadric_world.quadricClass();
  const QuadricModel h = predictMeasurement(T_world_camera, l.quadric_world);
  const Eigen::MatrixXd sigma = measurementCovariance(h);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::VectorXd n(sigma.rows());
  for (int i = 0; i < n.size(); ++i)
    n[i] = gauss(rng) * noise_scale;
  const Eigen::MatrixXd L = sigma.llt().matrixL();
  const QuadricModel noisy = h.plusMinimal(L * n);
  const Eigen::Isometry3d G = randomSymmetry(c, rng);
  QuadricMeasurement m;
  m.quadric_camera = QuadricModel(c, noisy.pose() * G, noisy.scale(), noisy.signature());
  const Eigen::MatrixXd M = minimalAdjoint(c, G.inverse());
  m.covariance = M * sigma * M.transpose();
  m.covariance = 0.5 * (m.covariance + m.covariance.transpose()).eval();
  const ExtentBox box = l.extent.transformed(m.quadric_camera.pose().inverse() * h.pose());
  m.extent_min = box.min;
  m.extent_max = box.max;
  m.num_points = 1000;
  return m;
}

// Odometry with drift: each true increment D_i = T_{i-1}^-1 T_i is measured as D_i exp(xi^) with
// rho = 2% of D_i's translation + N(0, 1 mm), phi = (0, 0.001, 0) rad (a yaw bias about the
// camera's down axis) + N(0, 0.5 mrad). Starts at the identity.
inline std::vector<Eigen::Isometry3d> driftingOdometry(const std::vector<Eigen::Isometry3d>& truth,
                                                       std::mt19937& rng) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<Eigen::Isometry3d> odom{Eigen::Isometry3d::Identity()};
  for (size_t i = 1; i < truth.size(); ++i) {
    const Eigen::Isometry3d D = truth[i - 1].inverse() * truth[i];
    Vector6d xi;
    xi.head<3>() =
        0.02 * D.translation() + 0.001 * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    xi.tail<3>() =
        Eigen::Vector3d(0, 0.001, 0) + 0.0005 * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    odom.push_back(odom.back() * D * expSE3(xi));
  }
  return odom;
}

inline MapFileQuadric toMapFile(int id, const QuadricModel& q, int observations) {
  MapFileQuadric out;
  out.id = id;
  out.quadric_class = toString(q.quadricClass());
  out.observations = observations;
  out.T_map_quadric = q.pose();
  out.scale = q.scale();
  out.shape = shapeMap(q);
  return out;
}

// The map file of the true landmarks (ids = their indices in `world`), for eval/map_metrics.h.
inline MapFile truthMap(const std::vector<TrueLandmark>& world) {
  MapFile map;
  for (size_t i = 0; i < world.size(); ++i)
    map.quadrics.push_back(toMapFile(static_cast<int>(i), world[i].quadric_world, 0));
  return map;
}

// The map file of estimated landmarks (e.g. QuadricMapper::landmarks(), a batch solution's).
inline MapFile estimateMap(const std::vector<QuadricLandmark>& landmarks) {
  MapFile map;
  for (const QuadricLandmark& l : landmarks)
    map.quadrics.push_back(toMapFile(l.id, l.quadric_map, l.observations));
  return map;
}

// A piece of the wall x = 3 (normal -x) over world y in [y0, y1], z in [z0, z1], in a frame of its
// own: the segmenter reports a large surface as such fragments.
inline TrueLandmark wallPiece(double y0, double y1, double z0 = 0.0, double z1 = 2.5) {
  return plane(Eigen::Vector3d(3.0, 0.5 * (y0 + y1), 0.5 * (z0 + z1)), -Eigen::Vector3d::UnitX(),
               Eigen::Vector3d::UnitY(), 0.5 * (y1 - y0), 0.5 * (z1 - z0));
}

// A wall seen in three parts, frame by frame, with the floor (z = 0, 3 x 4 m around x = 1.5) in
// every frame: its left part (y in [-3.5, -2]) in the first 12 frames, its right part ([2, 3.5])
// in the next 12, then its middle ([-2.2, 2.2]), which makes the parts' extents touch. The parts
// are 4 m apart: synthetic measurements come in frames turned at random about the normal, whose
// axis-aligned boxes (moved twice, into the candidate's and the landmark's frame) are up to twice
// as wide, and association grows boxes by 0.25 m.
inline std::vector<std::vector<TrueLandmark>> wallInThreeParts(int frames = 36) {
  const TrueLandmark floor = plane(Eigen::Vector3d(1.5, 0, 0), Eigen::Vector3d::UnitZ(),
                                   Eigen::Vector3d::UnitX(), 1.5, 2.0);
  std::vector<std::vector<TrueLandmark>> pieces;
  for (int i = 0; i < frames; ++i) {
    if (i < frames / 3)
      pieces.push_back({wallPiece(-3.5, -2.0, 0.5, 2.0), floor});
    else if (i < 2 * frames / 3)
      pieces.push_back({wallPiece(2.0, 3.5, 0.5, 2.0), floor});
    else
      pieces.push_back({wallPiece(-2.2, 2.2, 0.5, 2.0), floor});
  }
  return pieces;
}

// The camera 3 m from the wall of wallPiece at 1.3 m height, looking at it (+x) and a little down,
// sliding along y from y_from to y_to over `frames` frames.
inline std::vector<Eigen::Isometry3d> slideAlongWall(int frames, double y_from, double y_to) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < frames; ++i) {
    const double y = y_from + (y_to - y_from) * i / std::max(frames - 1, 1);
    poses.push_back(lookAlong(Eigen::Vector3d(0, y, 1.3), Eigen::Vector3d(1, 0, -0.25)));
  }
  return poses;
}

}  // namespace test
}  // namespace quadric_slam
