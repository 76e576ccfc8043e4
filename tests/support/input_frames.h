#pragma once

#include <opencv2/core.hpp>

#include "pspslam/core/types.h"
#include "pspslam/io/input_frame.h"

namespace pspslam {

// An RGB-D frame from a grey image and a depth image in metres (no colour), as the synthetic
// tests feed System::process.
inline InputFrame grey_depth_frame(Timestamp timestamp, const cv::Mat& gray,
                                   const cv::Mat& depth_metres) {
  InputFrame frame;
  frame.timestamp = timestamp;
  frame.gray = gray;
  frame.depth = depth_metres;
  return frame;
}

}  // namespace pspslam
