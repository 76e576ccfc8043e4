#include "pspslam/session/frame_log.h"

#include <algorithm>
#include <cstdio>

#include <unistd.h>

#include "pspslam/core/error.h"

namespace pspslam {

std::ofstream open_output(const std::filesystem::path& file) {
  std::ofstream stream(file);
  if (!stream) throw Error(file.string() + ": cannot write output file");
  return stream;
}

namespace {
constexpr const char* kLostHeader =
    "# frames without a pose (tracking not initialised or lost): index timestamp state\n";
}  // namespace

FrameLog::FrameLog(const std::filesystem::path& folder)
    : trajectory_(folder / "trajectory.txt"),
      lost_path_(folder / "lost_frames.txt"),
      lost_(open_output(lost_path_)),
      timing_(open_output(folder / "timing.csv")) {
  lost_ << kLostHeader;
  timing_
      << "index,timestamp,state,method,keypoints,inliers,keyframe,extraction_ms,tracking_ms,"
         "local_ba_ms,mapping_queue,extraction_cpu_ms,tracking_cpu_ms,flow_ms,semantic_wait_"
         "ms,mask_age,geometry_ms,tested,dynamic,masked_keypoints,culled_points,arrival_to_pose_"
         "ms,keyframes_in_map,map_points,rss_mib\n";
}

void FrameLog::write(size_t index, Timestamp timestamp, const FrameReport& report,
                     double local_ba_ms, const MappingStats& mapping,
                     std::optional<double> arrival_to_pose_ms) {
  const TrackResult& result = report.tracking;
  if (result.T_world_camera) {
    trajectory_.write(timestamp, *result.T_world_camera);
    posed_.emplace_back(index, timestamp);
  } else {
    write_lost({index, timestamp, to_string(result.state)});
    lost_ << std::flush;
  }
  const DynamicReport& dyn = report.dynamic;
  char row[384];
  std::snprintf(row, sizeof(row),
                "%zu,%.6f,%s,%s,%d,%d,%d,%.3f,%.3f,%.3f,%zu,%.3f,%.3f,%.3f,%.3f,%d,%.3f,%d,%d,%d,"
                "%d,",
                index, timestamp, to_string(result.state), to_string(result.method),
                result.num_keypoints, result.num_inliers, result.keyframe_inserted ? 1 : 0,
                report.extraction_ms, report.tracking_ms, local_ba_ms, mapping.queued_keyframes,
                report.extraction_cpu_ms, report.tracking_cpu_ms, dyn.flow_ms, dyn.semantic_wait_ms,
                dyn.mask_age_frames, dyn.geometry_ms, dyn.tested_points, dyn.dynamic_points,
                dyn.masked_keypoints, dyn.culled_map_points);
  timing_ << row;
  // Empty where a frame has no arrival time (deterministic runs).
  if (arrival_to_pose_ms) {
    std::snprintf(row, sizeof(row), "%.3f", *arrival_to_pose_ms);
    timing_ << row;
  }
  std::snprintf(row, sizeof(row), ",%zu,%zu,%.1f\n", mapping.keyframes_in_map, mapping.map_points,
                resident_mib());
  timing_ << row;
}

double FrameLog::resident_mib() {
  const auto now = std::chrono::steady_clock::now();
  if (!resident_read_at_ || now - *resident_read_at_ >= std::chrono::seconds(1)) {
    resident_mib_ = read_resident_mib();
    resident_read_at_ = now;
  }
  return resident_mib_;
}

double read_resident_mib() {
  std::FILE* file = std::fopen("/proc/self/statm", "r");
  if (file == nullptr) return 0.0;
  unsigned long size = 0;
  unsigned long resident = 0;
  const int read = std::fscanf(file, "%lu %lu", &size, &resident);
  std::fclose(file);
  if (read != 2) return 0.0;
  const long page = sysconf(_SC_PAGESIZE);
  return static_cast<double>(resident) * static_cast<double>(page) / (1024.0 * 1024.0);
}

void FrameLog::write_lost(const LostLine& line) {
  char text[96];
  std::snprintf(text, sizeof(text), "%zu %.6f %s\n", line.index, line.timestamp, line.state);
  lost_ << text;
  lost_lines_.push_back(line);
}

void FrameLog::write_earlier(const std::vector<StampedPose>& poses) {
  if (poses.empty()) return;
  for (const StampedPose& pose : poses) {
    // The frame was written as lost when it was processed (same timestamp, bit for bit).
    const auto line = std::find_if(lost_lines_.begin(), lost_lines_.end(), [&](const LostLine& l) {
      return l.timestamp == pose.timestamp;
    });
    if (line == lost_lines_.end()) continue;
    trajectory_.write(pose);
    posed_.emplace_back(line->index, pose.timestamp);
    lost_lines_.erase(line);
  }
  std::vector<LostLine> kept;
  kept.swap(lost_lines_);
  lost_.close();
  lost_ = open_output(lost_path_);
  lost_ << kLostHeader;
  for (const LostLine& line : kept) write_lost(line);
  lost_ << std::flush;
}

void FrameLog::forget_poses() {
  trajectory_.clear();
  for (const auto& [index, timestamp] : posed_) write_lost({index, timestamp, "restarted"});
  lost_ << std::flush;
  posed_.clear();
}

}  // namespace pspslam
