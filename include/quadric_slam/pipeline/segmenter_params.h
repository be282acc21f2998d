// The QuadricSegmenter parameters by name: one table shared by config/segmentation.yaml, the
// nodelet's private parameters and the offline tools, so every consumer reads the same keys.
#pragma once

#include <string>
#include <vector>

#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/io/param_reader.h"

namespace quadric_slam {

// Every key of config/segmentation.yaml, in file order.
const std::vector<std::string>& segmenterParamNames();
enum class SegmenterParamType { kReal, kInteger, kBool };
// The type of a key (ROS parameters and YAML values must have it). Throws std::invalid_argument
// for an unknown key.
SegmenterParamType segmenterParamType(const std::string& key);
// Value of a key as a double (booleans 0/1, integers exactly). Throws std::invalid_argument for
// an unknown key.
double getSegmenterParam(const QuadricSegmenter::Params& params, const std::string& key);
// Sets a key (integers are rounded, booleans are value != 0). Throws std::invalid_argument for an
// unknown key. Call params.validate() afterwards.
void setSegmenterParam(QuadricSegmenter::Params& params, const std::string& key, double value);
// Reads every key of the table present in reader (private ROS parameters or a YAML file) with its
// type (real, integer or boolean), keeping defaults for the others, logs the effective values and
// validates (std::invalid_argument naming the bad field or a key of the wrong type).
void readSegmentationParams(const ParamReader& reader, QuadricSegmenter::Params& params,
                            ParamLog& log);
// Reads the keys present in a YAML file of the config/segmentation.yaml form (unknown keys throw
// std::invalid_argument naming them; absent keys keep their defaults); validates.
QuadricSegmenter::Params loadSegmenterParams(const std::string& yaml_path);

}  // namespace quadric_slam
