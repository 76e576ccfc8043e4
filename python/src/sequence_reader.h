#pragma once

#include <pybind11/pybind11.h>

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>

#include "pspslam/io/sequence_setup.h"
#include "python_system.h"

namespace pspslam::python {

namespace py = pybind11;

// pspslam.read_sequence(folder): a TUM/Bonn, KITTI or EuRoC folder opened as `pspslam run`
// opens it (io/sequence_setup.h: its config, a KITTI calibration, an EuRoC rectification),
// iterated as frames decoded on demand.
class PySequence {
 public:
  PySequence(const std::filesystem::path& folder,
             const std::optional<std::filesystem::path>& config,
             const std::optional<std::string>& sensor, size_t max_frames);

  size_t size() const { return frames_; }
  // Frame i, decoded now (the GIL is released meanwhile); IndexError past the end.
  PyFrame frame(size_t i) const;
  // (timestamps N, poses Nx4x4 camera-to-world) of groundtruth.txt, or None.
  py::object ground_truth() const;

  const SequenceSetup& setup() const { return *setup_; }

 private:
  std::shared_ptr<const SequenceSetup> setup_;
  size_t frames_ = 0;
};

// Iterates a PySequence from its first frame.
struct PySequenceIterator {
  std::shared_ptr<const PySequence> sequence;
  size_t next = 0;
};

// Timestamps (N) and poses (Nx4x4) of a trajectory, as numpy arrays.
py::tuple trajectory_arrays(const Trajectory& trajectory);

}  // namespace pspslam::python
