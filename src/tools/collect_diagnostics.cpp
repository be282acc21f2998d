// collect_diagnostics: keeps the latest /diagnostics report of every status name and writes them
// all to a YAML file when it is stopped (SIGINT / SIGTERM / rosnode kill). The reports are
// periodic and cumulative, so the last one of each name holds the totals of the run: this is how
// scripts/bench_live reads what each nodelet processed.
//
//   rosrun quadric_slam collect_diagnostics OUT.yaml [SERIES.csv]
//
// SERIES.csv (optional, for long runs): one row per status received, as it arrives:
//   wall_s (since the start), name, frames processed, processing median and p95 (ms), landmarks,
//   reconstruction points and the process's heap in use in MB (the mapper's)
// (a field the status does not carry is left empty).
//
// OUT.yaml: {<status name>: {level: <0 OK, 1 WARN, 2 ERROR, 3 STALE>, message: <text>,
//            values: {<key>: <value as text>, ...}}, ...}
#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <string>

int main(int argc, char** argv) {
  ros::init(argc, argv, "collect_diagnostics", ros::init_options::AnonymousName);
  if (argc != 2 && argc != 3) {
    std::fprintf(stderr, "usage: collect_diagnostics OUT.yaml [SERIES.csv]\n");
    return 2;
  }
  const std::string out_path = argv[1];
  std::ofstream series;
  if (argc == 3) {
    series.open(argv[2]);
    series << "wall_s,name,frames_processed,median_ms,p95_ms,landmarks,reconstruction_points,"
              "heap_in_use_mb\n";
  }
  const ros::WallTime start = ros::WallTime::now();
  const auto value = [](const diagnostic_msgs::DiagnosticStatus& status, const std::string& key) {
    for (const auto& kv : status.values)
      if (kv.key == key)
        return kv.value;
    return std::string();
  };
  ros::NodeHandle nh;
  std::mutex mutex;
  std::map<std::string, diagnostic_msgs::DiagnosticStatus> latest;
  // Every reporting node publishes each period: a queue that holds a few periods of them.
  const ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&](const diagnostic_msgs::DiagnosticArrayConstPtr& array) {
        std::lock_guard<std::mutex> lock(mutex);
        for (const auto& status : array->status) {
          latest[status.name] = status;
          if (series.is_open()) {
            series << (ros::WallTime::now() - start).toSec() << ",\"" << status.name << "\","
                   << value(status, "frames processed") << ','
                   << value(status, "processing time median (ms)") << ','
                   << value(status, "processing time p95 (ms)") << ',' << value(status, "landmarks")
                   << ',' << value(status, "reconstruction points") << ','
                   << value(status, "process heap in use (MB)") << '\n';
          }
        }
      });
  ros::spin();

  YAML::Emitter yaml;
  yaml << YAML::BeginMap;
  for (const auto& [name, status] : latest) {
    yaml << YAML::Key << name << YAML::Value << YAML::BeginMap;
    yaml << YAML::Key << "level" << YAML::Value << static_cast<int>(status.level);
    yaml << YAML::Key << "message" << YAML::Value << status.message;
    yaml << YAML::Key << "values" << YAML::Value << YAML::BeginMap;
    for (const auto& kv : status.values)
      yaml << YAML::Key << kv.key << YAML::Value << kv.value;
    yaml << YAML::EndMap << YAML::EndMap;
  }
  yaml << YAML::EndMap;
  std::ofstream out(out_path);
  out << yaml.c_str() << "\n";
  if (!out) {
    std::fprintf(stderr, "collect_diagnostics: cannot write %s\n", out_path.c_str());
    return 1;
  }
  std::printf("collect_diagnostics: %zu statuses written to %s\n", latest.size(), out_path.c_str());
  return 0;
}
