#include "quadric_slam/io/landmark_map_file.h"

#include "quadric_slam/geometry/quadric_class.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/mapping/extent_box.h"

namespace quadric_slam {

MapFile mapFileFromLandmarks(const std::vector<QuadricLandmark>& landmarks,
                             const std::string& frame_id, const std::map<int, int>& merged_into) {
  MapFile map;
  map.frame_id = frame_id;
  map.merged_into = merged_into;
  for (const QuadricLandmark& landmark : landmarks) {
    const QuadricModel& quadric = landmark.quadric_map;
    MapFileQuadric entry;
    entry.id = landmark.id;
    entry.quadric_class = toString(quadric.quadricClass());
    if (quadric.quadricClass() == QuadricClass::kGeneral &&
        quadric.signature() == Eigen::Vector4d(1, 1, 1, -1))
      entry.quadric_class = "ellipsoid";
    entry.observations = landmark.observations;
    entry.T_map_quadric = quadric.pose();
    entry.scale = quadric.scale();
    entry.shape = shapeMap(quadric);
    if (entry.quadric_class == "ellipsoid") {  // as the generator's truth: centre and semi-axes
      const Eigen::Vector3d centre = quadric.pose().translation();
      const Eigen::Vector3d radii = quadric.scale().cwiseInverse();
      entry.shape["center"] = {centre.x(), centre.y(), centre.z()};
      entry.shape["radii"] = {radii.x(), radii.y(), radii.z()};
    }
    const ExtentBox extent{landmark.extent_min, landmark.extent_max};
    if (extent.known()) {
      entry.has_extent = true;
      entry.extent_min = extent.min;
      entry.extent_max = extent.max;
    }
    map.quadrics.push_back(entry);
  }
  return map;
}

}  // namespace quadric_slam
