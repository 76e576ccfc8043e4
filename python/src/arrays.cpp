#include "arrays.h"

#include <cstdint>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pspslam/io/image_files.h"

namespace pspslam::python {
namespace {

// The argument as an ndarray; anything else (a list, a PIL image) is a TypeError, not a copy.
py::array require_array(const py::handle& object, const std::string& argument,
                        const std::string& expected) {
  if (!py::isinstance<py::array>(object)) {
    throw py::type_error(argument + ": expected a numpy array (" + expected + "), got " +
                         std::string(py::str(py::type::of(object).attr("__name__"))));
  }
  return py::reinterpret_borrow<py::array>(object);
}

void require_c_contiguous(const py::array& array, const std::string& argument) {
  if ((array.flags() & py::array::c_style) == 0) {
    throw py::value_error(argument + ": expected a C-contiguous array, got " +
                          describe_array(array) +
                          " with other strides (a slice or transpose; numpy.ascontiguousarray "
                          "makes a contiguous copy)");
  }
}

// `array` is CV_TYPE pixels in its own memory: a cv::Mat header over them (no copy).
cv::Mat header_over(const py::array& array, int cv_type) {
  return cv::Mat(static_cast<int>(array.shape(0)), static_cast<int>(array.shape(1)), cv_type,
                 const_cast<void*>(array.data()));
}

int cv_depth_of(int mat_depth, py::dtype& dtype) {
  switch (mat_depth) {
    case CV_8U:
      dtype = py::dtype::of<std::uint8_t>();
      return 1;
    case CV_16U:
      dtype = py::dtype::of<std::uint16_t>();
      return 2;
    case CV_32F:
      dtype = py::dtype::of<float>();
      return 4;
    default:
      throw std::logic_error("view_of: unsupported cv::Mat depth " + std::to_string(mat_depth));
  }
}

}  // namespace

std::string describe_array(const py::array& array) {
  std::string shape = array.ndim() == 0 ? "a scalar" : "";
  for (py::ssize_t axis = 0; axis < array.ndim(); ++axis) {
    if (axis > 0) shape += 'x';
    shape += std::to_string(array.shape(axis));
  }
  return shape + " " + std::string(py::str(array.dtype()));
}

cv::Mat copy_image(const py::handle& object, const ImageSpec& spec) {
  const std::string argument = spec.argument;
  const std::string expected = spec.colour_allowed && spec.gray_allowed
                                   ? "uint8 HxWx3 BGR or uint8 HxW gray"
                               : spec.colour_allowed ? "uint8 HxWx3 BGR"
                                                     : "uint8 HxW gray";
  const py::array array = require_array(object, argument, expected);
  if (!py::array_t<std::uint8_t>::check_(array)) {
    throw py::type_error(argument + ": expected " + expected + ", got dtype " +
                         std::string(py::str(array.dtype())));
  }
  const bool gray = array.ndim() == 2;
  const bool colour = array.ndim() == 3 && array.shape(2) == 3;
  if (!((gray && spec.gray_allowed) || (colour && spec.colour_allowed))) {
    std::string got = describe_array(array);
    if (array.ndim() == 3 && array.shape(0) == 3 && array.shape(2) != 3)
      got += " (channels first?)";
    throw py::value_error(argument + ": expected " + expected + ", got " + got);
  }
  require_c_contiguous(array, argument);
  if (array.shape(0) == 0 || array.shape(1) == 0)
    throw py::value_error(argument + ": expected a non-empty image, got " + describe_array(array));
  return header_over(array, gray ? CV_8UC1 : CV_8UC3).clone();
}

cv::Mat copy_depth(const py::handle& object, double depth_factor, int shift_x, int shift_y) {
  const std::string expected = "HxW uint16 raw depth units or HxW float32 metres";
  const py::array array = require_array(object, "depth", expected);
  const bool raw = py::array_t<std::uint16_t>::check_(array);
  const bool metres = py::array_t<float>::check_(array);
  if (!raw && !metres) {
    throw py::type_error("depth: expected " + expected + ", got dtype " +
                         std::string(py::str(array.dtype())));
  }
  if (array.ndim() != 2)
    throw py::value_error("depth: expected " + expected + ", got " + describe_array(array));
  require_c_contiguous(array, "depth");
  if (metres) return header_over(array, CV_32FC1).clone();
  return depth_to_metres(header_over(array, CV_16UC1), depth_factor, shift_x, shift_y);
}

py::array view_of(const cv::Mat& mat) {
  py::dtype dtype;
  const int element = cv_depth_of(mat.depth(), dtype);
  std::vector<py::ssize_t> shape = {mat.rows, mat.cols};
  std::vector<py::ssize_t> strides = {static_cast<py::ssize_t>(mat.step[0]),
                                      static_cast<py::ssize_t>(mat.elemSize())};
  if (mat.channels() > 1) {
    shape.push_back(mat.channels());
    strides.push_back(element);
  }
  // The capsule owns a cv::Mat header sharing the pixels: they live as long as the array.
  auto* owner = new cv::Mat(mat);
  const py::capsule keep_alive(owner, [](void* held) { delete static_cast<cv::Mat*>(held); });
  py::array array(dtype, shape, strides, owner->data, keep_alive);
  array.attr("setflags")(py::arg("write") = false);
  return array;
}

py::array_t<double> pose_matrix(const Pose& pose) {
  py::array_t<double> matrix({4, 4});
  auto cells = matrix.mutable_unchecked<2>();
  const Eigen::Matrix4d& m = pose.matrix();
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) cells(row, col) = m(row, col);
  return matrix;
}

Pose pose_from_matrix(const py::handle& object, const std::string& argument) {
  const py::array array = require_array(object, argument, "4x4 float64");
  if (array.ndim() != 2 || array.shape(0) != 4 || array.shape(1) != 4)
    throw py::value_error(argument + ": expected a 4x4 matrix, got " + describe_array(array));
  const auto values = py::array_t<double, py::array::forcecast>::ensure(array);
  const auto cells = values.unchecked<2>();
  Pose pose = Pose::Identity();
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) pose.matrix()(row, col) = cells(row, col);
  return pose;
}

}  // namespace pspslam::python
