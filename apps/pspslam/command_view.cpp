// `pspslam view`: shows a finished run in the browser. The viewer's HTTP server (viewer/, the
// one `run --viewer` uses) serves the page in web/ and JSON built once from the run's output
// files, so nothing of SLAM runs here.
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include <Eigen/Geometry>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "commands.h"
#include "pspslam/core/error.h"
#include "pspslam/core/interrupt.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/eval/ate.h"
#include "pspslam/io/point_cloud_ply.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/viewer/endpoint.h"
#include "pspslam/viewer/web_server.h"

namespace pspslam::cli {

namespace {

namespace fs = std::filesystem;

struct ViewOptions {
  std::string run_dir;
  std::string viewer = "8080";
  std::string gt_file;
};

nlohmann::json poses_json(const Trajectory& trajectory) {
  nlohmann::json poses = nlohmann::json::array();
  for (const StampedPose& pose : trajectory) {
    const Eigen::Vector3d p = pose.T_world_camera.translation();
    const Eigen::Quaterniond q(pose.T_world_camera.rotation());
    poses.push_back(
        {{"t", pose.timestamp}, {"p", {p.x(), p.y(), p.z()}}, {"q", {q.x(), q.y(), q.z(), q.w()}}});
  }
  return poses;
}

// A trajectory the run may not have written (an interrupted run has no keyframes.txt): empty.
Trajectory read_if_present(const fs::path& file) {
  return fs::is_regular_file(file) ? read_tum_trajectory(file) : Trajectory{};
}

nlohmann::json read_stats(const fs::path& run_dir) {
  const fs::path file = run_dir / "stats.json";
  if (!fs::is_regular_file(file)) return nlohmann::json::object();
  try {
    std::ifstream stream(file);
    return nlohmann::json::parse(stream);
  } catch (const nlohmann::json::exception& e) {
    throw Error(file.string() + ": not valid JSON: " + e.what());
  }
}

nlohmann::json map_json(const fs::path& run_dir) {
  nlohmann::json map = {{"positions", nlohmann::json::array()},
                        {"colors", nlohmann::json::array()}};
  const fs::path file = run_dir / "map.ply";
  if (!fs::is_regular_file(file)) return map;
  // Flat arrays: they go straight into a three.js BufferAttribute.
  for (const ColoredPoint& point : read_point_cloud_ply(file)) {
    for (int i = 0; i < 3; ++i) map["positions"].push_back(point.position[i]);
    map["colors"].push_back(point.red);
    map["colors"].push_back(point.green);
    map["colors"].push_back(point.blue);
  }
  return map;
}

// The ground truth moved into the estimate's frame (the inverse of the ATE alignment, which maps
// the estimate onto the ground truth), so the map and the estimate keep their own coordinates.
nlohmann::json ground_truth_json(const fs::path& gt_file, const Trajectory& estimate) {
  nlohmann::json result = {{"file", gt_file.string()}, {"positions", nlohmann::json::array()}};
  if (gt_file.empty() || estimate.empty()) return result;
  const AteResult ate = compute_ate(read_tum_trajectory(gt_file), estimate);
  for (const Eigen::Vector3d& g : ate.gt_all) {
    const Eigen::Vector3d p = ate.alignment.inverse_apply(g);
    result["positions"].push_back({p.x(), p.y(), p.z()});
  }
  result["ate_rmse"] = ate.error.rmse;
  return result;
}

// --gt, else the sequence's own groundtruth.txt named by stats.json, else none.
fs::path ground_truth_file(const ViewOptions& options, const nlohmann::json& stats) {
  if (!options.gt_file.empty()) {
    if (!fs::is_regular_file(options.gt_file)) throw Error(options.gt_file + ": no such file");
    return options.gt_file;
  }
  if (stats.contains("sequence") && stats["sequence"].is_string()) {
    const fs::path candidate = fs::path(stats["sequence"].get<std::string>()) / "groundtruth.txt";
    std::error_code failure;
    if (fs::is_regular_file(candidate, failure)) return candidate;
  }
  return {};
}

// Everything the API serves, built once: the run is finished, so the answers never change and
// the server threads only read these strings.
struct RunData {
  std::string trajectory, stats, map, ground_truth;
  size_t poses = 0;
};

RunData load_run(const ViewOptions& options) {
  const fs::path run_dir = options.run_dir;
  if (!fs::is_regular_file(run_dir / "trajectory.txt")) {
    throw Error(options.run_dir +
                ": not a run folder (no trajectory.txt; make one with 'pspslam "
                "run --out " +
                options.run_dir + "')");
  }
  const Trajectory online = read_tum_trajectory(run_dir / "trajectory.txt");
  const Trajectory refined = read_if_present(run_dir / "trajectory_refined.txt");
  const nlohmann::json stats = read_stats(run_dir);
  RunData data;
  data.poses = online.size();
  data.trajectory =
      nlohmann::json{{"online", poses_json(online)},
                     {"refined", poses_json(refined)},
                     {"keyframes", poses_json(read_if_present(run_dir / "keyframes.txt"))}}
          .dump();
  data.stats = stats.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  data.map = map_json(run_dir).dump();
  const fs::path gt_file = ground_truth_file(options, stats);
  try {
    data.ground_truth = ground_truth_json(gt_file, refined.empty() ? online : refined).dump();
  } catch (const Error& e) {
    // Too few associated poses should not keep the rest of the run from being shown.
    spdlog::warn("ground truth not shown: {}", e.what());
    data.ground_truth = ground_truth_json({}, {}).dump();
  }
  return data;
}

int view(const ViewOptions& options) {
  parse_endpoint(options.viewer);  // a bad --viewer is told before the run is read
  WebServer server(data_dir() / "web");
  const RunData data = load_run(options);
  const auto json_route = [&server](const std::string& route, std::string body) {
    auto shared = std::make_shared<const std::string>(std::move(body));
    server.get(route, [shared](const WebServer::Query&) {
      return HttpReply{200, "application/json", shared};
    });
  };
  json_route("/api/trajectory", data.trajectory);
  json_route("/api/stats", data.stats);
  json_route("/api/map", data.map);
  json_route("/api/groundtruth", data.ground_truth);
  // The guard exists before the address is printed: a Ctrl-C from then on stops the server
  // cleanly instead of killing the process.
  InterruptGuard guard;
  const std::string url = server.listen(options.viewer);
  std::cout << "viewer: " << url << "  (" << data.poses << " poses; Ctrl-C stops)" << std::endl;
  while (!interrupted()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  server.stop();
  clear_interrupt();
  std::cout << "viewer stopped" << std::endl;
  return 0;
}

}  // namespace

Command add_view_command(CLI::App& root) {
  CLI::App* app = root.add_subcommand(
      "view",
      "show a finished run in the browser (no SLAM runs).\n"
      "Serves a 3D view of RUN_DIR's map (map.ply, from 'run --export-map RUN_DIR/map.ply'), "
      "keyframes,\ntrajectory and aligned ground truth, with the counters of stats.json.");
  auto options = std::make_shared<ViewOptions>();
  app->add_option("RUN_DIR", options->run_dir, "output folder of 'pspslam run --out'")->required();
  app->add_option("--viewer", options->viewer,
                  "[HOST:]PORT to listen on (host 127.0.0.1 unless given; port 0: any free one)")
      ->capture_default_str();
  app->add_option("--gt", options->gt_file,
                  "ground-truth trajectory (default: groundtruth.txt of the sequence named in "
                  "stats.json, when there is one)");
  return {app, [options](const GlobalOptions&) { return view(*options); }};
}

}  // namespace pspslam::cli
