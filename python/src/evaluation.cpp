#include "evaluation.h"

#include <pybind11/numpy.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>

#include "arrays.h"
#include "pspslam/eval/ate.h"
#include "pspslam/eval/rpe.h"
#include "pspslam/io/trajectory_io.h"
#include "sequence_reader.h"

namespace pspslam::python {
namespace {

constexpr const char* kExpectedTrajectory =
    "(timestamps N, poses Nx4x4) or an Nx8 array of TUM rows t tx ty tz qx qy qz qw";

Trajectory from_tum_rows(const py::array& array, const std::string& argument) {
  if (array.ndim() != 2 || array.shape(1) != 8)
    throw py::value_error(argument + ": expected " + kExpectedTrajectory + ", got " +
                          describe_array(array));
  const auto values = py::array_t<double, py::array::forcecast>::ensure(array);
  const auto rows = values.unchecked<2>();
  Trajectory trajectory(static_cast<size_t>(rows.shape(0)));
  for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
    const Eigen::Quaterniond q(rows(i, 7), rows(i, 4), rows(i, 5), rows(i, 6));
    if (!(std::abs(q.norm() - 1.0) <= kQuaternionNormTolerance))
      throw py::value_error(argument + ": row " + std::to_string(i) + " has a quaternion of norm " +
                            std::to_string(q.norm()) + ", expected a unit quaternion");
    StampedPose& pose = trajectory[static_cast<size_t>(i)];
    pose.timestamp = rows(i, 0);
    pose.T_world_camera.linear() = q.normalized().toRotationMatrix();
    pose.T_world_camera.translation() = Eigen::Vector3d(rows(i, 1), rows(i, 2), rows(i, 3));
  }
  return trajectory;
}

Trajectory from_timestamps_and_poses(const py::tuple& pair, const std::string& argument) {
  const auto timestamps = py::array_t<double, py::array::forcecast>::ensure(pair[0]);
  const auto poses = py::array_t<double, py::array::forcecast>::ensure(pair[1]);
  if (!timestamps || !poses || timestamps.ndim() != 1 || poses.ndim() != 3 ||
      poses.shape(0) != timestamps.shape(0) || poses.shape(1) != 4 || poses.shape(2) != 4)
    throw py::value_error(argument + ": expected " + kExpectedTrajectory);
  const auto times = timestamps.unchecked<1>();
  const auto cells = poses.unchecked<3>();
  Trajectory trajectory(static_cast<size_t>(times.shape(0)));
  for (py::ssize_t i = 0; i < times.shape(0); ++i) {
    StampedPose& pose = trajectory[static_cast<size_t>(i)];
    pose.timestamp = times(i);
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 4; ++col) pose.T_world_camera.matrix()(row, col) = cells(i, row, col);
  }
  return trajectory;
}

py::dict stats_dict(const ErrorStats& stats) {
  py::dict d;
  d["count"] = stats.count;
  d["rmse"] = stats.rmse;
  d["mean"] = stats.mean;
  d["median"] = stats.median;
  d["std"] = stats.std;
  d["min"] = stats.min;
  d["max"] = stats.max;
  return d;
}

py::array_t<double> matrix_array(const Eigen::Matrix3d& matrix) {
  py::array_t<double> array({3, 3});
  auto cells = array.mutable_unchecked<2>();
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) cells(row, col) = matrix(row, col);
  return array;
}

py::array_t<double> vector_array(const Eigen::Vector3d& vector) {
  py::array_t<double> array(3);
  auto cells = array.mutable_unchecked<1>();
  for (int i = 0; i < 3; ++i) cells(i) = vector[i];
  return array;
}

py::dict ate(const py::handle& ground_truth, const py::handle& estimate, double max_difference,
             double offset, bool sim3) {
  const Trajectory gt = trajectory_from(ground_truth, "ground_truth");
  const Trajectory est = trajectory_from(estimate, "estimate");
  AteResult result;
  {
    py::gil_scoped_release release;
    result =
        compute_ate(gt, est, {.max_difference = max_difference, .offset = offset, .sim3 = sim3});
  }
  py::dict d = stats_dict(result.error);
  d["rotation"] = matrix_array(result.alignment.rotation);
  d["translation"] = vector_array(result.alignment.translation);
  d["scale"] = result.alignment.scale;
  return d;
}

py::dict rpe(const py::handle& ground_truth, const py::handle& estimate, double delta,
             const std::string& unit, double offset) {
  if (unit != "s" && unit != "f")
    throw py::value_error("unit: expected 's' (seconds) or 'f' (frames), got '" + unit + "'");
  const Trajectory gt = trajectory_from(ground_truth, "ground_truth");
  const Trajectory est = trajectory_from(estimate, "estimate");
  const RpeOptions options{.delta = delta,
                           .unit = unit == "s" ? RpeDeltaUnit::seconds : RpeDeltaUnit::frames,
                           .offset = offset};
  RpeResult result;
  {
    py::gil_scoped_release release;
    result = compute_rpe(gt, est, options);
  }
  py::dict d;
  d["translation"] = stats_dict(result.translation);
  d["rotation"] = stats_dict(result.rotation);
  d["translation_per_second"] = stats_dict(result.translation_per_second);
  d["rotation_per_second"] = stats_dict(result.rotation_per_second);
  d["body_frame_rotation_deg"] = result.body_frame_rotation_deg;
  return d;
}

}  // namespace

Trajectory trajectory_from(const py::handle& object, const std::string& argument) {
  if (py::isinstance<py::tuple>(object) && py::len(object) == 2)
    return from_timestamps_and_poses(py::reinterpret_borrow<py::tuple>(object), argument);
  if (py::isinstance<py::array>(object))
    return from_tum_rows(py::reinterpret_borrow<py::array>(object), argument);
  throw py::type_error(argument + ": expected " + kExpectedTrajectory + ", got " +
                       std::string(py::str(py::type::of(object).attr("__name__"))));
}

void register_evaluation(py::module_& m) {
  m.def("ate", &ate, py::arg("ground_truth"), py::arg("estimate"), py::kw_only(),
        py::arg("max_difference") = kDefaultMaxTimeDifference, py::arg("offset") = 0.0,
        py::arg("sim3") = false,
        "Absolute trajectory error, the computation of `pspslam eval` (TUM evaluate_ate.py): "
        "dict of count, rmse, mean, median, std, min, max (metres) and the alignment of the "
        "estimate onto the ground truth: x' = scale * rotation @ x + translation.");
  m.def("rpe", &rpe, py::arg("ground_truth"), py::arg("estimate"), py::kw_only(),
        py::arg("delta") = 1.0, py::arg("unit") = "s", py::arg("offset") = 0.0,
        "Relative pose error, the computation of `pspslam eval` (TUM evaluate_rpe.py "
        "--fixed_delta): dicts of translation (m) and rotation (degrees) statistics.");
  m.def(
      "write_trajectory",
      [](const std::filesystem::path& file, const py::handle& trajectory) {
        write_tum_trajectory(file, trajectory_from(trajectory, "trajectory"));
      },
      py::arg("path"), py::arg("trajectory"),
      "Writes a TUM trajectory file exactly as `pspslam run` writes trajectory.txt.");
  m.def(
      "read_trajectory",
      [](const std::filesystem::path& file) {
        return trajectory_arrays(read_tum_trajectory(file));
      },
      py::arg("path"), "Reads a TUM trajectory file: (timestamps N, poses Nx4x4).");
}

}  // namespace pspslam::python
