#include "quadric_slam/frontend/cgal_shape_detector.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Random.h>
#include <CGAL/Shape_detection/Efficient_RANSAC.h>
#include <CGAL/property_map.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

namespace quadric_slam {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
// The input index travels with each point: Efficient RANSAC reorders its input range (octree).
using PointWithNormal = std::tuple<Kernel::Point_3, Kernel::Vector_3, int>;
using PwnVector = std::vector<PointWithNormal>;
using PointMap = CGAL::Nth_of_tuple_property_map<0, PointWithNormal>;
using NormalMap = CGAL::Nth_of_tuple_property_map<1, PointWithNormal>;
using Traits =
    CGAL::Shape_detection::Efficient_RANSAC_traits<Kernel, PwnVector, PointMap, NormalMap>;
using EfficientRansac = CGAL::Shape_detection::Efficient_RANSAC<Traits>;

// CGAL's connected_component() labels a bitmap over the shape's 2D parameter space, of
// ceil(u range / cluster_epsilon) x ceil(v range / cluster_epsilon) cells, without checking that
// size: a candidate with a huge radius, or with NaN parameters (a sample on a cylinder's axis),
// makes the product overflow or its conversion undefined, and the labelling writes out of bounds
// (found by the hostile-input fuzz: a real-looking depth image with four flipped bytes). Such a
// candidate is clustered with CGAL's kd-tree search instead, which needs no grid; every other
// candidate keeps CGAL's grid, so ordinary results do not change.
template <class CgalShape>
class BoundedGridShape : public CgalShape {
 public:
  using FT = typename CgalShape::FT;

 protected:
  std::size_t connected_component(std::vector<std::size_t>& indices, FT cluster_epsilon) override {
    if (!indices.empty() && this->supports_connected_component() &&
        !gridIsBounded(indices.size(), cluster_epsilon))
      return this->connected_component_kdTree(indices, cluster_epsilon);
    return CgalShape::connected_component(indices, cluster_epsilon);
  }

 private:
  // At most this many cells (4 bytes each): a 20 m x 20 m patch at 1 cm.
  static constexpr double kMaxGridCells = 4e6;

  bool gridIsBounded(std::size_t count, FT cluster_epsilon) const {
    FT min[] = {0, 0}, max[] = {0, 0};
    std::vector<std::pair<FT, FT>> parameter_space(count);
    FT epsilon = cluster_epsilon;  // parameters() may adjust its copy, as CGAL's own call does
    this->parameters(this->m_indices, parameter_space, epsilon, min, max);
    const double u = (max[0] - min[0]) / epsilon;
    const double v = (max[1] - min[1]) / epsilon;
    return std::isfinite(u) && std::isfinite(v) && u >= 0 && v >= 0 &&
           (u + 1) * (v + 1) <= kMaxGridCells;
  }
};

using CgalPlane = BoundedGridShape<CGAL::Shape_detection::Plane<Traits>>;
using CgalSphere = BoundedGridShape<CGAL::Shape_detection::Sphere<Traits>>;
using CgalCylinder = BoundedGridShape<CGAL::Shape_detection::Cylinder<Traits>>;
using CgalCone = BoundedGridShape<CGAL::Shape_detection::Cone<Traits>>;

Eigen::Vector3d toEigen(const Kernel::Point_3& p) {
  return Eigen::Vector3d(p.x(), p.y(), p.z());
}
Eigen::Vector3d toEigen(const Kernel::Vector_3& v) {
  return Eigen::Vector3d(v.x(), v.y(), v.z());
}

void require(bool ok, const std::string& message) {
  if (!ok)
    throw std::invalid_argument("CgalShapeDetector: " + message);
}

}  // namespace

void CgalShapeDetector::Params::validate() const {
  require(probability > 0 && probability < 1,
          "probability must be in (0, 1), got " + std::to_string(probability));
  require(min_points >= 4, "min_points must be >= 4, got " + std::to_string(min_points));
  require(epsilon > 0, "epsilon must be > 0 m, got " + std::to_string(epsilon));
  require(cluster_epsilon > 0,
          "cluster_epsilon must be > 0 m, got " + std::to_string(cluster_epsilon));
  require(normal_threshold > 0 && normal_threshold < 1,
          "normal_threshold must be in (0, 1), got " + std::to_string(normal_threshold));
  require(planes || spheres || cylinders || cones, "at least one shape type must be enabled");
}

CgalShapeDetector::CgalShapeDetector(const Params& params) : params_(params) {
  params_.validate();
}

std::vector<CgalShapeDetector::Shape> CgalShapeDetector::detect(
    const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals) const {
  if (points.size() != normals.size())
    throw std::invalid_argument("CgalShapeDetector: points and normals differ in length");
  std::vector<Shape> shapes;
  if (static_cast<int>(points.size()) < params_.min_points)
    return shapes;
  PwnVector pwn;
  pwn.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    pwn.emplace_back(Kernel::Point_3(points[i].x(), points[i].y(), points[i].z()),
                     Kernel::Vector_3(normals[i].x(), normals[i].y(), normals[i].z()),
                     static_cast<int>(i));
  }
  // CGAL draws its samples from CGAL::get_default_random(); reseed it for repeatable results.
  CGAL::get_default_random() = CGAL::Random(params_.random_seed);
  EfficientRansac ransac;
  ransac.set_input(pwn);
  if (params_.planes)
    ransac.add_shape_factory<CgalPlane>();
  if (params_.spheres)
    ransac.add_shape_factory<CgalSphere>();
  if (params_.cylinders)
    ransac.add_shape_factory<CgalCylinder>();
  if (params_.cones)
    ransac.add_shape_factory<CgalCone>();
  ransac.preprocess();
  EfficientRansac::Parameters parameters;
  parameters.probability = params_.probability;
  parameters.min_points = static_cast<std::size_t>(params_.min_points);
  parameters.epsilon = params_.epsilon;
  parameters.cluster_epsilon = params_.cluster_epsilon;
  parameters.normal_threshold = params_.normal_threshold;
  ransac.detect(parameters);

  for (const auto& detected : ransac.shapes()) {
    Shape shape;
    for (std::size_t k : detected->indices_of_assigned_points())
      shape.indices.push_back(std::get<2>(pwn[k]));
    if (shape.indices.empty())
      continue;
    if (const auto* plane = dynamic_cast<const CgalPlane*>(detected.get())) {
      const Kernel::Plane_3 p = static_cast<Kernel::Plane_3>(*plane);
      const Eigen::Vector3d n(p.a(), p.b(), p.c());
      shape.shape = PrimitiveShape::plane(n, -p.d() / n.norm());
    } else if (const auto* sphere = dynamic_cast<const CgalSphere*>(detected.get())) {
      shape.shape = PrimitiveShape::sphere(toEigen(sphere->center()), sphere->radius());
    } else if (const auto* cylinder = dynamic_cast<const CgalCylinder*>(detected.get())) {
      const Kernel::Line_3 axis = cylinder->axis();
      shape.shape = PrimitiveShape::cylinder(toEigen(axis.point()), toEigen(axis.to_vector()),
                                             cylinder->radius());
    } else if (const auto* cone = dynamic_cast<const CgalCone*>(detected.get())) {
      const Eigen::Vector3d apex = toEigen(cone->apex());
      Eigen::Vector3d axis = toEigen(cone->axis()).normalized();
      double along = 0;
      for (int i : shape.indices)
        along += axis.dot(points[i] - apex);
      if (along < 0)
        axis = -axis;
      shape.shape = PrimitiveShape::cone(apex, axis, cone->angle());
    } else {
      continue;
    }
    shapes.push_back(std::move(shape));
  }
  return shapes;
}

}  // namespace quadric_slam
