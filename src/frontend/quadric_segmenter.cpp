#include "quadric_slam/frontend/quadric_segmenter.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "quadric_slam/frontend/boundary_labels.h"
#include "quadric_slam/frontend/central_quadric.h"
#include "quadric_slam/frontend/cgal_shape_detector.h"
#include "quadric_slam/frontend/ellipsoid_candidate.h"
#include "quadric_slam/frontend/general_quadric_fit.h"
#include "quadric_slam/frontend/parallel_chunks.h"
#include "quadric_slam/geometry/symmetry.h"

namespace quadric_slam {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok)
    throw std::invalid_argument("QuadricSegmenter: " + message);
}

std::string str(double value) {
  return std::to_string(value);
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

Eigen::Vector3d pointOf(const pcl::PointNormal& p) {
  return Eigen::Vector3d(p.x, p.y, p.z);
}
Eigen::Vector3d normalOf(const pcl::PointNormal& p) {
  return Eigen::Vector3d(p.normal_x, p.normal_y, p.normal_z);
}

std::vector<Eigen::Vector3d> pointsOf(const pcl::PointCloud<pcl::PointNormal>& cloud,
                                      const std::vector<int>& indices) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(indices.size());
  for (int i : indices)
    points.push_back(pointOf(cloud.points[i]));
  return points;
}

double medianDepth(const pcl::PointCloud<pcl::PointNormal>& cloud, const std::vector<int>& idx) {
  std::vector<float> z;
  z.reserve(idx.size());
  for (int i : idx)
    z.push_back(cloud.points[i].z);
  std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
  return z[z.size() / 2];
}

// Everything the segmenter shares between its steps for one frame.
struct Frame {
  const pcl::PointCloud<pcl::PointNormal>& cloud;
  int width, height;
  std::vector<std::uint8_t> valid, used;
};

// Pixels of the frame's free points inside roi that lie within the distance threshold of shape
// and whose normal agrees; the largest 4-connected component of them, with the large components on
// the surface's other face.
std::vector<int> assignLargestComponent(const Frame& frame, const PrimitiveShape& shape,
                                        const ImageRoi& roi, const QuadricSegmenter::Params& p) {
  const double cos_angle = std::cos(p.curved_max_normal_angle);
  const int x0 = roi.x_offset, y0 = roi.y_offset, w = roi.width, h = roi.height;
  std::vector<std::uint8_t> candidate(static_cast<std::size_t>(w) * h, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int i = (y + y0) * frame.width + (x + x0);
      if (!frame.valid[i] || frame.used[i])
        continue;
      const pcl::PointNormal& q = frame.cloud.points[i];
      const Eigen::Vector3d point = pointOf(q);
      if (std::abs(shape.distance(point)) >
          depthThreshold(q.z, p.planes.distance_factor, p.planes.min_distance))
        continue;
      if (std::abs(shape.normalAt(point).dot(normalOf(q))) < cos_angle)
        continue;
      candidate[y * w + x] = 1;
    }
  }
  std::vector<int> best, component, stack;
  std::vector<std::vector<int>> large;  // components of at least min_curved_points
  std::vector<std::uint8_t> seen(candidate.size(), 0);
  for (int start = 0; start < static_cast<int>(candidate.size()); ++start) {
    if (!candidate[start] || seen[start])
      continue;
    component.clear();
    stack.assign(1, start);
    seen[start] = 1;
    while (!stack.empty()) {
      const int k = stack.back();
      stack.pop_back();
      const int x = k % w, y = k / w;
      component.push_back((y + y0) * frame.width + (x + x0));
      const float zk = frame.cloud.points[(y + y0) * frame.width + (x + x0)].z;
      const int neighbours[4] = {x > 0 ? k - 1 : -1, x + 1 < w ? k + 1 : -1, y > 0 ? k - w : -1,
                                 y + 1 < h ? k + w : -1};
      for (int m : neighbours) {
        if (m < 0 || !candidate[m] || seen[m])
          continue;
        const float zm = frame.cloud.points[(m / w + y0) * frame.width + (m % w + x0)].z;
        if (std::abs(zm - zk) > p.planes.max_depth_jump_factor * zk)
          continue;
        seen[m] = 1;
        stack.push_back(m);
      }
    }
    if (static_cast<int>(component.size()) >= p.min_curved_points)
      large.push_back(component);
    if (component.size() > best.size())
      best.swap(component);
  }
  // The other face of an open surface joins: an open cylinder's outer wall and, over the rim, its
  // inner wall are separate components (a depth jump at the rim) whose measured normals, turned
  // to the camera, point out of and into the surface. Components on the same face as the largest
  // (a neighbouring object of the same size and pose) do not.
  const auto outward = [&](const std::vector<int>& indices) {
    int out = 0;
    for (int i : indices) {
      const pcl::PointNormal& q = frame.cloud.points[i];
      out += shape.normalAt(pointOf(q)).dot(normalOf(q)) > 0;
    }
    return 2 * out > static_cast<int>(indices.size());
  };
  if (large.size() > 1) {
    const auto largest =
        std::max_element(large.begin(), large.end(),
                         [](const auto& a, const auto& b) { return a.size() < b.size(); });
    const bool largest_outward = outward(*largest);
    std::vector<int> joined = *largest;
    for (auto other = large.begin(); other != large.end(); ++other)
      if (other != largest && outward(*other) != largest_outward)
        joined.insert(joined.end(), other->begin(), other->end());
    return joined;
  }
  return best;
}

// 4-connected components of the valid, unused points (depth jumps break connectivity).
std::vector<std::vector<int>> freeComponents(const Frame& frame,
                                             const QuadricSegmenter::Params& p) {
  std::vector<std::vector<int>> components;
  std::vector<std::uint8_t> seen(frame.valid.size(), 0);
  std::vector<int> stack;
  const auto& points = frame.cloud.points;
  for (int start = 0; start < static_cast<int>(seen.size()); ++start) {
    if (seen[start] || !frame.valid[start] || frame.used[start])
      continue;
    std::vector<int> component;
    stack.assign(1, start);
    seen[start] = 1;
    while (!stack.empty()) {
      const int k = stack.back();
      stack.pop_back();
      component.push_back(k);
      const int u = k % frame.width, v = k / frame.width;
      const int neighbours[4] = {u > 0 ? k - 1 : -1, u + 1 < frame.width ? k + 1 : -1,
                                 v > 0 ? k - frame.width : -1,
                                 v + 1 < frame.height ? k + frame.width : -1};
      for (int m : neighbours) {
        if (m < 0 || seen[m] || !frame.valid[m] || frame.used[m])
          continue;
        if (std::abs(points[m].z - points[k].z) > p.planes.max_depth_jump_factor * points[k].z)
          continue;
        seen[m] = 1;
        stack.push_back(m);
      }
    }
    components.push_back(std::move(component));
  }
  return components;
}

ImageRoi roiOf(const std::vector<int>& indices, int width) {
  int x_min = std::numeric_limits<int>::max(), y_min = x_min, x_max = -1, y_max = -1;
  for (int i : indices) {
    const int x = i % width, y = i / width;
    x_min = std::min(x_min, x);
    x_max = std::max(x_max, x);
    y_min = std::min(y_min, y);
    y_max = std::max(y_max, y);
  }
  ImageRoi roi;
  if (x_max < 0)
    return roi;
  roi.x_offset = x_min;
  roi.y_offset = y_min;
  roi.width = x_max - x_min + 1;
  roi.height = y_max - y_min + 1;
  return roi;
}

ImageRoi grown(const ImageRoi& roi, int margin, int width, int height) {
  ImageRoi g;
  g.x_offset = std::max(0, roi.x_offset - margin);
  g.y_offset = std::max(0, roi.y_offset - margin);
  g.width = std::min(width, roi.x_offset + roi.width + margin) - g.x_offset;
  g.height = std::min(height, roi.y_offset + roi.height + margin) - g.y_offset;
  return g;
}

// The smallest box holding both.
ImageRoi unite(const ImageRoi& a, const ImageRoi& b) {
  ImageRoi u;
  u.x_offset = std::min(a.x_offset, b.x_offset);
  u.y_offset = std::min(a.y_offset, b.y_offset);
  u.width = std::max(a.x_offset + a.width, b.x_offset + b.width) - u.x_offset;
  u.height = std::max(a.y_offset + a.height, b.y_offset + b.height) - u.y_offset;
  return u;
}

// Cylinder through the points around the cone's axis (the degenerate thin cone).
PrimitiveShape cylinderFromCone(const PrimitiveShape& cone,
                                const std::vector<Eigen::Vector3d>& points) {
  const Eigen::Vector3d d = cone.direction;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& q : points)
    mean += q;
  mean /= static_cast<double>(points.size());
  const Eigen::Vector3d on_axis = cone.point + d.dot(mean - cone.point) * d;
  double radius = 0;
  for (const auto& q : points) {
    const Eigen::Vector3d v = q - on_axis;
    radius += (v - d.dot(v) * d).norm();
  }
  return PrimitiveShape::cylinder(on_axis, d, radius / points.size());
}

// A cone through the points of a cylinder fit: the radius as a straight line of the axial
// coordinate, rho = r0 + k z; none (half angle 0) when k vanishes.
PrimitiveShape coneFromCylinder(const PrimitiveShape& cylinder,
                                const std::vector<Eigen::Vector3d>& points) {
  const Eigen::Vector3d d = cylinder.direction;
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  for (const auto& q : points) {
    const Eigen::Vector3d v = q - cylinder.point;
    const double z = d.dot(v);
    const double rho = (v - z * d).norm();
    const Eigen::Vector2d row(1.0, z);
    A += row * row.transpose();
    b += row * rho;
  }
  PrimitiveShape cone = PrimitiveShape::cone(cylinder.point, d, 0.0);
  if (std::abs(A.determinant()) < 1e-18)
    return cone;
  const Eigen::Vector2d x = A.ldlt().solve(b);
  const double r0 = x[0], k = x[1];
  if (!(std::abs(k) > 1e-6) || !std::isfinite(r0))
    return cone;
  // Apex where the radius vanishes; the axis points from it into the opening.
  cone.point = cylinder.point - (r0 / k) * d;
  cone.direction = k > 0 ? d : Eigen::Vector3d(-d);
  cone.size = std::atan(std::abs(k));
  return cone;
}

// A cone from points and their normals: every tangent plane passes through the apex
// (n_i . (apex - p_i) = 0, linear least squares), and the normals lie on a small circle around
// the axis (the least-variance direction of the centred normals). Catches the side view of a cone,
// whose visible strip a tilted cylinder also fits. Half angle 0 when degenerate.
PrimitiveShape coneFromNormals(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<Eigen::Vector3d>& normals) {
  PrimitiveShape cone = PrimitiveShape::cone(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0);
  if (points.size() < 10 || points.size() != normals.size())
    return cone;
  Eigen::Vector3d mean_n = Eigen::Vector3d::Zero();
  for (const auto& n : normals)
    mean_n += n;
  mean_n /= static_cast<double>(normals.size());
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero(), A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    C += (normals[i] - mean_n) * (normals[i] - mean_n).transpose();
    A += normals[i] * normals[i].transpose();
    b += normals[i] * normals[i].dot(points[i]);
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(C);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig_a(A);
  if (eig.info() != Eigen::Success || eig_a.info() != Eigen::Success ||
      eig_a.eigenvalues()[0] < 1e-6 * eig_a.eigenvalues()[2])
    return cone;
  Eigen::Vector3d axis = eig.eigenvectors().col(0);
  const Eigen::Vector3d apex = A.ldlt().solve(b);
  double mean_z = 0;
  for (const auto& q : points)
    mean_z += axis.dot(q - apex);
  if (mean_z < 0)
    axis = -axis;
  double angle = 0;
  for (const auto& q : points) {
    const Eigen::Vector3d v = q - apex;
    const double z = axis.dot(v);
    angle += std::atan2((v - z * axis).norm(), z);
  }
  cone.point = apex;
  cone.direction = axis;
  cone.size = angle / static_cast<double>(points.size());
  return cone;
}

// A cylinder of the given curvature (1/radius) from points and their normals: the normals are
// perpendicular to the axis (the least-variance direction of the normals, uncentred), and the axis
// runs through p -+ r n (the sign that gathers these feet best: normals towards the camera point
// out of a cylinder's outside and into its inside). Radius 0 when degenerate.
PrimitiveShape cylinderFromNormals(const std::vector<Eigen::Vector3d>& points,
                                   const std::vector<Eigen::Vector3d>& normals, double curvature) {
  PrimitiveShape cylinder =
      PrimitiveShape::cylinder(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0);
  if (points.size() < 10 || points.size() != normals.size() || !(curvature > 0))
    return cylinder;
  Eigen::Matrix3d N = Eigen::Matrix3d::Zero();
  for (const auto& n : normals)
    N += n * n.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(N);
  if (eig.info() != Eigen::Success)
    return cylinder;
  const Eigen::Vector3d axis = eig.eigenvectors().col(0);
  const double radius = 1.0 / curvature;
  double best_scatter = std::numeric_limits<double>::max();
  for (const double sign : {-1.0, 1.0}) {
    // Feet on the axis, projected onto the plane perpendicular to it.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    double sum_sq = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      Eigen::Vector3d foot = points[i] + sign * radius * normals[i];
      foot -= axis.dot(foot) * axis;
      mean += foot;
      sum_sq += foot.squaredNorm();
    }
    mean /= static_cast<double>(points.size());
    const double scatter = sum_sq / static_cast<double>(points.size()) - mean.squaredNorm();
    if (scatter < best_scatter) {
      best_scatter = scatter;
      cylinder = PrimitiveShape::cylinder(mean, axis, radius);
    }
  }
  return cylinder;
}

// The largest principal curvature of a curved shape over its support (1/m): 1/r for a sphere or
// cylinder, cos(half angle) / (distance to the axis) for a cone (mean over the points).
double shapeCurvature(const PrimitiveShape& shape, const std::vector<Eigen::Vector3d>& points) {
  if (shape.quadric_class != QuadricClass::kCone)
    return shape.size > 0 ? 1.0 / shape.size : 0.0;
  const double cos_half_angle = std::cos(shape.size);
  double sum = 0;
  for (const auto& q : points) {
    const Eigen::Vector3d v = q - shape.point;
    sum += cos_half_angle / std::max((v - shape.direction.dot(v) * shape.direction).norm(), 1e-3);
  }
  return points.empty() ? 0.0 : sum / static_cast<double>(points.size());
}

// Whether the measured normals bend like the shape: curvature (patchCurvature of the support) above
// the plane grower's flatness limit and within a factor of 2 of the shape's own curvature.
bool normalsBendLike(double curvature, double shape_curvature, const QuadricSegmenter::Params& p) {
  return curvature > p.planes.max_curvature && curvature > 0.5 * shape_curvature &&
         curvature < 2.0 * shape_curvature;
}

// Least share of neighbouring points (4-neighbours on the grid) on which the general quadric's
// gradient must take the same side of the measured normal for the quadric to be a surface through
// the points: about 1 on a real surface (a single sheet, or two that meet along a line such as a
// dihedral edge), about 1/2 when two close sheets split the noise band point by point.
constexpr double kMinSheetCoherence = 0.75;

// Whether the general quadric is a surface through the points rather than a fit of their noise
// band: neighbouring points lie on the same sheet (see kMinSheetCoherence).
bool generalQuadricIsSurface(const GeneralQuadricFit& general, const Frame& frame,
                             const std::vector<int>& indices, const ImageRoi& roi) {
  // Side of the measured normal the gradient takes, per pixel of the roi: 0 none, 1, 2.
  std::vector<std::uint8_t> side(static_cast<std::size_t>(roi.width) * roi.height, 0);
  for (int i : indices) {
    const pcl::PointNormal& q = frame.cloud.points[i];
    const double c = general.gradientDirection(pointOf(q)).dot(normalOf(q));
    const int x = i % frame.width - roi.x_offset, y = i / frame.width - roi.y_offset;
    side[static_cast<std::size_t>(y) * roi.width + x] = c > 0 ? 1 : c < 0 ? 2 : 0;
  }
  int same = 0, pairs = 0;
  for (int y = 0; y < roi.height; ++y) {
    for (int x = 0; x < roi.width; ++x) {
      const std::uint8_t s = side[static_cast<std::size_t>(y) * roi.width + x];
      if (s == 0)
        continue;
      for (const std::uint8_t t :
           {x + 1 < roi.width ? side[static_cast<std::size_t>(y) * roi.width + x + 1]
                              : std::uint8_t(0),
            y + 1 < roi.height ? side[static_cast<std::size_t>(y + 1) * roi.width + x]
                               : std::uint8_t(0)}) {
        if (t == 0)
          continue;
        ++pairs;
        same += s == t;
      }
    }
  }
  return pairs > 0 && same >= kMinSheetCoherence * pairs;
}

bool plausible(const PrimitiveShape& s, const QuadricSegmenter::Params& p) {
  if (!s.point.allFinite() || !s.direction.allFinite() || !std::isfinite(s.size))
    return false;
  switch (s.quadric_class) {
    case QuadricClass::kSphere:
      return s.size >= p.min_sphere_radius && s.size <= p.max_sphere_radius;
    case QuadricClass::kCylinder:
      return s.size >= p.min_cylinder_radius && s.size <= p.max_cylinder_radius;
    case QuadricClass::kCone:
      return s.size >= p.min_cone_half_angle && s.size <= p.max_cone_half_angle;
    default:
      return true;
  }
}

// The ellipsoid of a segment whose shape test found shape residuals (general: the general quadric
// fitted to its points): the fit's ellipsoid (ellipsoid_candidate.h), then twice the curved
// shapes' re-assignment of the free pixels near it (in the candidate's roi) and a refinement of
// its 9 minimal parameters on them. None when the fit is no plausible ellipsoid, the refinement
// fails or leaves the plausible sizes, the support is too small, or the RMS exceeds the curved
// shapes' limit (max_rms_factor). *indices receives the support.
std::optional<ShapeRefiner::Result> detectEllipsoid(const Frame& frame,
                                                    const GeneralQuadricFit& general,
                                                    const ImageRoi& roi,
                                                    const QuadricSegmenter::Params& p,
                                                    const ShapeRefiner& refiner,
                                                    std::vector<int>* indices) {
  const std::optional<PrimitiveShape> start =
      ellipsoidCandidate(general, p.min_sphere_radius, p.max_sphere_radius);
  if (!start)
    return std::nullopt;
  ShapeRefiner::Result fit;
  fit.shape = *start;
  for (int pass = 0; pass < 2; ++pass) {
    *indices = assignLargestComponent(frame, fit.shape, roi, p);
    if (static_cast<int>(indices->size()) < p.min_curved_points)
      return std::nullopt;
    fit = refiner.refine(fit.shape, pointsOf(frame.cloud, *indices));
    if (!fit.ok ||
        !plausibleEllipsoid(fit.shape.general_quadric, p.min_sphere_radius, p.max_sphere_radius))
      return std::nullopt;
  }
  const double z = medianDepth(frame.cloud, *indices);
  if (fit.rms >
      p.max_rms_factor * depthThreshold(z, p.planes.distance_factor, p.planes.min_distance))
    return std::nullopt;
  return fit;
}

// Moves a curved shape's origin to the foot of the supporting points' centroid on its axis (the
// cylinder's point is free along the axis) so that extents are centred. A general quadric is put
// in its canonical axis order (central_quadric.h) instead: the refinement may have swapped the
// lengths of two axes.
void centreOnSupport(PrimitiveShape& s, const std::vector<Eigen::Vector3d>& points) {
  if (points.empty())
    return;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& q : points)
    mean += q;
  mean /= static_cast<double>(points.size());
  if (s.quadric_class == QuadricClass::kCylinder) {
    s.point += s.direction.dot(mean - s.point) * s.direction;
  } else if (s.quadric_class == QuadricClass::kPlane) {
    s.point = mean - s.direction.dot(mean - s.point) * s.direction;
  } else if (s.quadric_class == QuadricClass::kGeneral) {
    s = PrimitiveShape::general(withCanonicalAxisOrder(s.general_quadric));
  }
}

}  // namespace

void QuadricSegmenter::Params::validate() const {
  require(min_range > 0 && min_range < max_range,
          "min_range and max_range must satisfy 0 < min_range < max_range (m), got " +
              str(min_range) + ", " + str(max_range));
  require(decimation >= 1 && decimation <= 8,
          "decimation must be in [1, 8], got " + std::to_string(decimation));
  require(threads >= 1 && threads <= 64,
          "threads must be in [1, 64], got " + std::to_string(threads));
  require(boundary_rings >= 0 && boundary_rings <= 10,
          "boundary_rings must be in [0, 10], got " + std::to_string(boundary_rings));
  planes.validate();
  refiner.validate();
  require(cgal_stride >= 1 && cgal_stride <= 16,
          "cgal_stride must be in [1, 16], got " + std::to_string(cgal_stride));
  require(cgal_probability > 0 && cgal_probability < 1,
          "cgal_probability must be in (0, 1), got " + str(cgal_probability));
  require(quadric_rms_ratio >= 1, "quadric_rms_ratio must be >= 1, got " + str(quadric_rms_ratio));
  require(cgal_min_points >= 4,
          "cgal_min_points must be >= 4, got " + std::to_string(cgal_min_points));
  require(cgal_epsilon > 0, "cgal_epsilon must be > 0 m, got " + str(cgal_epsilon));
  require(cgal_cluster_epsilon > 0,
          "cgal_cluster_epsilon must be > 0 m, got " + str(cgal_cluster_epsilon));
  require(cgal_max_points >= 100,
          "cgal_max_points must be >= 100, got " + std::to_string(cgal_max_points));
  require(cgal_min_fraction >= 0 && cgal_min_fraction < 1,
          "cgal_min_fraction must be in [0, 1), got " + str(cgal_min_fraction));
  require(cgal_normal_threshold > 0 && cgal_normal_threshold < 1,
          "cgal_normal_threshold must be in (0, 1), got " + str(cgal_normal_threshold));
  require(curved_max_normal_angle > 0 && curved_max_normal_angle < M_PI / 2,
          "curved_max_normal_angle must be in (0, pi/2) rad, got " + str(curved_max_normal_angle));
  require(min_curved_points >= 4,
          "min_curved_points must be >= 4, got " + std::to_string(min_curved_points));
  require(min_sphere_radius > 0 && min_sphere_radius < max_sphere_radius,
          "sphere radii must satisfy 0 < min_sphere_radius < max_sphere_radius (m)");
  require(min_cylinder_radius > 0 && min_cylinder_radius < max_cylinder_radius,
          "cylinder radii must satisfy 0 < min_cylinder_radius < max_cylinder_radius (m)");
  require(min_cone_half_angle > 0 && min_cone_half_angle < max_cone_half_angle &&
              max_cone_half_angle < M_PI / 2,
          "cone half angles must satisfy 0 < min_cone_half_angle < max_cone_half_angle < pi/2");
  require(plane_rms_ratio >= 1, "plane_rms_ratio must be >= 1, got " + str(plane_rms_ratio));
  require(cylinder_rms_ratio >= 1,
          "cylinder_rms_ratio must be >= 1, got " + str(cylinder_rms_ratio));
  require(general_model_sigma >= 0 && general_model_sigma <= 0.1,
          "general_model_sigma must be in [0, 0.1] m, got " + str(general_model_sigma));
  require(max_rms_factor > 0 && max_rms_factor <= 10,
          "max_rms_factor must be in (0, 10], got " + str(max_rms_factor));
}

QuadricSegmenter::QuadricSegmenter(const Params& params) : params_(params) {
  params_.validate();
}

namespace {

// The segmentation proper, on the grid of the cloud it is given.
Segmentation segmentGrid(const pcl::PointCloud<pcl::PointNormal>& cloud,
                         const QuadricSegmenter::Params& p) {
  Segmentation result;
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  result.labels = cv::Mat::zeros(height, width, CV_16UC1);
  if (cloud.empty())
    return result;

  Frame frame{cloud, width, height, std::vector<std::uint8_t>(cloud.size(), 0),
              std::vector<std::uint8_t>(cloud.size(), 0)};
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const pcl::PointNormal& q = cloud.points[i];
    frame.valid[i] = std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
                     std::isfinite(q.normal_x) && std::isfinite(q.normal_y) &&
                     std::isfinite(q.normal_z) && q.z >= p.min_range && q.z <= p.max_range;
  }

  const ShapeRefiner refiner(p.refiner);
  auto accept = [&](const PrimitiveShape& shape, const std::vector<int>& indices,
                    const ShapeRefiner::Result& fit) {
    QuadricDetection detection;
    detection.shape = fit.shape;
    const std::vector<Eigen::Vector3d> points = pointsOf(cloud, indices);
    centreOnSupport(detection.shape, points);
    (void)shape;
    detection.covariance = fit.covariance;
    // The fit's covariance is about fit.shape.quadric(); re-centring moves the frame by a symmetry
    // element G (a slide along the cylinder axis; a relabelling of a general quadric's axes), so
    // re-express it: C' = M C M^T, M = Ad(G^-1).
    const Eigen::Isometry3d G =
        fit.shape.quadric().pose().inverse() * detection.shape.quadric().pose();
    const int k = minimalDimension(detection.shape.quadric_class);
    if (fit.covariance.rows() == k && fit.covariance.cols() == k) {
      const Eigen::MatrixXd M = minimalAdjoint(detection.shape.quadric_class, G.inverse());
      detection.covariance = M * fit.covariance * M.transpose();
    }
    detection.num_points = static_cast<int>(indices.size());
    detection.fit_rms = rmsDistance(detection.shape, points);
    detection.label = static_cast<std::uint16_t>(result.detections.size() + 1);
    detection.roi = roiOf(indices, width);
    const Eigen::Isometry3d T_quadric_frame = detection.shape.quadric().pose().inverse();
    detection.extent_min = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
    detection.extent_max = -detection.extent_min;
    for (const auto& q : points) {
      const Eigen::Vector3d local = T_quadric_frame * q;
      detection.extent_min = detection.extent_min.cwiseMin(local);
      detection.extent_max = detection.extent_max.cwiseMax(local);
    }
    for (int i : indices) {
      frame.used[i] = 1;
      result.labels.at<std::uint16_t>(i / width, i % width) = detection.label;
    }
    result.detections.push_back(std::move(detection));
  };

  auto start = std::chrono::steady_clock::now();
  // 1. Planes from the image grid.
  const PlaneRegionGrower grower(p.planes);
  for (const PlaneRegionGrower::Region& region : grower.grow(cloud, frame.valid, frame.used)) {
    const ShapeRefiner::Result fit =
        refiner.evaluate(region.plane, pointsOf(cloud, region.indices));
    accept(fit.shape, region.indices, fit);
  }

  result.timings.planes_ms = msSince(start);
  start = std::chrono::steady_clock::now();

  // 2. Curved candidates from CGAL, run per image-grid connected component of the free points (on
  // a sub-sample): small inputs with a support threshold relative to their size converge in few
  // RANSAC rounds, and a shape never spans two separate objects.
  if (!(p.detect_spheres || p.detect_cylinders || p.detect_cones))
    return result;
  CgalShapeDetector::Params cgal;
  cgal.planes = true;  // absorbs small planar patches that would otherwise become wide cylinders
  cgal.spheres = p.detect_spheres;
  cgal.cylinders = p.detect_cylinders;
  cgal.cones = p.detect_cones;
  cgal.probability = p.cgal_probability;
  cgal.epsilon = p.cgal_epsilon;
  cgal.cluster_epsilon = p.cgal_cluster_epsilon;
  cgal.normal_threshold = p.cgal_normal_threshold;
  cgal.random_seed = p.random_seed;
  std::vector<Eigen::Vector3d> sample_points, sample_normals;
  std::vector<int> sample_pixel;
  // Each component's sample is a contiguous range of the sample arrays.
  struct ComponentJob {
    std::size_t first = 0;
    int count = 0;
    int min_points = 0;
    std::vector<CgalShapeDetector::Shape> shapes;
    std::exception_ptr error;
  };
  std::vector<ComponentJob> jobs;
  for (const std::vector<int>& component : freeComponents(frame, p)) {
    if (static_cast<int>(component.size()) < p.min_curved_points)
      continue;
    const std::size_t first = sample_points.size();
    // A stride that keeps the component's sample within cgal_max_points.
    const int stride = std::max(
        p.cgal_stride, static_cast<int>(std::ceil(
                           std::sqrt(static_cast<double>(component.size()) / p.cgal_max_points))));
    for (int i : component) {
      if ((i % width) % stride != 0 || (i / width) % stride != 0)
        continue;
      sample_points.push_back(pointOf(cloud.points[i]));
      sample_normals.push_back(normalOf(cloud.points[i]).normalized());
      sample_pixel.push_back(i);
    }
    ComponentJob job;
    job.first = first;
    job.count = static_cast<int>(sample_points.size() - first);
    job.min_points =
        std::max(p.cgal_min_points, static_cast<int>(std::ceil(p.cgal_min_fraction * job.count)));
    if (job.count < job.min_points) {
      sample_points.resize(first);
      sample_normals.resize(first);
      sample_pixel.resize(first);
      continue;
    }
    jobs.push_back(std::move(job));
  }
  auto detectComponent = [&](ComponentJob& job) {
    CgalShapeDetector::Params params = cgal;
    params.min_points = job.min_points;
    const std::vector<Eigen::Vector3d> points(sample_points.begin() + job.first,
                                              sample_points.begin() + job.first + job.count);
    const std::vector<Eigen::Vector3d> normals(sample_normals.begin() + job.first,
                                               sample_normals.begin() + job.first + job.count);
    job.shapes = CgalShapeDetector(params).detect(points, normals);
    // CGAL's planes only absorb flat patches. A plane on points whose normals bend (curvature above
    // the grower's max_curvature) is a curved surface whose sag the depth noise hides (a far,
    // narrow strip of a cylinder fits a plane within epsilon): it becomes a cylinder candidate
    // fitted to the normals (model selection may turn it into a cone or sphere).
    for (CgalShapeDetector::Shape& shape : job.shapes) {
      if (shape.shape.quadric_class != QuadricClass::kPlane)
        continue;
      std::vector<int> pixels;
      std::vector<Eigen::Vector3d> support, support_normals;
      for (int k : shape.indices) {
        pixels.push_back(sample_pixel[job.first + k]);
        support.push_back(points[k]);
        support_normals.push_back(normals[k]);
      }
      const double curvature = patchCurvature(cloud, pixels, shape.shape.direction);
      if (curvature <= p.planes.max_curvature)
        continue;
      // The cylinder the normals describe must fit the points better than the plane does (not so
      // on clutter, which stays absorbed by the plane).
      const PrimitiveShape cylinder = cylinderFromNormals(support, support_normals, curvature);
      if (plausible(cylinder, p) &&
          rmsDistance(cylinder, support) < rmsDistance(shape.shape, support))
        shape.shape = cylinder;
    }
    for (CgalShapeDetector::Shape& shape : job.shapes)
      for (int& k : shape.indices)
        k += static_cast<int>(job.first);
  };
  // The components are independent inputs: CGAL runs on them in parallel, each thread taking the
  // next component. CGAL's random generator is thread-local and reseeded per call, so the result
  // does not depend on the number of threads.
  std::atomic<std::size_t> next_job{0};
  forEachChunk(p.threads, p.threads, [&](int, int, int) {
    for (std::size_t j = next_job++; j < jobs.size(); j = next_job++) {
      try {
        detectComponent(jobs[j]);
      } catch (...) {  // rethrown on the calling thread below
        jobs[j].error = std::current_exception();
      }
    }
  });
  std::vector<CgalShapeDetector::Shape> candidates;
  for (ComponentJob& job : jobs) {
    if (job.error)
      std::rethrow_exception(job.error);
    for (CgalShapeDetector::Shape& shape : job.shapes)
      candidates.push_back(std::move(shape));
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
    return a.indices.size() > b.indices.size();
  });

  result.timings.ransac_points = static_cast<int>(sample_points.size());
  result.timings.ransac_candidates = static_cast<int>(candidates.size());
  result.timings.ransac_ms = msSince(start);
  start = std::chrono::steady_clock::now();

  // 3. Verify, refine and re-assign each curved candidate, biggest first.
  for (const CgalShapeDetector::Shape& candidate : candidates) {
    if (candidate.shape.quadric_class == QuadricClass::kPlane)
      continue;
    std::vector<Eigen::Vector3d> support;
    std::vector<int> pixels;
    for (int k : candidate.indices) {
      if (frame.used[sample_pixel[k]])
        continue;
      support.push_back(sample_points[k]);
      pixels.push_back(sample_pixel[k]);
    }
    if (static_cast<int>(support.size()) < p.cgal_min_points)
      continue;
    PrimitiveShape shape = candidate.shape;
    if (shape.quadric_class == QuadricClass::kCone && shape.size < p.min_cone_half_angle)
      shape = cylinderFromCone(shape, support);
    ShapeRefiner::Result fit = refiner.refine(shape, support);
    const ImageRoi roi = grown(roiOf(pixels, width), 4 * p.cgal_stride, width, height);

    std::vector<int> indices;
    for (int pass = 0; pass < 2; ++pass) {
      if (!plausible(fit.shape, p))
        break;
      indices = assignLargestComponent(frame, fit.shape, roi, p);
      if (static_cast<int>(indices.size()) < p.min_curved_points) {
        indices.clear();
        break;
      }
      const std::vector<Eigen::Vector3d> points = pointsOf(cloud, indices);
      fit = refiner.refine(fit.shape, points);
      // Model selection: a simpler class that fits almost as well wins (a thin cone is a
      // cylinder; a wide cone or a cylinder on a sphere cap is a sphere).
      if (fit.shape.quadric_class == QuadricClass::kCone) {
        const ShapeRefiner::Result as_cylinder =
            refiner.refine(cylinderFromCone(fit.shape, points), points);
        if (as_cylinder.rms < p.cylinder_rms_ratio * fit.rms && plausible(as_cylinder.shape, p))
          fit = as_cylinder;
      }
      if (fit.shape.quadric_class == QuadricClass::kCylinder && p.detect_cones) {
        std::vector<Eigen::Vector3d> normals;
        normals.reserve(indices.size());
        for (int i : indices)
          normals.push_back(normalOf(cloud.points[i]).normalized());
        const ShapeRefiner::Result cylinder = fit;
        for (const PrimitiveShape& start :
             {coneFromCylinder(cylinder.shape, points), coneFromNormals(points, normals)}) {
          if (!plausible(start, p))
            continue;
          const ShapeRefiner::Result as_cone = refiner.refine(start, points);
          if (p.cylinder_rms_ratio * as_cone.rms < cylinder.rms && as_cone.rms < fit.rms &&
              plausible(as_cone.shape, p))
            fit = as_cone;
        }
      }
      if (fit.shape.quadric_class != QuadricClass::kSphere && p.detect_spheres) {
        const ShapeRefiner::Result as_sphere = refiner.refine(fitSphereAlgebraic(points), points);
        if (as_sphere.rms < p.cylinder_rms_ratio * fit.rms && plausible(as_sphere.shape, p))
          fit = as_sphere;
      }
    }
    if (indices.empty() || !plausible(fit.shape, p))
      continue;
    const std::vector<Eigen::Vector3d> points = pointsOf(cloud, indices);
    // Degeneracy: a near-flat surface is a plane, not a curved primitive. Flat means what it means
    // to the plane region grower: the plane fits almost as well AND the normals do not bend (shape
    // operator at most the grower's max_curvature). The normals decide when the depth noise hides
    // the sag (a far cylinder seen over a narrow arc); without them such a surface would be
    // neither a plane (the grower rejects it as curved) nor a curved primitive.
    const PrimitiveShape plane = fitPlane(points);
    if (rmsDistance(plane, points) < p.plane_rms_ratio * fit.rms &&
        !normalsBendLike(patchCurvature(cloud, indices, plane.direction),
                         shapeCurvature(fit.shape, points), p))
      continue;
    // Shape test: residuals well above a general quadric's are shape (e.g. an ellipsoid), not
    // noise. Only when the general quadric is a surface through the points: when the depth noise
    // is large against the patch's curvature (a far, narrow strip of a cylinder), its 10
    // coefficients fit the noise band instead, with two close sheets that split neighbouring
    // points, and its RMS drops well below the noise that any true surface leaves. The primitive
    // is dropped; an ellipsoid found there is reported instead (before the primitive's RMS limit:
    // a sphere on an elongated ellipsoid may well exceed it).
    const GeneralQuadricFit general = fitGeneralQuadric(points);
    if (general.ok && fit.rms > p.quadric_rms_ratio * general.rms &&
        generalQuadricIsSurface(general, frame, indices, roiOf(indices, width))) {
      if (p.detect_general) {
        std::vector<int> general_indices;
        const std::optional<ShapeRefiner::Result> ellipsoid =
            detectEllipsoid(frame, general, unite(roi, grown(roiOf(indices, width),
                                                              4 * p.cgal_stride, width, height)),
                            p, refiner, &general_indices);
        if (ellipsoid)
          accept(ellipsoid->shape, general_indices, *ellipsoid);
      }
      continue;
    }
    const double z = medianDepth(cloud, indices);
    if (fit.rms >
        p.max_rms_factor * depthThreshold(z, p.planes.distance_factor, p.planes.min_distance))
      continue;
    accept(fit.shape, indices, fit);
  }
  result.timings.verify_ms = msSince(start);
  return result;
}

// The parameters of a grid decimated by d: counts of points scale with 1 / d^2, strides with 1 / d.
QuadricSegmenter::Params coarseParams(const QuadricSegmenter::Params& p, int d) {
  QuadricSegmenter::Params c = p;
  c.planes.min_points = std::max(3, p.planes.min_points / (d * d));
  c.planes.min_fragment_points = std::max(3, p.planes.min_fragment_points / (d * d));
  c.min_curved_points = std::max(4, p.min_curved_points / (d * d));
  c.planes.seed_stride = std::max(1, p.planes.seed_stride / d);
  c.cgal_stride = std::max(1, (p.cgal_stride + d / 2) / d);
  c.decimation = 1;
  return c;
}

bool validPoint(const pcl::PointNormal& q, const QuadricSegmenter::Params& p) {
  return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
         std::isfinite(q.normal_x) && std::isfinite(q.normal_y) && std::isfinite(q.normal_z) &&
         q.z >= p.min_range && q.z <= p.max_range;
}

// Full-resolution labels from a segmentation of the grid decimated by d: each valid pixel takes
// the label of a neighbouring coarse sample whose surface it fits (distance threshold and normal
// agreement, as on the coarse grid); support, ROI, extent and covariance follow the full-resolution
// points.
Segmentation upsample(const pcl::PointCloud<pcl::PointNormal>& cloud, Segmentation coarse, int d,
                      const QuadricSegmenter::Params& p) {
  Segmentation result;
  result.timings = coarse.timings;
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  result.labels = cv::Mat::zeros(height, width, CV_16UC1);
  const int n = static_cast<int>(coarse.detections.size());
  std::vector<Eigen::Isometry3d> T_quadric_camera(n);
  std::vector<double> cos_angle(n);
  for (int k = 0; k < n; ++k) {
    T_quadric_camera[k] = coarse.detections[k].shape.quadric().pose().inverse();
    cos_angle[k] = std::cos(coarse.detections[k].shape.quadric_class == QuadricClass::kPlane
                                ? p.planes.max_normal_angle
                                : p.curved_max_normal_angle);
  }
  // Per-chunk tallies of the labelled points (rows split over threads), merged afterwards.
  struct Tally {
    std::vector<int> count;
    std::vector<Eigen::Vector3d> lo, hi;
    std::vector<ImageRoi> box;  // x, y min; width, height = max
  };
  const int threads = std::max(1, std::min(p.threads, height));
  std::vector<Tally> tallies(threads);
  const int cw = coarse.labels.cols, ch = coarse.labels.rows;
  forEachChunk(height, threads, [&](int chunk, int v_begin, int v_end) {
    Tally& tally = tallies[chunk];
    tally.count.assign(n, 0);
    tally.lo.assign(n, Eigen::Vector3d::Constant(std::numeric_limits<double>::max()));
    tally.hi.assign(n, Eigen::Vector3d::Constant(-std::numeric_limits<double>::max()));
    tally.box.assign(n, ImageRoi{width, height, -1, -1});
    for (int v = v_begin; v < v_end; ++v) {
      const int cv0 = std::min(v / d, ch - 1), cv1 = std::min(v / d + 1, ch - 1);
      for (int u = 0; u < width; ++u) {
        const pcl::PointNormal& q = cloud.points[static_cast<std::size_t>(v) * width + u];
        if (!validPoint(q, p))
          continue;
        const int cu0 = std::min(u / d, cw - 1), cu1 = std::min(u / d + 1, cw - 1);
        const std::uint16_t candidates[4] = {
            coarse.labels.at<std::uint16_t>(cv0, cu0), coarse.labels.at<std::uint16_t>(cv0, cu1),
            coarse.labels.at<std::uint16_t>(cv1, cu0), coarse.labels.at<std::uint16_t>(cv1, cu1)};
        const Eigen::Vector3d point = pointOf(q);
        const double threshold =
            depthThreshold(q.z, p.planes.distance_factor, p.planes.min_distance);
        int best = 0;
        double best_distance = threshold;
        for (int c = 0; c < 4; ++c) {
          const int label = candidates[c];
          // Inside a region the four samples share one label: each surface is measured once.
          if (label == 0 || label == best || (c > 0 && label == candidates[c - 1]) ||
              (c > 1 && label == candidates[c - 2]) || (c > 2 && label == candidates[0]))
            continue;
          const PrimitiveShape& shape = coarse.detections[label - 1].shape;
          const double distance = std::abs(shape.distance(point));
          if (distance >= best_distance)
            continue;
          if (std::abs(shape.normalAt(point).dot(normalOf(q))) < cos_angle[label - 1])
            continue;
          best = label;
          best_distance = distance;
        }
        if (best == 0)
          continue;
        result.labels.at<std::uint16_t>(v, u) = static_cast<std::uint16_t>(best);
        const int k = best - 1;
        ++tally.count[k];
        const Eigen::Vector3d local = T_quadric_camera[k] * point;
        tally.lo[k] = tally.lo[k].cwiseMin(local);
        tally.hi[k] = tally.hi[k].cwiseMax(local);
        ImageRoi& box = tally.box[k];
        box.x_offset = std::min(box.x_offset, u);
        box.y_offset = std::min(box.y_offset, v);
        box.width = std::max(box.width, u);
        box.height = std::max(box.height, v);
      }
    }
  });
  std::vector<int> count(n, 0);
  std::vector<Eigen::Vector3d> lo(n, Eigen::Vector3d::Constant(std::numeric_limits<double>::max()));
  std::vector<Eigen::Vector3d> hi(n,
                                  Eigen::Vector3d::Constant(-std::numeric_limits<double>::max()));
  std::vector<ImageRoi> box(n, ImageRoi{width, height, -1, -1});
  for (const Tally& tally : tallies) {
    for (int k = 0; k < n; ++k) {
      count[k] += tally.count[k];
      lo[k] = lo[k].cwiseMin(tally.lo[k]);
      hi[k] = hi[k].cwiseMax(tally.hi[k]);
      box[k].x_offset = std::min(box[k].x_offset, tally.box[k].x_offset);
      box[k].y_offset = std::min(box[k].y_offset, tally.box[k].y_offset);
      box[k].width = std::max(box[k].width, tally.box[k].width);
      box[k].height = std::max(box[k].height, tally.box[k].height);
    }
  }
  // Keep the detections with support, renumbered 1..m.
  std::vector<std::uint16_t> relabel(n + 1, 0);
  for (int k = 0; k < n; ++k) {
    if (count[k] == 0)
      continue;
    QuadricDetection detection = coarse.detections[k];
    detection.label = static_cast<std::uint16_t>(result.detections.size() + 1);
    relabel[k + 1] = detection.label;
    // More points of the same noise: the covariance shrinks with the support.
    detection.covariance *= static_cast<double>(detection.num_points) / count[k];
    detection.num_points = count[k];
    detection.extent_min = lo[k];
    detection.extent_max = hi[k];
    detection.roi = ImageRoi{box[k].x_offset, box[k].y_offset, box[k].width - box[k].x_offset + 1,
                             box[k].height - box[k].y_offset + 1};
    result.detections.push_back(std::move(detection));
  }
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      std::uint16_t& label = result.labels.at<std::uint16_t>(v, u);
      label = relabel[label];
    }
  return result;
}

}  // namespace

Segmentation QuadricSegmenter::segment(const pcl::PointCloud<pcl::PointNormal>& cloud) const {
  Segmentation result = segmentWithNormals(cloud);
  const auto start = std::chrono::steady_clock::now();
  BoundaryCompletion boundary;
  boundary.rings = params_.boundary_rings;
  boundary.min_range = params_.min_range;
  boundary.max_range = params_.max_range;
  boundary.distance_factor = params_.planes.distance_factor;
  boundary.min_distance = params_.planes.min_distance;
  completeBoundaryLabels(cloud, boundary, result);
  // The model error of the general detections, added once their support (which scales the
  // least-squares part) is final.
  for (QuadricDetection& d : result.detections)
    if (d.shape.quadric_class == QuadricClass::kGeneral && d.covariance.rows() == 9)
      d.covariance += ellipsoidModelCovariance(d.shape.general_quadric, params_.general_model_sigma);
  result.timings.boundary_ms = msSince(start);
  return result;
}

Segmentation QuadricSegmenter::segmentWithNormals(
    const pcl::PointCloud<pcl::PointNormal>& cloud) const {
  if (!cloud.isOrganized() && !cloud.empty())
    throw std::invalid_argument("QuadricSegmenter: the cloud must be organized");
  const int d = params_.decimation;
  if (d == 1 || cloud.width < static_cast<std::uint32_t>(4 * d) ||
      cloud.height < static_cast<std::uint32_t>(4 * d))
    return segmentGrid(cloud, params_);
  const auto start = std::chrono::steady_clock::now();
  pcl::PointCloud<pcl::PointNormal> grid(cloud.width / d, cloud.height / d);
  grid.is_dense = false;
  for (std::uint32_t r = 0; r < grid.height; ++r)
    for (std::uint32_t c = 0; c < grid.width; ++c)
      grid(c, r) = cloud(c * d, r * d);
  const double decimate_ms = msSince(start);
  Segmentation coarse = segmentGrid(grid, coarseParams(params_, d));
  const auto upsample_start = std::chrono::steady_clock::now();
  Segmentation result = upsample(cloud, std::move(coarse), d, params_);
  result.timings.upsample_ms = decimate_ms + msSince(upsample_start);
  return result;
}

cv::Mat colouriseLabels(const cv::Mat& labels) {
  cv::Mat rgb(labels.rows, labels.cols, CV_8UC3, cv::Scalar(0, 0, 0));
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      const unsigned label = labels.at<std::uint16_t>(y, x);
      if (label == 0)
        continue;
      // Golden-angle hue steps give neighbouring labels distinct colours.
      const double hue = std::fmod(label * 137.508, 360.0) / 60.0;
      const double f = hue - std::floor(hue);
      const double s = 0.85, v = 0.95;
      const double pp = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
      double r = v, g = t, b = pp;
      switch (static_cast<int>(hue) % 6) {
        case 1:
          r = q;
          g = v;
          b = pp;
          break;
        case 2:
          r = pp;
          g = v;
          b = t;
          break;
        case 3:
          r = pp;
          g = q;
          b = v;
          break;
        case 4:
          r = t;
          g = pp;
          b = v;
          break;
        case 5:
          r = v;
          g = pp;
          b = q;
          break;
        default:
          break;
      }
      rgb.at<cv::Vec3b>(y, x) =
          cv::Vec3b(static_cast<unsigned char>(255 * r), static_cast<unsigned char>(255 * g),
                    static_cast<unsigned char>(255 * b));
    }
  }
  return rgb;
}

}  // namespace quadric_slam
