#include "quadric_slam/frontend/curved_candidates.h"

#include <algorithm>
#include <cmath>
#include <exception>

#include "quadric_slam/frontend/curved_shape_starts.h"
#include "quadric_slam/frontend/curved_verification.h"
#include "quadric_slam/frontend/grid_shape_ransac.h"
#include "quadric_slam/frontend/parallel_chunks.h"
#include "quadric_slam/frontend/plane_region_grower.h"

namespace quadric_slam {

std::vector<std::vector<int>> freeComponents(const SegmentationFrame& frame,
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

CurvedCandidates findCurvedCandidates(const SegmentationFrame& frame,
                                      const QuadricSegmenter::Params& p) {
  CurvedCandidates out;
  if (!(p.detect_spheres || p.detect_cylinders || p.detect_cones))
    return out;
  const pcl::PointCloud<pcl::PointNormal>& cloud = frame.cloud;
  const int width = frame.width;
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
  // Each component's sample is a contiguous range of the sample arrays.
  struct ComponentJob {
    std::size_t first = 0;
    int count = 0;
    int min_points = 0;
    int stride = 1;  // of the component's sample, in grid pixels
    std::vector<CgalShapeDetector::Shape> shapes;
    std::exception_ptr error;
  };
  std::vector<ComponentJob> jobs;
  for (const std::vector<int>& component : freeComponents(frame, p)) {
    if (static_cast<int>(component.size()) < p.min_curved_points)
      continue;
    const std::size_t first = out.points.size();
    // A stride that keeps the component's sample within cgal_max_points.
    const int stride = std::max(
        p.cgal_stride, static_cast<int>(std::ceil(
                           std::sqrt(static_cast<double>(component.size()) / p.cgal_max_points))));
    for (int i : component) {
      if ((i % width) % stride != 0 || (i / width) % stride != 0)
        continue;
      out.points.push_back(pointOf(cloud.points[i]));
      out.normals.push_back(normalOf(cloud.points[i]).normalized());
      out.pixels.push_back(i);
    }
    ComponentJob job;
    job.first = first;
    job.count = static_cast<int>(out.points.size() - first);
    job.stride = stride;
    job.min_points =
        std::max(p.cgal_min_points, static_cast<int>(std::ceil(p.cgal_min_fraction * job.count)));
    if (job.count < job.min_points) {
      out.points.resize(first);
      out.normals.resize(first);
      out.pixels.resize(first);
      continue;
    }
    jobs.push_back(std::move(job));
  }
  auto detectComponent = [&](ComponentJob& job) {
    CgalShapeDetector::Params params = cgal;
    params.min_points = job.min_points;
    const std::vector<Eigen::Vector3d> points(out.points.begin() + job.first,
                                              out.points.begin() + job.first + job.count);
    const std::vector<Eigen::Vector3d> normals(out.normals.begin() + job.first,
                                               out.normals.begin() + job.first + job.count);
    if (p.grid_ransac) {
      std::vector<Eigen::Vector2i> cells;  // each sample's cell on the component's sample grid
      cells.reserve(job.count);
      for (int k = 0; k < job.count; ++k) {
        const int pixel = out.pixels[job.first + k];
        cells.emplace_back((pixel % width) / job.stride, (pixel / width) / job.stride);
      }
      job.shapes = GridShapeRansac(params).detect(points, normals, cells);
    } else {
      job.shapes = CgalShapeDetector(params).detect(points, normals);
    }
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
        pixels.push_back(out.pixels[job.first + k]);
        support.push_back(points[k]);
        support_normals.push_back(normals[k]);
      }
      const double curvature = patchCurvature(cloud, pixels, shape.shape.direction);
      if (curvature <= p.planes.max_curvature)
        continue;
      // The cylinder the normals describe must fit the points better than the plane does (not so
      // on clutter, which stays absorbed by the plane). Where the depth noise exceeds CGAL's
      // epsilon, the plane's support is the part of the noise band within epsilon of the plane,
      // which flatters the plane: there the cylinder need only fit within plane_rms_ratio of it
      // (the verification's degeneracy test then decides on the surface's whole support).
      const PrimitiveShape cylinder = cylinderFromNormals(support, support_normals, curvature);
      const double sigma = kinectDepthSigma(medianDepth(cloud, pixels), p.planes.noise_scale,
                                            p.planes.quantisation_factor);
      const double allowed = sigma > p.cgal_epsilon ? p.plane_rms_ratio : 1.0;
      if (plausibleShape(cylinder, p) &&
          rmsDistance(cylinder, support) < allowed * rmsDistance(shape.shape, support))
        shape.shape = cylinder;
    }
    for (CgalShapeDetector::Shape& shape : job.shapes)
      for (int& k : shape.indices)
        k += static_cast<int>(job.first);
  };
  // The components are independent inputs: CGAL runs on them in parallel, each thread taking the
  // next component. CGAL's random generator is thread-local and reseeded per call, so the result
  // does not depend on the number of threads.
  // The largest sample first: the threads then finish together (a frame's cost is often one
  // large component's).
  std::vector<int> order(jobs.size());
  for (std::size_t j = 0; j < jobs.size(); ++j)
    order[j] = static_cast<int>(j);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return jobs[a].count > jobs[b].count; });
  forEachTask(
      static_cast<int>(jobs.size()), p.threads, [&](int j) { detectComponent(jobs[order[j]]); },
      [&](int j, std::exception_ptr error) { jobs[order[j]].error = error; });  // rethrown below
  for (ComponentJob& job : jobs) {
    if (job.error)
      std::rethrow_exception(job.error);
    for (CgalShapeDetector::Shape& shape : job.shapes)
      out.shapes.push_back(std::move(shape));
  }
  std::stable_sort(out.shapes.begin(), out.shapes.end(), [](const auto& a, const auto& b) {
    return a.indices.size() > b.indices.size();
  });
  return out;
}

}  // namespace quadric_slam
