#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pspslam/core/types.h"
#include "pspslam/people/people_tracker.h"
#include "pspslam/session/keypoint_overlay.h"
#include "pspslam/session/run_observer.h"
#include "pspslam/viewer/web_server.h"

namespace pspslam {

// A tracked person as the page shows her: in the 3D view at her world position, on the frame at
// the pixel her centre projects to (none: no pose or intrinsics, or behind the camera).
struct ShownPerson {
  TrackedPerson person;
  std::optional<Eigen::Vector2d> pixel;
};

class OccupancyRun;
struct OccupancyGrid;

// The grid layer of the page: the grid's cells as an RGBA picture (top row: the grid's highest
// row, as an image is shown; unknown clear, free pale, occupied dark red) and its placement and
// counts as JSON (width, height, resolution, origin, T_world_grid row-major, cells).
cv::Mat grid_picture(const OccupancyGrid& grid);
nlohmann::json grid_json(const OccupancyGrid& grid, std::uint64_t version);

// One element of the frame JSON's "people" array: id, p (world position), v (velocity),
// extent (metres), seen (observed in this frame, not only predicted), pixel ([u, v] or null).
nlohmann::json person_json(const ShownPerson& shown);

struct LiveViewerOptions {
  std::string endpoint = "127.0.0.1:8080";  // --viewer [HOST:]PORT
  std::filesystem::path web_root;           // the page's folder (core/shared_paths.h data_dir)
  // Frame snapshots at most this often, the map's at most every map_interval: what the run
  // loop pays for the viewer is bounded by these, not by how often a browser asks.
  std::chrono::milliseconds interval{250};
  std::chrono::milliseconds map_interval{1000};
  // The occupancy grid (--occupancy) is rebuilt from the OctoMap at most this often, on the
  // viewer's thread: a grid costs a pass over the map, the frames need none of it.
  std::chrono::milliseconds grid_interval{3000};
  int image_width = 480;  // frames are sent JPEG at this width (never enlarged)
  bool start_paused = false;
  // A real-time feed keeps coming whatever the viewer does: pause is refused (the frames would
  // be dropped by the source, not held), and the keypoints the semantic mask removed are not
  // shown (finding them costs a second ORB extraction on the tracking thread; the label overlay
  // shows the mask instead).
  bool realtime = false;
  std::filesystem::path ground_truth;  // TUM file aligned onto the estimate; empty: none
  OverlayClasses classes;              // the segmentation's classes, for the label colours
  std::string title;                   // the sequence or camera, shown on the page
  bool occupancy = false;              // --occupancy: the page offers the grid layer
};

// `pspslam run --viewer`: serves the live page (web/live.html) and what it shows, a snapshot of
// the current frame (JPEG + label / grown-region overlays as PNG + keypoints as JSON) and of the
// map, pushed to the page by Server-Sent Events. The run loop only copies what a snapshot needs
// (image headers, keypoint records, map point positions) when one is due; resizing, encoding and
// JSON happen on the viewer's own encoder thread, newest snapshot wins (one pending at most, so
// a slow encoder or browser drops snapshots, never frames). Pause / resume / step hold the run
// loop between frames (deterministic runs only).
class LiveViewer final : public RunObserver {
 public:
  // Starts the server (prints nothing; url() says where) and the encoder thread. Throws
  // pspslam::Error when the page is missing or the address cannot be bound.
  explicit LiveViewer(LiveViewerOptions options);
  ~LiveViewer() override;
  LiveViewer(const LiveViewer&) = delete;
  LiveViewer& operator=(const LiveViewer&) = delete;

  const std::string& url() const { return url_; }

  Detail wants_detail() override;
  void frame_done(const FrameView& view) override;
  void run_ended() override;

  // The controls of the page (also reachable as POST /api/pause, /api/resume, /api/step).
  // False when refused (--realtime, or the run is over).
  bool pause();
  bool resume();
  bool step();

 private:
  struct FrameSnapshot;
  struct MapSnapshot;
  using Clock = std::chrono::steady_clock;

  static std::unique_ptr<FrameSnapshot> snapshot_frame(const FrameView& view, bool detail,
                                                       Clock::time_point now);
  static std::unique_ptr<MapSnapshot> snapshot_map(const FrameView& view);
  // Holds the run loop after frame `frame_index` until resume, step, closing or an interrupt.
  void hold(std::unique_lock<std::mutex>& lock, size_t frame_index);
  void encode_loop();
  void publish_frame(const FrameSnapshot& snapshot);
  void update_fps(const FrameSnapshot& snapshot);
  // The frame's JSON for the page; `labels` and `regions`: their pictures were encoded.
  std::string frame_json(const FrameSnapshot& snapshot, bool labels, bool regions) const;
  void publish_map(const MapSnapshot& snapshot);
  void publish_grid(const OccupancyRun& occupancy);
  std::string state_json() const;  // under mutex_
  std::string event_json() const;  // under mutex_: state + the newest frame's JSON
  std::optional<std::string> next_event(std::uint64_t& last);
  HttpReply control(bool (LiveViewer::*action)());

  LiveViewerOptions options_;
  Trajectory ground_truth_;
  WebServer server_;
  std::string url_;

  mutable std::mutex mutex_;
  std::condition_variable work_;     // the encoder: a snapshot is pending, or closing
  std::condition_variable changed_;  // event streams and the paused run loop
  std::unique_ptr<FrameSnapshot> pending_frame_;
  std::unique_ptr<MapSnapshot> pending_map_;
  // The occupancy map to make a grid of (pending), and whether the encoder is reading it:
  // run_ended() waits for that read, as the map goes when the run loop returns.
  const OccupancyRun* pending_grid_ = nullptr;
  const OccupancyRun* last_occupancy_ = nullptr;  // the run's map, for the grid at its end
  bool grid_busy_ = false;
  Clock::time_point last_grid_{};
  bool closing_ = false;
  // Control state.
  bool paused_ = false;
  int steps_ = 0;          // frames the paused loop may still process
  bool waiting_ = false;   // the run loop is held now
  bool ended_ = false;     // the frame loop is over
  bool detail_ = false;    // the frame being processed records its keypoint fates
  size_t held_frame_ = 0;  // index of the frame the loop is held after
  Clock::time_point last_frame_snapshot_{};
  Clock::time_point last_map_snapshot_{};
  std::uint64_t last_map_keyframes_ = 0;
  size_t last_map_merges_ = 0;
  // Published (read by the server threads; replaced, never modified, so a reply shares them).
  std::uint64_t event_ = 0;  // any change: frame, map or state
  std::uint64_t frame_version_ = 0;
  std::uint64_t map_version_ = 0;
  std::shared_ptr<const std::string> frame_json_, jpeg_, labels_png_, regions_png_, map_json_;
  std::shared_ptr<const std::string> grid_json_, grid_png_;
  std::uint64_t grid_version_ = 0;
  // fps over the snapshots: frames processed between two of them over the time between.
  std::optional<std::pair<size_t, Clock::time_point>> fps_reference_;
  double fps_ = 0.0;

  std::thread encoder_;  // last: started once everything above exists
};

}  // namespace pspslam
