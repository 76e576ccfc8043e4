#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <opencv2/core.hpp>
#include <string>

#include "pspslam/core/types.h"

namespace pspslam::python {

namespace py = pybind11;

// What an image argument of track() must be. Every check raises TypeError (not an array, wrong
// dtype) or ValueError (shape, channels, layout) naming `argument` and what was expected; nothing
// is ever converted into another layout behind the caller's back.
struct ImageSpec {
  const char* argument;
  bool colour_allowed = true;  // HxWx3 BGR
  bool gray_allowed = true;    // HxW
};

// A C-contiguous uint8 image (HxW gray or HxWx3 BGR) copied into a cv::Mat the system owns: the
// system keeps images of past frames, which must not change when the caller reuses its buffer.
cv::Mat copy_image(const py::handle& object, const ImageSpec& spec);

// A depth image: uint16 in the sensor's raw units (divided by `depth_factor`, as the sequence
// readers do) or float32 metres; 0 = no reading. HxW, C-contiguous. Returns CV_32FC1 metres
// that the system owns.
cv::Mat copy_depth(const py::handle& object, double depth_factor, int shift_x, int shift_y);

// A numpy view of `mat` without a copy: the array keeps the pixels alive (a capsule holds a
// reference to them) and is read-only, since the system may still read them.
py::array view_of(const cv::Mat& mat);

// 4x4 float64 camera-to-world matrix of `pose`.
py::array_t<double> pose_matrix(const Pose& pose);
// A 4x4 rigid transform (float64 array-like) as a Pose; `argument` names it in errors.
Pose pose_from_matrix(const py::handle& object, const std::string& argument);

// "HxWx3 uint8", the way messages describe an array.
std::string describe_array(const py::array& array);

}  // namespace pspslam::python
