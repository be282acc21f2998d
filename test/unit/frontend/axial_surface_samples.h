// Noisy samples of the camera-facing side of a cone or a cylinder with measured-like normals, for
// the tests of the curved shapes' starts and model selection.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <vector>

namespace quadric_slam {
namespace test {

struct SurfaceSamples {
  std::vector<Eigen::Vector3d> points, normals;
};

// The apex of the sampled cones and a point on the sampled cylinders' axis (axis along y).
inline const Eigen::Vector3d kAxisPoint(0.1, -0.3, 1.6);

// `count` points of a cone (apex kAxisPoint, half angle radius_or_angle) or a cylinder (axis
// through kAxisPoint, radius radius_or_angle) with axis along y, heights y in [y_min, y_max] and
// azimuths within +-max_azimuth_deg of the direction towards the camera at the origin; unit
// normals out of the surface; Gaussian noise of standard deviation `noise` along the normal.
inline SurfaceSamples axialSurface(bool cone, double radius_or_angle, double y_min, double y_max,
                                   double noise, unsigned seed, int count = 800,
                                   double max_azimuth_deg = 80.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, noise);
  SurfaceSamples s;
  for (int i = 0; i < count; ++i) {
    const double y = y_min + (y_max - y_min) * uni(rng);
    // Azimuth measured from -z (towards the camera at the origin).
    const double a = (uni(rng) - 0.5) * 2 * max_azimuth_deg * M_PI / 180;
    const Eigen::Vector3d radial(std::sin(a), 0, -std::cos(a));
    const double r = cone ? y * std::tan(radius_or_angle) : radius_or_angle;
    const Eigen::Vector3d axial = Eigen::Vector3d::UnitY();
    const Eigen::Vector3d n = cone ? Eigen::Vector3d(std::cos(radius_or_angle) * radial -
                                                     std::sin(radius_or_angle) * axial)
                                   : radial;
    s.points.push_back(kAxisPoint + y * axial + r * radial + gauss(rng) * n);
    s.normals.push_back(n.normalized());
  }
  return s;
}

}  // namespace test
}  // namespace quadric_slam
