#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pspslam/config/config.h"
#include "pspslam/io/input_frame.h"
#include "pspslam/session/occupancy_run.h"
#include "pspslam/system/system.h"
#include "system_options.h"

namespace pspslam::python {

namespace py = pybind11;

// One frame as Python sees it: the InputFrame the system reads, shared and never changed after it
// is made (its arrays are read-only views).
struct PyFrame {
  std::shared_ptr<const InputFrame> frame;
};

// What track() returns: the frame's report and its final dynamic mask (shared with the system,
// which replaces the mask of the next frame rather than writing into it).
struct PyResult {
  FrameReport report;
  Timestamp timestamp = 0.0;
  cv::Mat mask;  // CV_8UC1, non-zero = dynamic; all zero without dynamic detection
};

// pspslam.System: a System made as `pspslam run` makes it, fed numpy frames. One thread at a
// time may use it; the GIL is released while a frame is processed.
class PySystem {
 public:
  PySystem(SystemConfig config, std::string config_name, const RunSettings& settings,
           bool keypoints);
  ~PySystem();
  PySystem(const PySystem&) = delete;
  PySystem& operator=(const PySystem&) = delete;

  // A frame of this system's camera from numpy arrays, checked and copied (arrays.h).
  PyFrame make_frame(const py::handle& image, const py::handle& depth, const py::handle& right,
                     const py::handle& timestamp);
  void announce(const PyFrame& frame);
  PyResult track(const PyFrame& frame);
  void shutdown();

  py::array map_points();
  py::tuple keyframe_trajectory() const;
  // The final trajectory (System::refined_trajectory): it needs the back end finished, so this
  // shuts the system down first.
  py::tuple refined_trajectory();
  std::pair<size_t, size_t> save_map(const std::filesystem::path& file);
  // The occupancy map's 2D grid over this band (occupancy=True only; ValueError otherwise): the
  // live map while the System runs, the map rebuilt at the final poses once it has shut down.
  py::dict occupancy_grid(const GridOptions& band);

  const SystemConfig& config() const { return config_; }
  const SystemOptions& options() const { return options_; }
  std::string dynamic_mode() const { return to_string(options_.dynamic.mode); }
  // Every run setting the System got, as `pspslam run` reports them in stats.json "settings".
  const std::vector<std::pair<std::string, std::string>>& settings() const { return settings_; }

 private:
  // Holds the system for one call; a second thread gets RuntimeError instead of a race.
  std::unique_lock<std::mutex> claim(const char* what);
  void require_running(const char* what) const;
  void check_next(const PyFrame& frame) const;

  SystemConfig config_;
  std::string config_name_;
  SystemOptions options_;
  std::vector<std::pair<std::string, std::string>> settings_;
  std::unique_ptr<System> system_;
  std::unique_ptr<OccupancyRun> occupancy_;  // with occupancy=True, fed as `pspslam run` feeds it
  std::mutex busy_;
  bool shut_down_ = false;
  std::optional<Timestamp> last_timestamp_;  // of the last frame tracked or announced
  std::optional<Timestamp> last_tracked_;
  // Frames announced and not tracked yet, in order: track() must get them in that order.
  std::deque<std::shared_ptr<const InputFrame>> announced_;
  size_t next_index_ = 0;
};

}  // namespace pspslam::python
