// `pspslam run`: SLAM on an RGB-D sequence. Writes into OUT/
//   trajectory.txt   T_world_camera of every tracked frame (TUM), flushed per frame so an
//                    interrupted run leaves a valid file
//   lost_frames.txt  timestamps of frames that got no pose (not initialised yet or lost)
//   keyframes.txt    keyframe poses at the end (after local mapping)
//   trajectory_refined.txt  the frames of trajectory.txt re-expressed through their reference
//                    keyframes after local BA (ORB-SLAM2's saved trajectory), written at the end
//   timing.csv       per frame: extraction / tracking / local BA milliseconds, state
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "pspslam/core/arg_parser.h"
#include "pspslam/core/error.h"
#include "pspslam/core/interrupt.h"
#include "pspslam/core/progress.h"
#include "pspslam/eval/ate.h"
#include "pspslam/io/sequence_setup.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/system/system.h"

namespace pspslam::cli {
namespace {

// Conventional status of a process stopped by SIGINT (128 + 2).
constexpr int kInterruptedExit = 130;

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

std::ofstream open_output(const std::filesystem::path& file) {
  std::ofstream stream(file);
  if (!stream) throw Error(file.string() + ": cannot write output file");
  return stream;
}

}  // namespace

int run_command(const std::vector<std::string>& args) {
  ArgParser parser("pspslam run",
                   "Runs SLAM on an RGB-D sequence in TUM layout (rgb.txt, depth.txt or "
                   "associations.txt,\noptional groundtruth.txt) and writes OUT/trajectory.txt "
                   "(every tracked frame),\nOUT/lost_frames.txt, OUT/keyframes.txt and "
                   "OUT/timing.csv. With ground truth, prints ATE.");
  parser.add_option("sequence", "sequence folder", "", true);
  parser.add_option("config",
                    "camera/system config YAML (default: SEQUENCE/config.yaml when it exists, "
                    "else required; presets in config/)");
  parser.add_option("out", "output folder", "pspslam_out");
  parser.add_option("max-frames", "process at most this many frames (0 = all)", "0");
  parser.add_switch("no-local-mapping",
                    "track only: keyframes enter the map but are never refined (debugging)");
  if (!parser.parse(args)) return 0;
  const int max_frames_flag = parser.get_int("max-frames");
  if (max_frames_flag < 0)
    throw Error("--max-frames must be >= 0, got " + parser.get("max-frames"));

  const std::optional<std::filesystem::path> config =
      parser.has("config") ? std::optional<std::filesystem::path>(parser.get("config"))
                           : std::nullopt;
  const SequenceSetup setup = open_sequence_with_config(parser.get("sequence"), config, &std::cerr);
  const RgbdSequence& sequence = setup.sequence;
  const PinholeCamera& camera = setup.config.camera.pinhole;
  const size_t frames = max_frames_flag == 0
                            ? sequence.size()
                            : std::min(sequence.size(), static_cast<size_t>(max_frames_flag));

  const std::filesystem::path out_dir = parser.get("out");
  std::filesystem::create_directories(out_dir);
  TrajectoryWriter trajectory(out_dir / "trajectory.txt");
  std::ofstream lost = open_output(out_dir / "lost_frames.txt");
  lost << "# frames without a pose (tracking not initialised or lost): index timestamp state\n";
  std::ofstream timing = open_output(out_dir / "timing.csv");
  timing << "index,timestamp,state,method,keypoints,inliers,keyframe,extraction_ms,tracking_ms,"
            "local_ba_ms,mapping_queue,extraction_cpu_ms,tracking_cpu_ms\n";
  std::cout << describe_sequence(setup);

  SystemOptions system_options;
  system_options.local_mapping = !parser.flag("no-local-mapping");
  System system(setup.config, system_options);
  InterruptGuard interrupt_guard;
  ProgressBar progress("slam", frames, std::cerr);
  std::vector<double> extraction_ms;
  std::vector<double> tracking_ms;
  std::vector<double> tracking_cpu_ms;
  Trajectory estimate;
  size_t processed = 0;
  size_t lost_count = 0;
  double ba_ms_before = 0.0;
  const auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < frames; ++i) {
    if (interrupted()) break;
    const RgbdFrame frame = sequence.load(i);
    if (frame.bgr.cols != camera.width || frame.bgr.rows != camera.height) {
      throw Error((sequence.directory() / sequence.files(i).rgb_file).string() + " is " +
                  std::to_string(frame.bgr.cols) + "x" + std::to_string(frame.bgr.rows) +
                  " but the config " + setup.config_file.string() + " says camera " +
                  std::to_string(camera.width) + "x" + std::to_string(camera.height));
    }
    const FrameReport report = system.track(frame);
    const TrackResult& result = report.tracking;
    if (result.T_world_camera) {
      trajectory.write(frame.timestamp, *result.T_world_camera);
      estimate.push_back({frame.timestamp, *result.T_world_camera});
    } else {
      ++lost_count;
      char line[96];
      std::snprintf(line, sizeof(line), "%zu %.6f %s\n", i, frame.timestamp,
                    to_string(result.state));
      lost << line << std::flush;
    }
    const MappingStats mapping = system.mapping_stats();
    char row[256];
    std::snprintf(row, sizeof(row), "%zu,%.6f,%s,%s,%d,%d,%d,%.3f,%.3f,%.3f,%zu,%.3f,%.3f\n", i,
                  frame.timestamp, to_string(result.state), to_string(result.method),
                  result.num_keypoints, result.num_inliers, result.keyframe_inserted ? 1 : 0,
                  report.extraction_ms, report.tracking_ms,
                  mapping.local_ba_ms_total - ba_ms_before, mapping.queued_keyframes,
                  report.extraction_cpu_ms, report.tracking_cpu_ms);
    timing << row;
    ba_ms_before = mapping.local_ba_ms_total;
    extraction_ms.push_back(report.extraction_ms);
    tracking_ms.push_back(report.tracking_ms);
    tracking_cpu_ms.push_back(report.tracking_cpu_ms);
    ++processed;
    progress.update(processed);
  }
  progress.finish();
  system.shutdown();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_tum_trajectory(out_dir / "keyframes.txt", system.keyframe_trajectory());
  const Trajectory refined = system.refined_trajectory();
  write_tum_trajectory(out_dir / "trajectory_refined.txt", refined);
  const MappingStats mapping = system.mapping_stats();

  char line[512];
  std::snprintf(line, sizeof(line),
                "frames:       %zu processed, %zu tracked, %zu without pose (lost_frames.txt)\n"
                "speed:        %.1f fps overall (%.1f s)\n"
                "median ms:    extraction %.2f, tracking %.2f (tracking thread CPU %.2f)\n"
                "map:          %zu keyframes, %zu map points; mapping queue max %zu, local BA "
                "%.0f ms total\n",
                processed, processed - lost_count, lost_count,
                seconds > 0 ? processed / seconds : 0.0, seconds, median(extraction_ms),
                median(tracking_ms), median(tracking_cpu_ms), mapping.keyframes_in_map,
                mapping.map_points, mapping.max_queued_keyframes, mapping.local_ba_ms_total);
  std::cout << line;
  std::snprintf(line, sizeof(line),
                "mapping:      %zu keyframes processed, %zu culled; points: %zu triangulated, "
                "%zu fused, %zu culled, %zu BA outlier observations removed\n",
                mapping.processed_keyframes, mapping.keyframes_culled, mapping.points_triangulated,
                mapping.points_fused, mapping.points_culled, mapping.ba_outliers_removed);
  std::cout << line;
  std::cout << "output:       " << (out_dir / "trajectory.txt").string() << " ("
            << trajectory.count()
            << " poses), trajectory_refined.txt, keyframes.txt, lost_frames.txt, timing.csv\n";
  if (sequence.ground_truth() && estimate.size() >= 3) {
    const std::pair<const char*, const Trajectory*> evaluated[] = {
        {"trajectory.txt        ", &estimate}, {"trajectory_refined.txt", &refined}};
    for (const auto& [name, poses] : evaluated) {
      try {
        const AteResult ate = compute_ate(*sequence.ground_truth(), *poses);
        std::snprintf(line, sizeof(line),
                      "ATE %s (SE(3) aligned, %zu poses): RMSE %.4f m, mean %.4f m, median "
                      "%.4f m, max %.4f m\n",
                      name, ate.error.count, ate.error.rmse, ate.error.mean, ate.error.median,
                      ate.error.max);
        std::cout << line;
      } catch (const Error& e) {
        std::cout << "ATE " << name << ": not computed: " << e.what() << "\n";
      }
    }
  }
  if (interrupted()) {
    std::cout << "interrupted after " << processed << " of " << frames
              << " frames; trajectory.txt holds every pose computed so far\n";
    return kInterruptedExit;
  }
  return 0;
}

}  // namespace pspslam::cli
