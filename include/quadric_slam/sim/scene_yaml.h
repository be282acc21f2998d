// Scene files for the synthetic sequence generator (config/scenes/*.yaml): the camera, the
// centre of interest, hand-held motion and depth-model settings, and the primitives. Every key
// is checked: unknown keys, missing keys and bad values raise an error naming the key.
#pragma once

#include <string>

#include "quadric_slam/sim/scene.h"

namespace quadric_slam {

// Throws std::runtime_error naming the file (readSceneYaml) and the offending key, e.g.
// "primitives[3] (globe): missing key 'radius'".
Scene readSceneYaml(const std::string& path);
Scene parseSceneYaml(const std::string& text);
// Writes every field (orientation as rpy); parseSceneYaml(sceneYamlString(s)) reproduces s.
std::string sceneYamlString(const Scene& scene);
void writeSceneYaml(const Scene& scene, const std::string& path);

}  // namespace quadric_slam
