#include "quadric_slam/frontend/segmentation_score.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <utility>

namespace quadric_slam {

SegmentationScore::SegmentationScore(std::map<int, std::string> truth_classes, int min_pixels)
    : truth_classes_(std::move(truth_classes)), min_pixels_(min_pixels) {}

namespace {

double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

// The two parameter errors of a detection against the true shape of the same class.
std::pair<double, double> shapeErrors(const PrimitiveShape& d, const PrimitiveShape& t) {
  switch (t.quadric_class) {
    case QuadricClass::kPlane: {
      Eigen::Vector3d n = d.direction;
      double offset = d.planeOffset();
      if (n.dot(t.direction) < 0) {
        n = -n;
        offset = -offset;
      }
      return {angleDeg(n, t.direction), std::abs(offset - t.planeOffset())};
    }
    case QuadricClass::kSphere:
      return {(d.point - t.point).norm(), std::abs(d.size - t.size)};
    case QuadricClass::kCylinder:
      return {std::min(angleDeg(d.direction, t.direction), angleDeg(-d.direction, t.direction)),
              std::abs(d.size - t.size)};
    default:  // cone: the axis points into the opening
      return {angleDeg(d.direction, t.direction), std::abs(d.size - t.size) * 180.0 / M_PI};
  }
}

// The truth file's class name of a detection: a general quadric with the ellipsoid's signature is
// an "ellipsoid" (the generator's name), the others their class's name.
std::string truthClassName(const PrimitiveShape& shape) {
  if (shape.quadric_class == QuadricClass::kGeneral &&
      shape.general_quadric.signature() == Eigen::Vector4d(1, 1, 1, -1))
    return "ellipsoid";
  return toString(shape.quadric_class);
}

}  // namespace

void SegmentationScore::addFrame(const Segmentation& segmentation, const cv::Mat& truth,
                                 const cv::Mat& valid,
                                 const std::map<int, PrimitiveShape>& truth_camera) {
  addFrame(segmentation, truth, valid);
  std::map<int, int> detection_size;
  std::map<std::pair<int, int>, int> both;
  for (int v = 0; v < truth.rows; ++v)
    for (int u = 0; u < truth.cols; ++u) {
      if (!valid.at<std::uint8_t>(v, u))
        continue;
      const int d = segmentation.labels.at<std::uint16_t>(v, u);
      ++detection_size[d];
      ++both[{d, truth.at<std::uint16_t>(v, u)}];
    }
  for (const QuadricDetection& d : segmentation.detections) {
    // The surface holding the detection's majority, of the same class.
    int majority = 0, majority_pixels = -1;
    for (const auto& [key, pixels] : both)
      if (key.first == d.label && pixels > majority_pixels) {
        majority = key.second;
        majority_pixels = pixels;
      }
    const auto it = truth_camera.find(majority);
    if (majority == 0 || it == truth_camera.end() ||
        it->second.quadric_class != d.shape.quadric_class)
      continue;
    const Eigen::Vector3d centre = d.shape.quadric().pose() * (0.5 * (d.extent_min + d.extent_max));
    const auto [first, second] = shapeErrors(d.shape, it->second);
    errors_[toString(d.shape.quadric_class)].push_back({centre.norm(), first, second});
  }
}

std::map<std::string, SegmentationScore::ParameterErrors> SegmentationScore::parameterErrors(
    double min_range, double max_range) const {
  std::map<std::string, ParameterErrors> out;
  for (const auto& [name, fits] : errors_)
    for (const FitError& fit : fits) {
      if (fit.range < min_range || fit.range >= max_range)
        continue;
      ParameterErrors& e = out[name];
      e.first.push_back(fit.first);
      e.second.push_back(fit.second);
    }
  return out;
}

double SegmentationScore::median(std::vector<double> values) {
  if (values.empty())
    return 0.0;
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

void SegmentationScore::addFrame(const Segmentation& segmentation, const cv::Mat& truth,
                                 const cv::Mat& valid) {
  std::map<int, int> truth_size, detection_size;
  std::map<std::pair<int, int>, int> both;  // (detection label, surface id) -> pixels
  for (int v = 0; v < truth.rows; ++v)
    for (int u = 0; u < truth.cols; ++u) {
      if (!valid.at<std::uint8_t>(v, u))
        continue;
      const int t = truth.at<std::uint16_t>(v, u);
      const int d = segmentation.labels.at<std::uint16_t>(v, u);
      ++truth_size[t];
      ++detection_size[d];
      ++both[{d, t}];
    }
  ++frames_;
  last_missed_.clear();
  last_spurious_.clear();
  auto scored = [&](int id) {
    const auto it = truth_classes_.find(id);
    return it != truth_classes_.end() && (it->second == "plane" || it->second == "sphere" ||
                                          it->second == "cylinder" || it->second == "cone");
  };
  for (const auto& [id, size] : truth_size) {
    if (id == 0 || !scored(id) || size < min_pixels_)
      continue;
    Surface& s = surfaces_[id];
    s.quadric_class = truth_classes_[id];
    ++s.frames_scored;
    const int detected_before = s.frames_detected;
    for (const QuadricDetection& d : segmentation.detections) {
      if (toString(d.shape.quadric_class) != s.quadric_class)
        continue;
      const auto it = both.find({d.label, id});
      const int common = it == both.end() ? 0 : it->second;
      if (common >= 0.5 * detection_size[d.label] && common >= 0.3 * size) {
        ++s.frames_detected;
        break;
      }
    }
    if (s.frames_detected == detected_before)
      last_missed_.push_back(id);
  }
  for (const QuadricDetection& d : segmentation.detections) {
    int majority = 0, majority_pixels = -1;
    for (const auto& [key, pixels] : both)
      if (key.first == d.label && pixels > majority_pixels) {
        majority = key.second;
        majority_pixels = pixels;
      }
    const auto it = truth_classes_.find(majority);
    if (majority == 0 || it == truth_classes_.end() || it->second != truthClassName(d.shape)) {
      ++spurious_;
      if (majority != 0 && it != truth_classes_.end() && !scored(majority))
        ++spurious_unmodelled_;
      const std::string on = it == truth_classes_.end() ? std::string("no surface") : it->second;
      ++spurious_kinds_[toString(d.shape.quadric_class) + " on " + on];
      last_spurious_.push_back(toString(d.shape.quadric_class) + " " + std::to_string(d.label) +
                               " on " + on +
                               (it == truth_classes_.end() ? "" : " " + std::to_string(majority)));
    }
  }
}

std::string SegmentationScore::report() const {
  std::ostringstream out;
  char line[160];
  for (const auto& [id, s] : surfaces_) {
    std::snprintf(line, sizeof(line),
                  "surface %3d %-8s scored in %4d frames, detected in %4d (%.1f%%)\n", id,
                  s.quadric_class.c_str(), s.frames_scored, s.frames_detected, 100.0 * s.rate());
    out << line;
  }
  std::snprintf(
      line, sizeof(line),
      "frames %d, spurious detections %d (%.2f per frame; %.2f per frame without those on "
      "surfaces of unmodelled classes)\n",
      frames_, spurious_, spuriousPerFrame(), spuriousPerFrameOnModelled());
  out << line;
  for (const auto& [kind, count] : spurious_kinds_)
    out << "  spurious: " << count << " x " << kind << "\n";
  static const std::map<std::string, std::pair<const char*, const char*>> kNames = {
      {"plane", {"normal angle (deg)", "offset (m)"}},
      {"sphere", {"centre (m)", "radius (m)"}},
      {"cylinder", {"axis angle (deg)", "radius (m)"}},
      {"cone", {"axis angle (deg)", "half angle (deg)"}}};
  // Bands of range (m) whose errors are reported apart.
  static const std::vector<std::pair<double, const char*>> kBands = {
      {2.0, "0-2 m"}, {4.0, "2-4 m"}, {std::numeric_limits<double>::infinity(), "4 m+"}};
  double lower = 0.0;
  for (const auto& [upper, band] : kBands) {
    for (const auto& [name, e] : parameterErrors(lower, upper)) {
      const auto it = kNames.find(name);
      if (it == kNames.end())
        continue;
      std::snprintf(line, sizeof(line), "median errors %-8s %-5s (%4zu fits): %s %.4f, %s %.4f\n",
                    name.c_str(), band, e.first.size(), it->second.first, median(e.first),
                    it->second.second, median(e.second));
      out << line;
    }
    lower = upper;
  }
  return out.str();
}

}  // namespace quadric_slam
