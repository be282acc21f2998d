#include "quadric_slam/frontend/segmentation_score.h"

#include <cstdio>
#include <sstream>
#include <utility>

namespace quadric_slam {

SegmentationScore::SegmentationScore(std::map<int, std::string> truth_classes, int min_pixels)
    : truth_classes_(std::move(truth_classes)), min_pixels_(min_pixels) {}

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
  }
  for (const QuadricDetection& d : segmentation.detections) {
    int majority = 0, majority_pixels = -1;
    for (const auto& [key, pixels] : both)
      if (key.first == d.label && pixels > majority_pixels) {
        majority = key.second;
        majority_pixels = pixels;
      }
    const auto it = truth_classes_.find(majority);
    if (majority == 0 || it == truth_classes_.end() ||
        it->second != toString(d.shape.quadric_class)) {
      ++spurious_;
      if (majority != 0 && it != truth_classes_.end() && !scored(majority))
        ++spurious_unmodelled_;
      ++spurious_kinds_[toString(d.shape.quadric_class) + " on " +
                        (it == truth_classes_.end() ? std::string("no surface") : it->second)];
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
  return out.str();
}

}  // namespace quadric_slam
