#include "python_system.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "arrays.h"
#include "pspslam/core/thread_priority.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/session/run_option_table.h"
#include "pspslam/system/frame_builder.h"
#include "sequence_reader.h"

namespace pspslam::python {
namespace {

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

Timestamp timestamp_value(const py::handle& timestamp) {
  if (timestamp.is_none() ||
      !(py::isinstance<py::float_>(timestamp) || py::isinstance<py::int_>(timestamp) ||
        py::hasattr(timestamp, "__float__")) ||
      py::isinstance<py::bool_>(timestamp)) {
    throw py::type_error("timestamp: expected seconds as a number, got " +
                         std::string(py::str(py::type::of(timestamp).attr("__name__"))));
  }
  const double seconds = timestamp.cast<double>();
  if (!std::isfinite(seconds))
    throw py::value_error("timestamp: expected a finite number of seconds, got " +
                          std::to_string(seconds));
  return seconds;
}

// The second image a sensor reads beside the colour one: present exactly when it needs it.
void require_presence(const py::handle& object, bool needed, const char* argument,
                      SensorType sensor) {
  if (needed && object.is_none())
    throw py::value_error(std::string(argument) + ": the " + to_string(sensor) +
                          " sensor needs one, got None");
  if (!needed && !object.is_none())
    throw py::value_error(std::string(argument) + ": the " + to_string(sensor) +
                          " sensor reads none, expected None");
}

// Frames come in time order: a time going back (or standing still) is refused.
void require_after(const std::optional<Timestamp>& previous, Timestamp timestamp) {
  if (previous && !(timestamp > *previous)) {
    throw py::value_error("timestamp: expected a time after the previous frame's " +
                          std::to_string(*previous) + ", got " + std::to_string(timestamp));
  }
}

void require_size(const cv::Mat& image, cv::Size expected, const std::string& argument,
                  const std::string& what) {
  if (image.size() != expected) {
    throw py::value_error(argument + ": expected " + what + " " +
                          size_text(expected.width, expected.height) + " (width x height), got " +
                          size_text(image.cols, image.rows));
  }
}

}  // namespace

PySystem::PySystem(SystemConfig config, std::string config_name, const RunSettings& settings,
                   bool keypoints)
    : config_(std::move(config)),
      config_name_(std::move(config_name)),
      options_(checked_system_options(settings)),
      settings_(effective_settings(settings, options_)) {
  // As `pspslam run`: the linear algebra calls are small, a BLAS's spinning workers are not.
  use_single_threaded_blas();
  apply_sensor_limits(config_.camera.type, options_);
  options_.record_keypoint_fates = keypoints;
  py::gil_scoped_release release;  // loading the model and the vocabulary takes a while
  system_ = std::make_unique<System>(config_, options_);
  if (settings.occupancy)
    occupancy_ =
        std::make_unique<OccupancyRun>(config_.camera.pinhole, occupancy_run_options(settings));
}

PySystem::~PySystem() = default;

std::unique_lock<std::mutex> PySystem::claim(const char* what) {
  std::unique_lock lock(busy_, std::try_to_lock);
  if (!lock.owns_lock()) {
    throw std::runtime_error(std::string(what) +
                             ": this System is busy in another thread (one thread at a time)");
  }
  return lock;
}

void PySystem::require_running(const char* what) const {
  if (shut_down_) throw py::value_error(std::string(what) + ": this System has been shut down");
}

PyFrame PySystem::make_frame(const py::handle& image, const py::handle& depth,
                             const py::handle& right, const py::handle& timestamp) {
  const SensorType sensor = config_.camera.type;
  auto frame = std::make_shared<InputFrame>();
  frame->timestamp = timestamp_value(timestamp);
  frame->depth_timestamp = frame->timestamp;
  const bool semantics = uses_semantics(options_.dynamic.mode);
  const cv::Mat pixels = copy_image(image, {"image", true, !semantics});
  const cv::Size camera(config_.camera.pinhole.width, config_.camera.pinhole.height);
  require_size(pixels, camera, "image", "the camera's size in " + config_name_ + ",");
  if (pixels.channels() == 3) {
    frame->bgr = pixels;
    cv::cvtColor(frame->bgr, frame->gray, cv::COLOR_BGR2GRAY);
  } else {
    frame->gray = pixels;
    cv::cvtColor(frame->gray, frame->bgr, cv::COLOR_GRAY2BGR);
  }
  require_presence(depth, sensor == SensorType::rgbd, "depth", sensor);
  require_presence(right, sensor == SensorType::stereo, "right", sensor);
  if (!depth.is_none()) {
    const CameraConfig& c = config_.camera;
    frame->depth = copy_depth(depth, c.depth_factor, c.depth_shift_x, c.depth_shift_y);
    require_size(frame->depth, camera, "depth", "the image's size");
  }
  if (!right.is_none()) {
    frame->right = copy_image(right, {"right", false, true});
    require_size(frame->right, camera, "right", "the image's size");
  }
  frame->index = next_index_++;
  return {std::move(frame)};
}

void PySystem::check_next(const PyFrame& frame) const {
  if (!announced_.empty() && announced_.front() != frame.frame) {
    throw py::value_error("frame: expected the frame announced first (timestamp " +
                          std::to_string(announced_.front()->timestamp) +
                          "): announced frames are tracked in the order announced");
  }
  const InputFrame& f = *frame.frame;
  const cv::Size camera(config_.camera.pinhole.width, config_.camera.pinhole.height);
  require_size(f.bgr, camera, "frame", "the camera's size in " + config_name_ + ",");
  if (announced_.empty()) require_after(last_timestamp_, f.timestamp);
}

void PySystem::announce(const PyFrame& frame) {
  auto lock = claim("announce");
  require_running("announce");
  require_after(last_timestamp_, frame.frame->timestamp);
  if (options_.dynamic.realtime) return;  // a real-time feed segments the newest frame only
  announced_.push_back(frame.frame);
  last_timestamp_ = frame.frame->timestamp;
  py::gil_scoped_release release;
  system_->announce(*frame.frame);
}

PyResult PySystem::track(const PyFrame& frame) {
  auto lock = claim("track");
  require_running("track");
  check_next(frame);
  if (!announced_.empty()) announced_.pop_front();
  last_timestamp_ =
      std::max(last_timestamp_.value_or(frame.frame->timestamp), frame.frame->timestamp);
  PyResult result;
  result.timestamp = frame.frame->timestamp;
  {
    py::gil_scoped_release release;
    result.report = system_->process(*frame.frame);
    result.mask = system_->last_dynamic_mask();
    if (occupancy_ && result.report.tracking.keyframe_inserted)
      occupancy_->add_keyframe(system_->map().keyframe(system_->map().max_keyframe_id()),
                               frame.frame->depth, result.mask);
  }
  if (result.mask.empty()) result.mask = cv::Mat::zeros(frame.frame->bgr.size(), CV_8UC1);
  return result;
}

void PySystem::shutdown() {
  auto lock = claim("shutdown");
  if (shut_down_) return;
  shut_down_ = true;
  py::gil_scoped_release release;
  system_->shutdown();
  // As `pspslam run` ends: every keyframe enters the map, rebuilt at its final pose. Its exports
  // are the CLI's, so what finish() reports is not wanted here.
  std::ostringstream unused;
  if (occupancy_) occupancy_->finish(system_->keyframe_trajectory(), unused);
}

py::dict PySystem::occupancy_grid(const GridOptions& band) {
  auto lock = claim("occupancy_grid");
  if (!occupancy_)
    throw py::value_error(
        "occupancy_grid: this System builds no occupancy map (make it with occupancy=True)");
  OccupancyGrid grid;
  {
    py::gil_scoped_release release;
    grid = occupancy_->grid(band);
  }
  // Row 0 holds the cells nearest the origin (lowest y), as a ROS OccupancyGrid message.
  py::array_t<std::int8_t> cells(
      {static_cast<py::ssize_t>(grid.height), static_cast<py::ssize_t>(grid.width)});
  std::copy(grid.cells.begin(), grid.cells.end(), cells.mutable_data());
  py::array_t<double> pose({py::ssize_t{4}, py::ssize_t{4}});
  auto entries = pose.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) entries(r, c) = grid.T_world_grid.matrix()(r, c);
  py::dict result;
  result["grid"] = cells;
  result["resolution"] = grid.resolution;
  result["origin"] = py::make_tuple(grid.origin.x(), grid.origin.y());
  result["T_world_grid"] = pose;
  result["floor_height"] = grid.floor.height;
  return result;
}

py::array PySystem::map_points() {
  auto lock = claim("map_points");
  std::vector<Eigen::Vector3d> positions;
  {
    py::gil_scoped_release release;
    for (const std::shared_ptr<MapPoint>& point : system_->map().map_points())
      if (!point->is_bad()) positions.push_back(point->position());
  }
  py::array_t<double> array({static_cast<py::ssize_t>(positions.size()), py::ssize_t{3}});
  auto cells = array.mutable_unchecked<2>();
  for (size_t i = 0; i < positions.size(); ++i)
    for (int axis = 0; axis < 3; ++axis)
      cells(static_cast<py::ssize_t>(i), axis) = positions[i][axis];
  return array;
}

py::tuple PySystem::keyframe_trajectory() const {
  return trajectory_arrays(system_->keyframe_trajectory());
}

py::tuple PySystem::refined_trajectory() {
  shutdown();
  auto lock = claim("refined_poses");
  return trajectory_arrays(system_->refined_trajectory());
}

std::pair<size_t, size_t> PySystem::save_map(const std::filesystem::path& file) {
  shutdown();
  auto lock = claim("save_map");
  py::gil_scoped_release release;
  return system_->save_map(file);
}

}  // namespace pspslam::python
