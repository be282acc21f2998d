#include "quadric_slam/sim/primitive_scene_renderer.h"

#include <cmath>
#include <limits>
#include <random>

namespace quadric_slam {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Smallest t > 0 with a t^2 + b t + c = 0 that passes accept(t), or inf.
template <typename Accept>
double nearestRoot(double a, double b, double c, Accept accept) {
  if (std::abs(a) < 1e-15) {
    if (std::abs(b) < 1e-15)
      return kInf;
    const double t = -c / b;
    return t > 0 && accept(t) ? t : kInf;
  }
  const double disc = b * b - 4 * a * c;
  if (disc < 0)
    return kInf;
  const double s = std::sqrt(disc);
  double t1 = (-b - s) / (2 * a), t2 = (-b + s) / (2 * a);
  if (t1 > t2)
    std::swap(t1, t2);
  if (t1 > 0 && accept(t1))
    return t1;
  if (t2 > 0 && accept(t2))
    return t2;
  return kInf;
}

// Ray parameter t (point t * ray) of the first hit of ray with primitive, or inf.
double intersect(const ScenePrimitive& prim, const Eigen::Vector3d& ray) {
  const PrimitiveShape& s = prim.shape;
  switch (s.quadric_class) {
    case QuadricClass::kPlane: {
      const double denom = s.direction.dot(ray);
      if (std::abs(denom) < 1e-12)
        return kInf;
      const double t = s.direction.dot(s.point) / denom;
      if (t <= 0)
        return kInf;
      if (prim.plane_half_size > 0 &&
          ((t * ray - s.point).cwiseAbs().maxCoeff() > prim.plane_half_size))
        return kInf;
      return t;
    }
    case QuadricClass::kSphere: {
      const Eigen::Vector3d oc = -s.point;
      return nearestRoot(ray.squaredNorm(), 2 * ray.dot(oc), oc.squaredNorm() - s.size * s.size,
                         [](double) { return true; });
    }
    case QuadricClass::kCylinder: {
      const Eigen::Vector3d& d = s.direction;
      const Eigen::Vector3d o = -s.point;  // ray origin relative to the axis point
      const Eigen::Vector3d rp = ray - d.dot(ray) * d, op = o - d.dot(o) * d;
      auto within = [&](double t) {
        const double h = d.dot(o + t * ray);
        return h >= prim.axis_min && h <= prim.axis_max;
      };
      return nearestRoot(rp.squaredNorm(), 2 * rp.dot(op), op.squaredNorm() - s.size * s.size,
                         within);
    }
    case QuadricClass::kCone: {
      const Eigen::Vector3d& d = s.direction;
      const Eigen::Vector3d o = -s.point;  // ray origin relative to the apex
      const double c2 = std::cos(s.size) * std::cos(s.size);
      const double dr = d.dot(ray), dov = d.dot(o);
      auto within = [&](double t) {
        const double h = d.dot(o + t * ray);
        return h >= prim.axis_min && h <= prim.axis_max && h > 0;
      };
      // (d.(o + t r))^2 = cos^2 |o + t r|^2
      return nearestRoot(dr * dr - c2 * ray.squaredNorm(), 2 * (dr * dov - c2 * ray.dot(o)),
                         dov * dov - c2 * o.squaredNorm(), within);
    }
    default:
      return kInf;
  }
}

}  // namespace

PrimitiveRendering renderPrimitives(const std::vector<ScenePrimitive>& scene, const CameraIntrinsics& k,
                               const RenderParams& params) {
  PrimitiveRendering frame;
  frame.depth =
      cv::Mat(k.height, k.width, CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  frame.truth = cv::Mat::zeros(k.height, k.width, CV_16UC1);
  std::mt19937 rng(params.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector3d ray((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      double best = kInf;
      int best_index = -1;
      for (std::size_t i = 0; i < scene.size(); ++i) {
        const double t = intersect(scene[i], ray);
        if (t < best) {
          best = t;
          best_index = static_cast<int>(i);
        }
      }
      if (best_index < 0 || best > params.max_range)
        continue;
      double z = best;  // ray has unit z, so t is the depth
      z += params.noise_factor * z * z * gauss(rng);
      if (params.quantization_factor > 0) {
        const double q = params.quantization_factor * z * z;
        z = q * std::round(z / q);
      }
      frame.depth.at<float>(v, u) = static_cast<float>(z);
      frame.truth.at<std::uint16_t>(v, u) = static_cast<std::uint16_t>(best_index + 1);
    }
  }
  return frame;
}

}  // namespace quadric_slam
