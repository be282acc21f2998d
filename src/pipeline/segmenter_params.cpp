#include "quadric_slam/pipeline/segmenter_params.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <utility>

namespace quadric_slam {

namespace {

using Params = QuadricSegmenter::Params;

struct Entry {
  std::string name;
  std::function<double&(Params&)> real;  // for double fields
  std::function<int&(Params&)> integer;  // for int fields
  std::function<bool&(Params&)> flag;    // for bool fields
};

Entry real(std::string name, std::function<double&(Params&)> f) {
  return {std::move(name), f, {}, {}};
}
Entry integer(std::string name, std::function<int&(Params&)> f) {
  return {std::move(name), {}, f, {}};
}
Entry flag(std::string name, std::function<bool&(Params&)> f) {
  return {std::move(name), {}, {}, f};
}

const std::vector<Entry>& table() {
  static const std::vector<Entry> entries = {
      real("min_range", [](Params& p) -> double& { return p.min_range; }),
      real("max_range", [](Params& p) -> double& { return p.max_range; }),
      integer("decimation", [](Params& p) -> int& { return p.decimation; }),
      integer("curved_decimation", [](Params& p) -> int& { return p.curved_decimation; }),
      integer("boundary_rings", [](Params& p) -> int& { return p.boundary_rings; }),
      integer("threads", [](Params& p) -> int& { return p.threads; }),
      real("plane_max_normal_angle",
           [](Params& p) -> double& { return p.planes.max_normal_angle; }),
      real("distance_factor", [](Params& p) -> double& { return p.planes.distance_factor; }),
      real("min_distance", [](Params& p) -> double& { return p.planes.min_distance; }),
      real("max_depth_jump_factor",
           [](Params& p) -> double& { return p.planes.max_depth_jump_factor; }),
      integer("min_plane_points", [](Params& p) -> int& { return p.planes.min_points; }),
      real("max_plane_curvature", [](Params& p) -> double& { return p.planes.max_curvature; }),
      real("plane_merge_angle", [](Params& p) -> double& { return p.planes.merge_angle; }),
      integer("plane_seed_stride", [](Params& p) -> int& { return p.planes.seed_stride; }),
      real("depth_noise_scale", [](Params& p) -> double& { return p.planes.noise_scale; }),
      real("depth_quantisation_factor",
           [](Params& p) -> double& { return p.planes.quantisation_factor; }),
      real("depth_bend_factor", [](Params& p) -> double& { return p.planes.bend_factor; }),
      real("plane_noise_sigmas", [](Params& p) -> double& { return p.planes.noise_sigmas; }),
      integer("min_plane_fragment_points",
              [](Params& p) -> int& { return p.planes.min_fragment_points; }),
      real("plane_merge_rms_factor",
           [](Params& p) -> double& { return p.planes.merge_rms_factor; }),
      real("plane_fill_max_normal_angle",
           [](Params& p) -> double& { return p.planes.fill_max_normal_angle; }),
      integer("plane_cell_size", [](Params& p) -> int& { return p.planes.cell_size; }),
      real("plane_cell_min_depth", [](Params& p) -> double& { return p.planes.cell_min_depth; }),
      real("depth_correlated_points",
           [](Params& p) -> double& { return p.planes.correlated_points; }),
      flag("detect_spheres", [](Params& p) -> bool& { return p.detect_spheres; }),
      flag("detect_cylinders", [](Params& p) -> bool& { return p.detect_cylinders; }),
      flag("detect_cones", [](Params& p) -> bool& { return p.detect_cones; }),
      flag("grid_ransac", [](Params& p) -> bool& { return p.grid_ransac; }),
      integer("cgal_stride", [](Params& p) -> int& { return p.cgal_stride; }),
      integer("cgal_max_points", [](Params& p) -> int& { return p.cgal_max_points; }),
      real("cgal_probability", [](Params& p) -> double& { return p.cgal_probability; }),
      integer("cgal_min_points", [](Params& p) -> int& { return p.cgal_min_points; }),
      real("cgal_min_fraction", [](Params& p) -> double& { return p.cgal_min_fraction; }),
      real("cgal_epsilon", [](Params& p) -> double& { return p.cgal_epsilon; }),
      real("cgal_cluster_epsilon", [](Params& p) -> double& { return p.cgal_cluster_epsilon; }),
      real("cgal_normal_threshold", [](Params& p) -> double& { return p.cgal_normal_threshold; }),
      real("curved_max_normal_angle",
           [](Params& p) -> double& { return p.curved_max_normal_angle; }),
      integer("min_curved_points", [](Params& p) -> int& { return p.min_curved_points; }),
      real("min_sphere_radius", [](Params& p) -> double& { return p.min_sphere_radius; }),
      real("max_sphere_radius", [](Params& p) -> double& { return p.max_sphere_radius; }),
      real("min_cylinder_radius", [](Params& p) -> double& { return p.min_cylinder_radius; }),
      real("max_cylinder_radius", [](Params& p) -> double& { return p.max_cylinder_radius; }),
      real("min_cone_half_angle", [](Params& p) -> double& { return p.min_cone_half_angle; }),
      real("max_cone_half_angle", [](Params& p) -> double& { return p.max_cone_half_angle; }),
      real("plane_rms_ratio", [](Params& p) -> double& { return p.plane_rms_ratio; }),
      real("cylinder_rms_ratio", [](Params& p) -> double& { return p.cylinder_rms_ratio; }),
      real("quadric_rms_ratio", [](Params& p) -> double& { return p.quadric_rms_ratio; }),
      flag("detect_general", [](Params& p) -> bool& { return p.detect_general; }),
      real("general_model_sigma", [](Params& p) -> double& { return p.general_model_sigma; }),
      real("max_rms_factor", [](Params& p) -> double& { return p.max_rms_factor; }),
      integer("refine_max_iterations", [](Params& p) -> int& { return p.refiner.max_iterations; }),
      integer("refine_max_points", [](Params& p) -> int& { return p.refiner.max_points; }),
  };
  return entries;
}

const Entry& find(const std::string& key) {
  for (const Entry& e : table())
    if (e.name == key)
      return e;
  throw std::invalid_argument("unknown segmentation parameter '" + key + "'");
}

}  // namespace

const std::vector<std::string>& segmenterParamNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const Entry& e : table())
      n.push_back(e.name);
    return n;
  }();
  return names;
}

SegmenterParamType segmenterParamType(const std::string& key) {
  const Entry& e = find(key);
  if (e.real)
    return SegmenterParamType::kReal;
  if (e.integer)
    return SegmenterParamType::kInteger;
  return SegmenterParamType::kBool;
}

double getSegmenterParam(const Params& params, const std::string& key) {
  const Entry& e = find(key);
  Params& p = const_cast<Params&>(params);  // the accessors only read here
  if (e.real)
    return e.real(p);
  if (e.integer)
    return e.integer(p);
  return e.flag(p) ? 1.0 : 0.0;
}

void setSegmenterParam(Params& params, const std::string& key, double value) {
  const Entry& e = find(key);
  if (e.real)
    e.real(params) = value;
  else if (e.integer)
    e.integer(params) = static_cast<int>(std::lround(value));
  else
    e.flag(params) = value != 0.0;
}

void readSegmentationParams(const ParamReader& reader, Params& params, ParamLog& log) {
  for (const Entry& e : table()) {
    if (e.real)
      readParam(reader, e.name, e.real(params), log);
    else if (e.integer)
      readParam(reader, e.name, e.integer(params), log);
    else
      readParam(reader, e.name, e.flag(params), log);
  }
  params.validate();
}

QuadricSegmenter::Params loadSegmenterParams(const std::string& yaml_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument("cannot read " + yaml_path + ": " + e.what());
  }
  Params params;
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    // The nodelet's own keys (max_support_points: also QuadricSlam's), not the segmenter's.
    if (key == "queue_size" || key == "workers" || key == "max_support_points")
      continue;
    const Entry& e = find(key);
    try {
      if (e.flag)
        setSegmenterParam(params, key, entry.second.as<bool>() ? 1.0 : 0.0);
      else
        setSegmenterParam(params, key, entry.second.as<double>());
    } catch (const YAML::Exception&) {
      throw std::invalid_argument(yaml_path + ": bad value for " + key);
    }
  }
  params.validate();
  return params;
}

}  // namespace quadric_slam
