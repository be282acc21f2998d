#include "quadric_slam/sim/scene_yaml.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace quadric_slam {
namespace {

using Keys = std::set<std::string>;

void checkKeys(const YAML::Node& node, const Keys& allowed, const std::string& where) {
  if (!node.IsMap())
    throw std::runtime_error(where + "must be a mapping");
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    if (!allowed.count(key)) {
      std::string list;
      for (const std::string& k : allowed)
        list += (list.empty() ? "" : ", ") + k;
      throw std::runtime_error(where + "unknown key '" + key + "' (allowed: " + list + ")");
    }
  }
}

double readDouble(const YAML::Node& node, const std::string& key, const std::string& where) {
  try {
    return node.as<double>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error(where + "'" + key + "' must be a number");
  }
}

std::vector<double> readList(const YAML::Node& node, const std::string& key, std::size_t size,
                             const std::string& where) {
  std::vector<double> values;
  if (!node.IsSequence() || node.size() != size) {
    throw std::runtime_error(where + "'" + key + "' must be a list of " + std::to_string(size) +
                             " numbers");
  }
  for (const auto& v : node)
    values.push_back(readDouble(v, key, where));
  return values;
}

Eigen::Vector3d readVec3(const YAML::Node& node, const std::string& key, const std::string& where) {
  const std::vector<double> v = readList(node, key, 3, where);
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

// Optional scalar: keeps `value` when the key is absent.
void optional(const YAML::Node& map, const std::string& key, const std::string& where,
              double* value) {
  if (map[key])
    *value = readDouble(map[key], key, where);
}

// The child node under `key` (returned by value: assigning yaml-cpp nodes would alias them).
YAML::Node required(const YAML::Node& map, const std::string& key, const std::string& where) {
  const YAML::Node node = map[key];
  if (!node)
    throw std::runtime_error(where + "missing key '" + key + "'");
  return node;
}

Eigen::Vector3d readColour(const YAML::Node& node, const std::string& key,
                           const std::string& where) {
  const Eigen::Vector3d c = readVec3(node, key, where);
  if ((c.array() < 0.0).any() || (c.array() > 1.0).any())
    throw std::runtime_error(where + "'" + key + "' must be RGB in [0, 1]");
  return c;
}

// Rotation whose `column` (0: x, 2: z) is `axis`, the other axes chosen deterministically
// (x horizontal when the axis is z; y horizontal when the axis is x).
Eigen::Matrix3d rotationFromAxis(Eigen::Vector3d axis, int column) {
  axis.normalize();
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  Eigen::Matrix3d R;
  if (column == 2) {
    Eigen::Vector3d x = up.cross(axis);
    if (x.norm() < 1e-9)
      x = axis.z() > 0 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d(-1, 0, 0);
    x.normalize();
    R.col(0) = x;
    R.col(1) = axis.cross(x);
    R.col(2) = axis;
  } else {
    Eigen::Vector3d y = up.cross(axis);
    if (y.norm() < 1e-9)
      y = Eigen::Vector3d::UnitY();
    y.normalize();
    R.col(0) = axis;
    R.col(1) = y;
    R.col(2) = axis.cross(y);
  }
  return R;
}

Material readMaterial(const YAML::Node& node, const std::string& where) {
  Material m;
  if (node["colour"])
    m.colour = readColour(node["colour"], "colour", where);
  if (const YAML::Node texture = node["texture"]) {
    const std::string w = where + "texture: ";
    checkKeys(texture, {"type", "colour", "scale"}, w);
    const std::string name = required(texture, "type", w).as<std::string>();
    if (name == "none")
      m.texture = Texture::kNone;
    else if (name == "checker")
      m.texture = Texture::kChecker;
    else if (name == "noise")
      m.texture = Texture::kNoise;
    else
      throw std::runtime_error(w + "'type' must be none, checker or noise, not '" + name + "'");
    if (texture["colour"])
      m.colour2 = readColour(texture["colour"], "colour", w);
    optional(texture, "scale", w, &m.texture_scale);
    if (!(m.texture_scale > 0.0))
      throw std::runtime_error(w + "'scale' must be > 0 m");
  }
  return m;
}

PrimitiveSpec readPrimitive(const YAML::Node& node, std::size_t index) {
  std::string where = "primitives[" + std::to_string(index) + "]: ";
  if (!node.IsMap())
    throw std::runtime_error(where + "must be a mapping");
  PrimitiveSpec p;
  p.name = required(node, "name", where).as<std::string>();
  where = "primitives[" + std::to_string(index) + "] (" + p.name + "): ";
  try {
    p.type = primitiveTypeFromString(required(node, "type", where).as<std::string>());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + "'type': " + e.what());
  }
  Keys keys = {"name", "type", "position", "rpy", "colour", "texture"};
  switch (p.type) {
    case PrimitiveType::kRectangle:
      keys.insert({"normal", "size"});
      break;
    case PrimitiveType::kBox:
      keys.insert({"axis", "size"});
      break;
    case PrimitiveType::kSphere:
      keys.insert({"radius"});
      break;
    case PrimitiveType::kCylinder:
      keys.insert({"axis", "radius", "length", "capped"});
      break;
    case PrimitiveType::kCone:
      keys.insert({"axis", "half_angle", "z_min", "z_max"});
      break;
    case PrimitiveType::kEllipsoid:
      keys.insert({"axis", "radii"});
      break;
  }
  checkKeys(node, keys, where);
  p.T_world_primitive.translation() =
      readVec3(required(node, "position", where), "position", where);
  const char* axis_key = p.type == PrimitiveType::kRectangle ? "normal" : "axis";
  if (node["rpy"] && node[axis_key])
    throw std::runtime_error(where + "give either 'rpy' or '" + axis_key + "', not both");
  if (node["rpy"]) {
    const Eigen::Vector3d rpy = readVec3(node["rpy"], "rpy", where);
    p.T_world_primitive.linear() = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  } else if (node[axis_key]) {
    const Eigen::Vector3d axis = readVec3(node[axis_key], axis_key, where);
    if (axis.norm() < 1e-9)
      throw std::runtime_error(where + "'" + axis_key + "' must not be zero");
    p.T_world_primitive.linear() =
        rotationFromAxis(axis, p.type == PrimitiveType::kRectangle ? 0 : 2);
  }
  switch (p.type) {
    case PrimitiveType::kRectangle: {
      const std::vector<double> s = readList(required(node, "size", where), "size", 2, where);
      p.size = Eigen::Vector3d(0.0, s[0], s[1]);
      break;
    }
    case PrimitiveType::kBox:
      p.size = readVec3(required(node, "size", where), "size", where);
      break;
    case PrimitiveType::kSphere:
      p.radius = readDouble(required(node, "radius", where), "radius", where);
      break;
    case PrimitiveType::kCylinder:
      p.radius = readDouble(required(node, "radius", where), "radius", where);
      p.length = readDouble(required(node, "length", where), "length", where);
      if (node["capped"]) {
        try {
          p.capped = node["capped"].as<bool>();
        } catch (const YAML::Exception&) {
          throw std::runtime_error(where + "'capped' must be true or false");
        }
      }
      break;
    case PrimitiveType::kCone:
      p.half_angle = readDouble(required(node, "half_angle", where), "half_angle", where);
      p.z_min = readDouble(required(node, "z_min", where), "z_min", where);
      p.z_max = readDouble(required(node, "z_max", where), "z_max", where);
      break;
    case PrimitiveType::kEllipsoid:
      p.radii = readVec3(required(node, "radii", where), "radii", where);
      break;
  }
  p.material = readMaterial(node, where);
  const std::string problem = p.problem();
  if (!problem.empty())
    throw std::runtime_error(where + problem);
  return p;
}

void readHandheld(const YAML::Node& node, HandheldTrajectory::Params* h) {
  const std::string where = "handheld: ";
  checkKeys(node,
            {"distance", "height", "azimuth", "sweep", "sweep_period", "wobble", "gaze_wobble",
             "roll_wobble", "start_stamp"},
            where);
  optional(node, "distance", where, &h->distance);
  optional(node, "height", where, &h->height);
  optional(node, "azimuth", where, &h->azimuth);
  optional(node, "sweep", where, &h->sweep);
  optional(node, "sweep_period", where, &h->sweep_period);
  optional(node, "wobble", where, &h->wobble);
  optional(node, "gaze_wobble", where, &h->gaze_wobble);
  optional(node, "roll_wobble", where, &h->roll_wobble);
  optional(node, "start_stamp", where, &h->start_stamp);
  try {
    h->validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + e.what());
  }
}

void readDepth(const YAML::Node& node, KinectDepthModel::Params* d) {
  const std::string where = "depth_noise: ";
  checkKeys(node,
            {"min_range",
             "max_range",
             "sigma_constant",
             "sigma_quadratic",
             "sigma_reference_depth",
             "focal_px",
             "baseline",
             "disparity_resolution",
             "max_incidence",
             "edge_dropout_px",
             "edge_jump_ratio",
             "dropout_probability",
             "model",
             "sigma_scale",
             "distortion_r2",
             "distortion_r4",
             "pattern_amplitude",
             "pattern_wavelength_px",
             "pattern_seed",
             "correlated_fraction",
             "correlation_px",
             "projector_side"},
            where);
  // The preset first; the keys below override its terms.
  if (node["model"]) {
    try {
      KinectDepthModel::applyModel(node["model"].as<std::string>(), d);
    } catch (const std::exception& e) {
      throw std::runtime_error(where + "'model': " + e.what());
    }
  }
  optional(node, "min_range", where, &d->min_range);
  optional(node, "max_range", where, &d->max_range);
  optional(node, "sigma_constant", where, &d->sigma_constant);
  optional(node, "sigma_quadratic", where, &d->sigma_quadratic);
  optional(node, "sigma_reference_depth", where, &d->sigma_reference_depth);
  optional(node, "focal_px", where, &d->focal_px);
  optional(node, "baseline", where, &d->baseline);
  optional(node, "disparity_resolution", where, &d->disparity_resolution);
  optional(node, "max_incidence", where, &d->max_incidence);
  if (node["edge_dropout_px"]) {
    const double px = readDouble(node["edge_dropout_px"], "edge_dropout_px", where);
    if (px != std::floor(px))
      throw std::runtime_error(where + "'edge_dropout_px' must be an integer");
    d->edge_dropout_px = static_cast<int>(px);
  }
  optional(node, "edge_jump_ratio", where, &d->edge_jump_ratio);
  optional(node, "dropout_probability", where, &d->dropout_probability);
  optional(node, "sigma_scale", where, &d->sigma_scale);
  optional(node, "distortion_r2", where, &d->distortion_r2);
  optional(node, "distortion_r4", where, &d->distortion_r4);
  optional(node, "pattern_amplitude", where, &d->pattern_amplitude);
  optional(node, "pattern_wavelength_px", where, &d->pattern_wavelength_px);
  if (node["pattern_seed"]) {
    const double seed = readDouble(node["pattern_seed"], "pattern_seed", where);
    if (seed != std::floor(seed) || seed < 0 || seed > 2e9)
      throw std::runtime_error(where + "'pattern_seed' must be a non-negative integer");
    d->pattern_seed = static_cast<int>(seed);
  }
  optional(node, "correlated_fraction", where, &d->correlated_fraction);
  optional(node, "correlation_px", where, &d->correlation_px);
  if (node["projector_side"]) {
    const double side = readDouble(node["projector_side"], "projector_side", where);
    if (side != -1.0 && side != 0.0 && side != 1.0)
      throw std::runtime_error(where + "'projector_side' must be -1, 0 or 1");
    d->projector_side = static_cast<int>(side);
  }
  try {
    d->validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + e.what());
  }
}

void readCamera(const YAML::Node& node, Scene* scene) {
  const std::string where = "camera: ";
  checkKeys(node, {"width", "height", "fx", "fy", "cx", "cy", "rate"}, where);
  CameraIntrinsics& c = scene->camera;
  double width = c.width, height = c.height;
  optional(node, "width", where, &width);
  optional(node, "height", where, &height);
  if (width != std::floor(width) || height != std::floor(height))
    throw std::runtime_error(where + "'width' and 'height' must be integers");
  c.width = static_cast<int>(width);
  c.height = static_cast<int>(height);
  optional(node, "fx", where, &c.fx);
  optional(node, "fy", where, &c.fy);
  optional(node, "cx", where, &c.cx);
  optional(node, "cy", where, &c.cy);
  optional(node, "rate", where, &scene->rate);
  if (!c.valid())
    throw std::runtime_error(where + c.problem());
  if (!(scene->rate > 0.0))
    throw std::runtime_error(where + "'rate' must be > 0 Hz");
}

void emitVec(YAML::Emitter& out, const Eigen::Vector3d& v) {
  out << YAML::Flow << YAML::BeginSeq << v.x() << v.y() << v.z() << YAML::EndSeq;
}

}  // namespace

Scene parseSceneYaml(const std::string& text) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(std::string("bad YAML: ") + e.what());
  }
  if (!root || !root.IsMap())
    throw std::runtime_error("scene file must be a YAML mapping");
  checkKeys(root,
            {"name", "camera", "centre_of_interest", "background", "handheld", "depth_noise",
             "primitives"},
            "");
  Scene scene;
  try {
    scene.name = required(root, "name", "").as<std::string>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error("'name' must be a string");
  }
  if (scene.name.empty() || scene.name.find('/') != std::string::npos)
    throw std::runtime_error("'name' must be a non-empty file name without '/'");
  if (root["camera"])
    readCamera(root["camera"], &scene);
  scene.centre_of_interest =
      readVec3(required(root, "centre_of_interest", ""), "centre_of_interest", "");
  if (root["background"])
    scene.background = readColour(root["background"], "background", "");
  if (root["handheld"])
    readHandheld(root["handheld"], &scene.handheld);
  if (root["depth_noise"])
    readDepth(root["depth_noise"], &scene.depth);
  const YAML::Node value = required(root, "primitives", "");
  if (!value.IsSequence() || value.size() == 0)
    throw std::runtime_error("'primitives' must be a non-empty list");
  std::set<std::string> names;
  for (std::size_t i = 0; i < value.size(); ++i) {
    scene.primitives.push_back(readPrimitive(value[i], i));
    if (!names.insert(scene.primitives.back().name).second) {
      throw std::runtime_error("primitives[" + std::to_string(i) + "]: duplicate name '" +
                               scene.primitives.back().name + "'");
    }
  }
  return scene;
}

Scene readSceneYaml(const std::string& path) {
  std::ifstream in(path);
  if (!in)
    throw std::runtime_error("cannot open scene file " + path);
  std::stringstream text;
  text << in.rdbuf();
  try {
    return parseSceneYaml(text.str());
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

std::string sceneYamlString(const Scene& scene) {
  YAML::Emitter out;
  out.SetDoublePrecision(15);
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << scene.name;
  const CameraIntrinsics& c = scene.camera;
  out << YAML::Key << "camera" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "width" << YAML::Value << c.width << YAML::Key << "height" << YAML::Value
      << c.height << YAML::Key << "fx" << YAML::Value << c.fx << YAML::Key << "fy" << YAML::Value
      << c.fy << YAML::Key << "cx" << YAML::Value << c.cx << YAML::Key << "cy" << YAML::Value
      << c.cy << YAML::Key << "rate" << YAML::Value << scene.rate;
  out << YAML::EndMap;
  out << YAML::Key << "centre_of_interest" << YAML::Value;
  emitVec(out, scene.centre_of_interest);
  out << YAML::Key << "background" << YAML::Value;
  emitVec(out, scene.background);
  const HandheldTrajectory::Params& h = scene.handheld;
  out << YAML::Key << "handheld" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "distance" << YAML::Value << h.distance << YAML::Key << "height"
      << YAML::Value << h.height << YAML::Key << "azimuth" << YAML::Value << h.azimuth << YAML::Key
      << "sweep" << YAML::Value << h.sweep << YAML::Key << "sweep_period" << YAML::Value
      << h.sweep_period << YAML::Key << "wobble" << YAML::Value << h.wobble << YAML::Key
      << "gaze_wobble" << YAML::Value << h.gaze_wobble << YAML::Key << "roll_wobble" << YAML::Value
      << h.roll_wobble << YAML::Key << "start_stamp" << YAML::Value << h.start_stamp;
  out << YAML::EndMap;
  const KinectDepthModel::Params& d = scene.depth;
  out << YAML::Key << "depth_noise" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "min_range" << YAML::Value << d.min_range << YAML::Key << "max_range"
      << YAML::Value << d.max_range << YAML::Key << "sigma_constant" << YAML::Value
      << d.sigma_constant << YAML::Key << "sigma_quadratic" << YAML::Value << d.sigma_quadratic
      << YAML::Key << "sigma_reference_depth" << YAML::Value << d.sigma_reference_depth << YAML::Key
      << "focal_px" << YAML::Value << d.focal_px << YAML::Key << "baseline" << YAML::Value
      << d.baseline << YAML::Key << "disparity_resolution" << YAML::Value << d.disparity_resolution
      << YAML::Key << "max_incidence" << YAML::Value << d.max_incidence << YAML::Key
      << "edge_dropout_px" << YAML::Value << d.edge_dropout_px << YAML::Key << "edge_jump_ratio"
      << YAML::Value << d.edge_jump_ratio << YAML::Key << "dropout_probability" << YAML::Value
      << d.dropout_probability << YAML::Key << "sigma_scale" << YAML::Value << d.sigma_scale
      << YAML::Key << "distortion_r2" << YAML::Value << d.distortion_r2 << YAML::Key
      << "distortion_r4" << YAML::Value << d.distortion_r4 << YAML::Key << "pattern_amplitude"
      << YAML::Value << d.pattern_amplitude << YAML::Key << "pattern_wavelength_px" << YAML::Value
      << d.pattern_wavelength_px << YAML::Key << "pattern_seed" << YAML::Value << d.pattern_seed
      << YAML::Key << "correlated_fraction" << YAML::Value << d.correlated_fraction << YAML::Key
      << "correlation_px" << YAML::Value << d.correlation_px << YAML::Key << "projector_side"
      << YAML::Value << d.projector_side;
  out << YAML::EndMap;
  out << YAML::Key << "primitives" << YAML::Value << YAML::BeginSeq;
  for (const PrimitiveSpec& p : scene.primitives) {
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << p.name;
    out << YAML::Key << "type" << YAML::Value << toString(p.type);
    out << YAML::Key << "position" << YAML::Value;
    emitVec(out, p.T_world_primitive.translation());
    const Eigen::Vector3d ypr = p.T_world_primitive.rotation().eulerAngles(2, 1, 0);
    out << YAML::Key << "rpy" << YAML::Value;
    emitVec(out, Eigen::Vector3d(ypr.z(), ypr.y(), ypr.x()));
    switch (p.type) {
      case PrimitiveType::kRectangle:
        out << YAML::Key << "size" << YAML::Value << YAML::Flow << YAML::BeginSeq << p.size.y()
            << p.size.z() << YAML::EndSeq;
        break;
      case PrimitiveType::kBox:
        out << YAML::Key << "size" << YAML::Value;
        emitVec(out, p.size);
        break;
      case PrimitiveType::kSphere:
        out << YAML::Key << "radius" << YAML::Value << p.radius;
        break;
      case PrimitiveType::kCylinder:
        out << YAML::Key << "radius" << YAML::Value << p.radius << YAML::Key << "length"
            << YAML::Value << p.length << YAML::Key << "capped" << YAML::Value << p.capped;
        break;
      case PrimitiveType::kCone:
        out << YAML::Key << "half_angle" << YAML::Value << p.half_angle << YAML::Key << "z_min"
            << YAML::Value << p.z_min << YAML::Key << "z_max" << YAML::Value << p.z_max;
        break;
      case PrimitiveType::kEllipsoid:
        out << YAML::Key << "radii" << YAML::Value;
        emitVec(out, p.radii);
        break;
    }
    out << YAML::Key << "colour" << YAML::Value;
    emitVec(out, p.material.colour);
    if (p.material.texture != Texture::kNone) {
      out << YAML::Key << "texture" << YAML::Value << YAML::BeginMap;
      out << YAML::Key << "type" << YAML::Value
          << (p.material.texture == Texture::kChecker ? "checker" : "noise");
      out << YAML::Key << "colour" << YAML::Value;
      emitVec(out, p.material.colour2);
      out << YAML::Key << "scale" << YAML::Value << p.material.texture_scale;
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void writeSceneYaml(const Scene& scene, const std::string& path) {
  std::ofstream out(path);
  if (!out)
    throw std::runtime_error("cannot write scene file " + path);
  out << sceneYamlString(scene);
  if (!out)
    throw std::runtime_error("failed writing scene file " + path);
}

}  // namespace quadric_slam
