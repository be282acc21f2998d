// synth: renders a synthetic RGB-D sequence of a quadric scene in the TUM RGB-D layout (rosbag
// and folder), with ground truth for the trajectory (groundtruth.txt, /tf) and for every
// primitive (quadrics_gt.yaml, labels/). See `synth --help`.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "quadric_slam/io/map_yaml.h"
#include "quadric_slam/ros/tum_bag_writer.h"
#include "quadric_slam/sim/renderer.h"
#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/sequence_generator.h"
#include "quadric_slam/sim/surfaces.h"
#include "quadric_slam/sim/tum_folder_writer.h"

namespace qs = quadric_slam;

namespace {

const char* kUsage = R"(usage: synth --out DIR [options]
Renders a synthetic Kinect-like RGB-D sequence in the TUM RGB-D layout.
  --out DIR              output directory (required)
  --scene FILE           scene YAML (default config/scenes/desk.yaml of the package)
  --trajectory FILE|handheld
                         TUM ground-truth file resampled at the frame rate from its first stamp,
                         or the scene's seeded hand-held motion (default handheld)
  --seconds S            length of the sequence (default 10)
  --seed N               seed of the depth noise and the hand-held motion (default 1)
  --name NAME            sequence name, the bag is DIR/NAME.bag (default: the scene's name)
  --no-bag               do not write the rosbag
  --no-folder            do not write rgb/, depth/, rgb.txt, depth.txt
  --no-labels            do not write labels/
  --no-noise             depth without the Kinect model (true depth everywhere)
  --depth-model M        harsh | nguyen: the depth model's preset, replacing the scene's
                         depth_noise model terms (default: the scene's, harsh when not given)
  --threads N            worker threads (default: all cores)
  --png-compression N    PNG compression level 0..9 (default 1)
  --bag-compression C    none | lz4 | bz2 (default none)
  --width W --height H --fx F --fy F --cx C --cy C --rate HZ
                         override the scene's camera (defaults 640 480 525 525 319.5 239.5 30)
Writes DIR/NAME.bag, DIR/{rgb,depth,labels}/<stamp>.png, DIR/{rgb,depth,groundtruth}.txt,
DIR/quadrics_gt.yaml (map schema) and DIR/scene.yaml (the effective scene).
)";

struct Options {
  std::string out, scene, trajectory = "handheld", name, depth_model;
  double seconds = 10.0;
  std::uint64_t seed = 1;
  bool bag = true, folder = true, labels = true, noise = true;
  int threads = 0, png_compression = 1;
  std::string bag_compression = "none";
  std::vector<std::pair<std::string, double>> camera_overrides;
};

// The package's desk scene (CMake passes the config folder).
std::string defaultScene() {
  return std::string(QUADRIC_SLAM_CONFIG_DIR) + "/scenes/desk.yaml";
}

Options parse(int argc, char** argv) {
  Options o;
  auto value = [&](int& i) -> std::string {
    if (i + 1 >= argc)
      throw std::invalid_argument(std::string(argv[i]) + " needs a value");
    return argv[++i];
  };
  auto number = [&](int& i) {
    const std::string flag = argv[i], text = value(i);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0')
      throw std::invalid_argument(flag + ": '" + text + "' is not a number");
    return v;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      std::exit(0);
    } else if (a == "--out") {
      o.out = value(i);
    } else if (a == "--scene") {
      o.scene = value(i);
    } else if (a == "--trajectory") {
      o.trajectory = value(i);
    } else if (a == "--seconds") {
      o.seconds = number(i);
      if (!(o.seconds > 0.0))
        throw std::invalid_argument("--seconds must be > 0");
    } else if (a == "--seed") {
      const double s = number(i);
      if (s < 0 || s != static_cast<double>(static_cast<std::uint64_t>(s)))
        throw std::invalid_argument("--seed must be a non-negative integer");
      o.seed = static_cast<std::uint64_t>(s);
    } else if (a == "--name") {
      o.name = value(i);
    } else if (a == "--no-bag") {
      o.bag = false;
    } else if (a == "--no-folder") {
      o.folder = false;
    } else if (a == "--no-labels") {
      o.labels = false;
    } else if (a == "--depth-model") {
      o.depth_model = value(i);
      qs::KinectDepthModel::paramsForModel(o.depth_model);  // throws for an unknown name
    } else if (a == "--no-noise") {
      o.noise = false;
    } else if (a == "--threads") {
      o.threads = static_cast<int>(number(i));
      if (o.threads < 1)
        throw std::invalid_argument("--threads must be >= 1");
    } else if (a == "--png-compression") {
      o.png_compression = static_cast<int>(number(i));
    } else if (a == "--bag-compression") {
      o.bag_compression = value(i);
    } else if (a == "--width" || a == "--height" || a == "--fx" || a == "--fy" || a == "--cx" ||
               a == "--cy" || a == "--rate") {
      o.camera_overrides.emplace_back(a.substr(2), number(i));
    } else {
      throw std::invalid_argument("unknown argument '" + a + "' (see --help)");
    }
  }
  if (o.out.empty())
    throw std::invalid_argument("--out DIR is required (see --help)");
  if (o.scene.empty())
    o.scene = defaultScene();
  if (o.threads == 0)
    o.threads = std::max(1u, std::thread::hardware_concurrency());
  return o;
}

void applyCameraOverrides(const Options& o, qs::Scene* scene) {
  for (const auto& [key, v] : o.camera_overrides) {
    if (key == "width")
      scene->camera.width = static_cast<int>(v);
    else if (key == "height")
      scene->camera.height = static_cast<int>(v);
    else if (key == "fx")
      scene->camera.fx = v;
    else if (key == "fy")
      scene->camera.fy = v;
    else if (key == "cx")
      scene->camera.cx = v;
    else if (key == "cy")
      scene->camera.cy = v;
    else if (key == "rate")
      scene->rate = v;
  }
  if (!scene->camera.valid())
    throw std::invalid_argument("camera: " + scene->camera.problem());
  if (!(scene->rate > 0.0))
    throw std::invalid_argument("--rate must be > 0 Hz");
}

int run(int argc, char** argv) {
  const Options o = parse(argc, argv);
  qs::Scene scene = qs::readSceneYaml(o.scene);
  applyCameraOverrides(o, &scene);
  if (!o.depth_model.empty())
    qs::KinectDepthModel::applyModel(o.depth_model, &scene.depth);
  const std::string name = o.name.empty() ? scene.name : o.name;

  std::vector<qs::StampedPose> poses;
  if (o.trajectory == "handheld") {
    poses = qs::HandheldTrajectory(scene.handheld)
                .generate(scene.centre_of_interest, scene.rate, o.seconds, o.seed);
  } else {
    poses = qs::resampleTrajectory(qs::readDrivingTrajectory(o.trajectory), scene.rate, o.seconds);
  }
  if (poses.empty())
    throw std::runtime_error("the trajectory gives no frames");

  qs::Renderer::Params render_params;
  render_params.noise = o.noise;
  const qs::Renderer renderer(qs::buildSurfaces(scene), scene.camera, scene.depth, render_params,
                              scene.background);

  qs::TumFolderWriter::Params folder_params;
  folder_params.images = o.folder;
  folder_params.labels = o.labels;
  folder_params.png_compression = o.png_compression;
  folder_params.sequence_name = name;
  folder_params.camera = scene.camera;
  const qs::TumFolderWriter folder(o.out, folder_params);

  std::unique_ptr<qs::TumBagWriter> bag;
  qs::TumBagWriter::Params bag_params;
  bag_params.compression = o.bag_compression;
  const std::string bag_path = o.out + "/" + name + ".bag";
  if (o.bag)
    bag = std::make_unique<qs::TumBagWriter>(bag_path, scene.camera, bag_params);

  qs::SequenceGenerator::Params generator_params;
  generator_params.threads = o.threads;
  generator_params.max_in_flight = std::max(8, 2 * o.threads);
  generator_params.seed = o.seed;
  const qs::SequenceGenerator generator(renderer, generator_params);

  std::printf("synth: scene %s, %zu surfaces, %zu frames at %.1f Hz, %d threads -> %s\n",
              o.scene.c_str(), renderer.surfaces().size(), poses.size(), scene.rate, o.threads,
              o.out.c_str());
  std::fflush(stdout);
  const qs::SequenceGenerator::Stats stats = generator.run(
      poses,
      [&](std::size_t, const qs::StampedPose& pose, const qs::RenderedFrame& frame) {
        folder.writeFrame(pose, frame);
      },
      [&](std::size_t, const qs::StampedPose& pose, const qs::RenderedFrame& frame) {
        if (bag)
          bag->write(pose, frame);
      });
  if (bag)
    bag->close();
  folder.finish(poses);

  qs::MapFile truth;
  truth.frame_id = "world";
  for (const qs::Surface& s : renderer.surfaces()) {
    qs::MapFileQuadric q = s.toMapQuadric();
    q.observations = stats.observations[s.id()];
    q.large_views = stats.large_views[s.id()];
    truth.quadrics.push_back(q);
  }
  qs::writeMapYaml(truth, o.out + "/quadrics_gt.yaml");
  qs::writeSceneYaml(scene, o.out + "/scene.yaml");

  const double n = static_cast<double>(poses.size());
  std::printf(
      "timing: %zu frames in %.2f s wall (%.1f frames/s); summed over threads: render "
      "%.2f s, png %.2f s; bag %.2f s\n",
      poses.size(), stats.wall_seconds, n / stats.wall_seconds, stats.render_seconds,
      stats.per_frame_seconds, stats.ordered_seconds);
  std::printf("coverage (frames with >= 1 labelled pixel with valid depth):\n");
  std::printf("  %3s  %-22s %-10s %7s %7s %12s\n", "id", "name", "class", "frames", "share",
              "mean pixels");
  for (const qs::Surface& s : renderer.surfaces()) {
    const int seen = stats.observations[s.id()];
    std::printf("  %3d  %-22s %-10s %7d %6.1f%% %12.0f\n", s.id(), s.name().c_str(),
                s.toMapQuadric().quadric_class.c_str(), seen, 100.0 * seen / n,
                stats.pixels[s.id()] / n);
  }
  if (bag)
    std::printf("wrote %s\n", bag_path.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "synth: %s\n", e.what());
    return 1;
  }
}
