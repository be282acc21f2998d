#include "quadric_slam/frontend/curved_verification.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "quadric_slam/frontend/central_quadric.h"
#include "quadric_slam/frontend/curved_model_selection.h"
#include "quadric_slam/frontend/curved_shape_starts.h"
#include "quadric_slam/frontend/ellipsoid_candidate.h"
#include "quadric_slam/frontend/general_quadric_fit.h"
#include "quadric_slam/frontend/grid_flood.h"
#include "quadric_slam/frontend/parallel_chunks.h"
#include "quadric_slam/frontend/plane_region_grower.h"
#include "quadric_slam/frontend/ray_residual.h"
#include "quadric_slam/frontend/silhouette_taper.h"

namespace quadric_slam {

bool plausibleShape(const PrimitiveShape& s, const QuadricSegmenter::Params& p) {
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

std::vector<int> assignLargestComponent(const SegmentationFrame& frame, const PrimitiveShape& shape,
                                        const ImageRoi& roi, const QuadricSegmenter::Params& p,
                                        std::vector<int>* eligible) {
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
      if (eligible != nullptr)
        eligible->push_back(i);
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

namespace {

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
bool generalQuadricIsSurface(const GeneralQuadricFit& general, const SegmentationFrame& frame,
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

// Whether the general quadric explains the points' depths better than the primitive: a lower RMS
// of the residuals along the rays (ray_residual.h), a ray that misses a surface (or meets it
// beyond the segmenter's distance threshold, `gate`) counting as the threshold.
bool explainsDepthsBetter(const GeneralQuadricFit& general, const PrimitiveShape& primitive,
                          const std::vector<Eigen::Vector3d>& points, double gate) {
  const RayResidualStats by_general = rayResidualStats(general.matrix(), points, gate);
  const RayResidualStats by_primitive =
      rayResidualStats(primitive.quadric().matrix(), points, gate);
  return by_primitive.rms > by_general.rms;
}

// Shape test: the general quadric fitted to the points (general) when the primitive's residuals
// (rms) are shape rather than noise: above quadric_rms_ratio times the general quadric's, that
// quadric a surface through the points (generalQuadricIsSurface) and explaining their depths better
// along the rays (explainsDepthsBetter with the distance threshold gate). None otherwise.
std::optional<GeneralQuadricFit> shapeResiduals(const GeneralQuadricFit& general,
                                                const PrimitiveShape& primitive, double rms,
                                                const SegmentationFrame& frame,
                                                const std::vector<int>& indices,
                                                const std::vector<Eigen::Vector3d>& points,
                                                double gate, const QuadricSegmenter::Params& p) {
  if (general.ok && rms > p.quadric_rms_ratio * general.rms &&
      generalQuadricIsSurface(general, frame, indices, roiOf(indices, frame.width)) &&
      explainsDepthsBetter(general, primitive, points, gate))
    return general;
  return std::nullopt;
}

// The free pixels in roi reached from the support without crossing a depth jump (neighbours
// differing by more than max_depth_jump_factor times the depth): the rest of the surface the
// support lies on, where that is not yet segmented.
std::vector<int> smoothContinuation(const SegmentationFrame& frame, const std::vector<int>& support,
                                    const ImageRoi& roi, double max_depth_jump_factor) {
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(roi.width) * roi.height, 0);
  const auto local = [&](int i) {
    return static_cast<std::size_t>(i / frame.width - roi.y_offset) * roi.width +
           (i % frame.width - roi.x_offset);
  };
  const auto inside = [&](int i) {
    const int u = i % frame.width - roi.x_offset, v = i / frame.width - roi.y_offset;
    return u >= 0 && v >= 0 && u < roi.width && v < roi.height;
  };
  std::vector<int> frontier;
  for (int i : support) {
    if (!inside(i))
      continue;
    seen[local(i)] = 1;
    frontier.push_back(i);
  }
  const std::size_t seeds = frontier.size();
  floodFill4(frame.width, frame.height, frontier, [&](int from, int to) {
    if (!inside(to) || seen[local(to)] || !frame.valid[to] || frame.used[to])
      return false;
    const float z_from = frame.cloud.points[from].z, z_to = frame.cloud.points[to].z;
    if (std::abs(z_to - z_from) > max_depth_jump_factor * z_from)
      return false;
    seen[local(to)] = 1;
    return true;
  });
  return std::vector<int>(frontier.begin() + static_cast<std::ptrdiff_t>(seeds), frontier.end());
}

// The ellipsoid of a segment whose shape test found shape residuals (general: the general quadric
// fitted to its points): the fit's ellipsoid (ellipsoid_candidate.h), then twice the curved
// shapes' re-assignment of the free pixels near it (in the candidate's roi) and a refinement of
// its 9 minimal parameters on them. None when the fit is no plausible ellipsoid, the refinement
// fails or leaves the plausible sizes, the support is too small, or the RMS exceeds the curved
// shapes' limit (max_rms_factor). *indices receives the support; *eligible the pixels the
// re-assignments found fitting (assignLargestComponent).
std::optional<ShapeRefiner::Result> detectEllipsoid(
    const SegmentationFrame& frame, const GeneralQuadricFit& general, const ImageRoi& roi,
    const QuadricSegmenter::Params& p, const ShapeRefiner& refiner, std::vector<int>* indices,
    std::vector<int>* eligible) {
  const std::optional<PrimitiveShape> start =
      ellipsoidCandidate(general, p.min_sphere_radius, p.max_sphere_radius);
  if (!start)
    return std::nullopt;
  ShapeRefiner::Result fit;
  fit.shape = *start;
  for (int pass = 0; pass < 2; ++pass) {
    *indices = assignLargestComponent(frame, fit.shape, roi, p, eligible);
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

// What verifying one candidate decided, and the pixels whose used flags the decision depends on:
// the candidate's own samples, and the pixels its re-assignments found fitting (a pixel that did
// not fit the shape stays out of the support whether it is free or not). The decision stays the
// same as long as no other detection takes one of them.
struct CandidateVerdict {
  bool decided = false;  // false: not verified yet (or its speculative verification threw)
  bool accepted = false;
  std::vector<int> indices;
  ShapeRefiner::Result fit;
  std::vector<int> read_pixels;
};

CandidateVerdict verifyCandidate(const SegmentationFrame& frame,
                                 const CgalShapeDetector::Shape& candidate,
                                 const CurvedCandidates& candidates,
                                 const QuadricSegmenter::Params& p, const ShapeRefiner& refiner) {
  const pcl::PointCloud<pcl::PointNormal>& cloud = frame.cloud;
  const int width = frame.width, height = frame.height;
  CandidateVerdict verdict;
  verdict.decided = true;
  // The verdict depends on all of the candidate's samples; the free ones are its support.
  std::vector<int> pixels;
  std::vector<Eigen::Vector3d> support;
  verdict.read_pixels.reserve(candidate.indices.size());
  for (int k : candidate.indices) {
    verdict.read_pixels.push_back(candidates.pixels[k]);
    if (frame.used[candidates.pixels[k]])
      continue;
    support.push_back(candidates.points[k]);
    pixels.push_back(candidates.pixels[k]);
  }
  if (static_cast<int>(support.size()) < p.cgal_min_points)
    return verdict;
  PrimitiveShape shape = candidate.shape;
  if (shape.quadric_class == QuadricClass::kCone && shape.size < p.min_cone_half_angle)
    shape = cylinderFromCone(shape, support);
  // A cone that refines thinner than the least half angle is a cylinder (the side of a cylinder
  // proposed as a slightly tapering cone): refined as one rather than dropped as implausible.
  const auto refine = [&](const PrimitiveShape& start, const std::vector<Eigen::Vector3d>& on) {
    ShapeRefiner::Result result = refiner.refine(start, on);
    if (result.shape.quadric_class == QuadricClass::kCone &&
        result.shape.size < p.min_cone_half_angle)
      result = refiner.refine(cylinderFromCone(result.shape, on), on);
    return result;
  };
  ShapeRefiner::Result fit = refine(shape, support);
  const ImageRoi roi = grown(roiOf(pixels, width), 4 * p.cgal_stride, width, height);

  std::vector<int> indices;
  std::vector<Eigen::Vector3d> points;  // those of indices
  for (int pass = 0; pass < 2; ++pass) {
    if (!plausibleShape(fit.shape, p))
      break;
    indices = assignLargestComponent(frame, fit.shape, roi, p, &verdict.read_pixels);
    if (static_cast<int>(indices.size()) < p.min_curved_points) {
      indices.clear();
      break;
    }
    points = pointsOf(cloud, indices);
    fit = refine(fit.shape, points);
    // Model selection on the first support only: the second pass re-assigns the pixels with
    // the chosen class and refines it there (selecting again there changed nothing measurable
    // on the generated scenes' recall, at a third of the verification's time).
    if (pass == 0) {
      std::vector<Eigen::Vector3d> normals;
      normals.reserve(indices.size());
      for (int i : indices)
        normals.push_back(normalOf(cloud.points[i]).normalized());
      // The outline's cut pixels matter only to a cylinder or a cone (the taper).
      const bool tapered = fit.shape.quadric_class == QuadricClass::kCylinder ||
                           fit.shape.quadric_class == QuadricClass::kCone;
      fit = selectCurvedModel(fit, points, normals,
                              tapered ? cutOutline(frame, indices, p.planes.max_depth_jump_factor)
                                      : std::vector<std::uint8_t>(),
                              p, refiner);
    }
  }
  if (indices.empty() || !plausibleShape(fit.shape, p))
    return verdict;
  // Degeneracy: a near-flat surface is a plane, not a curved primitive. Flat means what it means
  // to the plane region grower: the plane fits almost as well AND the normals do not bend (shape
  // operator at most the grower's max_curvature). The normals decide when the depth noise hides
  // the sag (a far cylinder seen over a narrow arc); without them such a surface would be
  // neither a plane (the grower rejects it as curved) nor a curved primitive.
  // A curved fit no closer to the points than their plane has no evidence of curvature in the
  // depths at all, however the normals bend: the normal estimation's windows smooth across a
  // surface's border with its neighbour (on the generated desk, strips of a flat face 14-27 pixels
  // tall along the image's border beside the floor, 0.9 m away, bent by 4-17 /m), and a cylinder
  // fitted there stays in a minimum away from the plane (RMS 0.90-1.0 times the plane's). Where the
  // depth noise hides a true cylinder's sag, its fit is still at least as close as the plane.
  const PrimitiveShape plane = fitPlane(points);
  const double plane_rms = rmsDistance(plane, points);
  if (plane_rms <= fit.rms || (plane_rms < p.plane_rms_ratio * fit.rms &&
                               !normalsBendLike(patchCurvature(cloud, indices, plane.direction),
                                                shapeCurvature(fit.shape, points), p)))
    return verdict;
  // Shape test: residuals well above a general quadric's are shape (e.g. an ellipsoid), not
  // noise. Only when the general quadric is a surface through the points: when the depth noise
  // is large against the patch's curvature (a far, narrow strip of a cylinder), its 10
  // coefficients fit the noise band instead, with two close sheets that split neighbouring
  // points, and its RMS drops well below the noise that any true surface leaves. Nor when its
  // advantage is only in the first-order (Sampson) distance it was fitted by: the sensor errs
  // along the pixel's ray, and a quadric that bends away within the noise band (a tenth to a
  // third of the rays of a cylinder's strip at 2 m missing it) scores lower by that distance but
  // explains the depths no better (ray_residual.h): along the rays it must fit better too (an
  // ellipsoid taken for a sphere: 1.5-2 times; the strip of a cylinder 2 m away: 0.5-0.9).
  // The primitive is dropped; an ellipsoid found there is reported instead (before the
  // primitive's RMS limit: a sphere on an elongated ellipsoid may well exceed it).
  const GeneralQuadricFit general = fitGeneralQuadric(points);
  const double z = medianDepth(cloud, indices);
  const double gate = depthThreshold(z, p.planes.distance_factor, p.planes.min_distance);
  std::optional<GeneralQuadricFit> shape_found =
      shapeResiduals(general, fit.shape, fit.rms, frame, indices, points, gate, p);
  // The same test over the surface as far as it continues beyond the support: a primitive fitted
  // to part of a surface (a cylinder along the middle of an elongated ellipsoid) leaves out, by its
  // own distance and normal tests, exactly the parts where it fails. Only when one quadric fits the
  // wider surface at least as closely as the primitive fits its support: beside a true primitive
  // the continuation is another surface met without a depth jump (a lying cylinder's end caps and
  // the unsegmented strip of the plane it rests on), which a general quadric bends towards and
  // then fits 1.7-3.5 times worse than the primitive fits its support (generated desk; the ends
  // of an ellipsoid beyond a cylinder: 0.5-0.6 times).
  if (!shape_found) {
    const std::vector<int> beyond =
        smoothContinuation(frame, indices, roi, p.planes.max_depth_jump_factor);
    verdict.read_pixels.insert(verdict.read_pixels.end(), beyond.begin(), beyond.end());
    if (!beyond.empty()) {
      std::vector<int> surface = indices;
      surface.insert(surface.end(), beyond.begin(), beyond.end());
      const std::vector<Eigen::Vector3d> surface_points = pointsOf(cloud, surface);
      const GeneralQuadricFit wider = fitGeneralQuadric(surface_points);
      if (wider.ok && wider.rms <= fit.rms)
        shape_found = shapeResiduals(wider, fit.shape, rmsDistance(fit.shape, surface_points),
                                     frame, surface, surface_points, gate, p);
    }
  }
  if (shape_found) {
    if (p.detect_general) {
      std::vector<int> general_indices;
      const ImageRoi ellipsoid_roi =
          unite(roi, grown(roiOf(indices, width), 4 * p.cgal_stride, width, height));
      const std::optional<ShapeRefiner::Result> ellipsoid = detectEllipsoid(
          frame, *shape_found, ellipsoid_roi, p, refiner, &general_indices, &verdict.read_pixels);
      if (ellipsoid) {
        verdict.accepted = true;
        verdict.indices = std::move(general_indices);
        verdict.fit = *ellipsoid;
      }
    }
    return verdict;
  }
  if (fit.rms >
      p.max_rms_factor * depthThreshold(z, p.planes.distance_factor, p.planes.min_distance))
    return verdict;
  verdict.accepted = true;
  verdict.indices = std::move(indices);
  verdict.fit = fit;
  return verdict;
}

}  // namespace

int verifyCurvedCandidates(const SegmentationFrame& frame, const CurvedCandidates& candidates,
                           const QuadricSegmenter::Params& p, const ShapeRefiner& refiner,
                           const AcceptDetection& accept) {
  std::vector<const CgalShapeDetector::Shape*> curved;
  for (const CgalShapeDetector::Shape& candidate : candidates.shapes)
    if (candidate.shape.quadric_class != QuadricClass::kPlane)
      curved.push_back(&candidate);
  const int n = static_cast<int>(curved.size());
  // The verdicts depend on each other only through the pixels that accepted candidates take. All
  // are first verified in parallel against the free pixels as they are before this stage; then,
  // in order, a verdict is kept when no pixel it depends on (CandidateVerdict::read_pixels) was
  // taken since, and verified again otherwise. The result is the sequential one, whatever the
  // number of threads.
  std::vector<CandidateVerdict> verdicts(n);
  if (p.threads > 1 && n > 1) {
    forEachTask(
        n, p.threads,
        [&](int k) { verdicts[k] = verifyCandidate(frame, *curved[k], candidates, p, refiner); },
        // Left undecided: verified again in order below, where it may throw.
        [&](int k, std::exception_ptr) { verdicts[k] = CandidateVerdict(); });
  }
  std::vector<std::uint8_t> taken_here(frame.used.size(), 0);  // taken by this stage's detections
  const auto dependsOnTaken = [&](const CandidateVerdict& verdict) {
    return std::any_of(verdict.read_pixels.begin(), verdict.read_pixels.end(),
                       [&](int i) { return taken_here[i] != 0; });
  };
  int verified_again = 0;
  for (int k = 0; k < n; ++k) {
    CandidateVerdict verdict = std::move(verdicts[k]);
    const bool stale = verdict.decided && dependsOnTaken(verdict);
    verified_again += stale;
    if (!verdict.decided || stale)
      verdict = verifyCandidate(frame, *curved[k], candidates, p, refiner);
    if (!verdict.accepted)
      continue;
    accept(verdict.indices, verdict.fit);
    for (int i : verdict.indices)
      taken_here[i] = 1;
  }
  return verified_again;
}

}  // namespace quadric_slam
