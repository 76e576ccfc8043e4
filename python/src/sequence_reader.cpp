#include "sequence_reader.h"

#include <iostream>
#include <utility>

#include "pspslam/config/config.h"

namespace pspslam::python {

PySequence::PySequence(const std::filesystem::path& folder,
                       const std::optional<std::filesystem::path>& config,
                       const std::optional<std::string>& sensor, size_t max_frames) {
  std::optional<SensorType> sensor_type;
  if (sensor) sensor_type = parse_sensor_type(*sensor, "sensor");
  setup_ = std::make_shared<const SequenceSetup>(
      open_sequence_with_config(folder, config, &std::cerr, sensor_type));
  frames_ = setup_->sequence->size();
  if (max_frames > 0 && max_frames < frames_) frames_ = max_frames;
}

PyFrame PySequence::frame(size_t i) const {
  if (i >= frames_)
    throw py::index_error("frame " + std::to_string(i) + " of a sequence of " +
                          std::to_string(frames_));
  py::gil_scoped_release release;
  return {std::make_shared<const InputFrame>(setup_->sequence->load(i))};
}

py::object PySequence::ground_truth() const {
  const std::optional<Trajectory>& ground_truth = setup_->sequence->ground_truth();
  if (!ground_truth) return py::none();
  return trajectory_arrays(*ground_truth);
}

py::tuple trajectory_arrays(const Trajectory& trajectory) {
  const auto count = static_cast<py::ssize_t>(trajectory.size());
  py::array_t<double> timestamps(count);
  py::array_t<double> poses({count, py::ssize_t{4}, py::ssize_t{4}});
  auto times = timestamps.mutable_unchecked<1>();
  auto cells = poses.mutable_unchecked<3>();
  for (py::ssize_t i = 0; i < count; ++i) {
    const StampedPose& pose = trajectory[static_cast<size_t>(i)];
    times(i) = pose.timestamp;
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 4; ++col) cells(i, row, col) = pose.T_world_camera(row, col);
  }
  return py::make_tuple(timestamps, poses);
}

}  // namespace pspslam::python
