// The mapper's landmarks as the map schema (io/map_yaml.h), for saved maps and their evaluation.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "quadric_slam/io/map_yaml.h"
#include "quadric_slam/mapping/landmark.h"

namespace quadric_slam {

// One entry per landmark: id, class (a general quadric with the ellipsoid signature is written as
// "ellipsoid", with the shape keys center and radii (its semi-axes along quadric x, y, z) as in
// the generator's truth), observation count, T_map_quadric, scale and the human-readable shape of
// its class; `merged_into` (merged ids -> surviving ids, LandmarkRegistry::mergedInto) as is.
MapFile mapFileFromLandmarks(const std::vector<QuadricLandmark>& landmarks,
                             const std::string& frame_id,
                             const std::map<int, int>& merged_into = {});

}  // namespace quadric_slam
