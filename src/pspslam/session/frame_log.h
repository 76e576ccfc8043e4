#pragma once

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <optional>
#include <utility>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/system/system.h"

namespace pspslam {

// The per-frame files of a run, written (and flushed) as frames come, so an interrupted run
// leaves valid files:
//   trajectory.txt   T_world_camera of every tracked frame (TUM), and of the frames a monocular
//                    map placed when it started (write_earlier)
//   lost_frames.txt  frames without a pose (not initialised yet or lost): index timestamp state;
//                    state `restarted` for frames tracked in a monocular map that was restarted
//   timing.csv       per frame, as it was processed (a frame placed later keeps its
//                    not_initialized row): extraction / tracking / local BA milliseconds, state,
//                    the dynamic-scene stages (mask age, geometry time, masked keypoints) and,
//                    for frames that arrived live (--realtime, a camera), arrival to pose;
//                    then keyframes and map points in the map as of the frame, and the
//                    process's resident memory in MiB (read at most once a second)
class FrameLog {
 public:
  // Creates the three files in `folder` (which must exist); throws pspslam::Error naming a file
  // that cannot be written.
  explicit FrameLog(const std::filesystem::path& folder);

  // `local_ba_ms`: local BA time finished since the previous frame; `mapping` as of now;
  // `arrival_to_pose_ms`: from the frame's arrival to its pose, when it had an arrival.
  void write(size_t index, Timestamp timestamp, const FrameReport& report, double local_ba_ms,
             const MappingStats& mapping, std::optional<double> arrival_to_pose_ms);

  // The frame just started the map and placed earlier frames (TrackResult::earlier_frames, oldest
  // first): their poses go to trajectory.txt ahead of the frame's own, and they leave
  // lost_frames.txt (rewritten). Call before write() of the frame that started the map.
  void write_earlier(const std::vector<StampedPose>& poses);

  size_t poses() const { return trajectory_.count(); }
  // A monocular map was restarted (TrackResult::restart_due) by the frame just written: the
  // poses tracked in it leave trajectory.txt and are listed in lost_frames.txt as `restarted`.
  void forget_poses();

 private:
  TrajectoryWriter trajectory_;
  struct LostLine {
    size_t index = 0;
    Timestamp timestamp = 0.0;
    const char* state = "";
  };
  void write_lost(const LostLine& line);

  std::vector<std::pair<size_t, Timestamp>> posed_;  // index, time of each line of trajectory_
  std::filesystem::path lost_path_;
  std::vector<LostLine> lost_lines_;  // every line of lost_, so that it can be rewritten
  std::ofstream lost_;
  std::ofstream timing_;
  // Resident memory is read from /proc at most once a second, not per frame.
  double resident_mib_ = 0.0;
  std::optional<std::chrono::steady_clock::time_point> resident_read_at_;
  double resident_mib();
};

// The process's resident set size in MiB (/proc/self/statm); 0 where it cannot be read.
double read_resident_mib();

// Opens `file` for writing; throws pspslam::Error naming it when it cannot.
std::ofstream open_output(const std::filesystem::path& file);

}  // namespace pspslam
