#pragma once

#include <chrono>
#include <cstddef>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "pspslam/core/types.h"

namespace pspslam {

// The images of one moment as the sensor delivered them, whatever the sensor: colour with depth
// (RGB-D), colour with the rectified right image (stereo) or colour alone (monocular).
struct InputFrame {
  size_t index = 0;           // position in the sequence (0 .. size()-1)
  Timestamp timestamp = 0.0;  // colour timestamp
  Timestamp depth_timestamp = 0.0;
  cv::Mat bgr;    // CV_8UC3
  cv::Mat gray;   // CV_8UC1 (empty unless SequenceOptions::load_gray)
  cv::Mat depth;  // CV_32FC1 metres, 0 = no reading (empty for a stereo pair)
  cv::Mat right;  // stereo only: the rectified right image, CV_8UC1 (empty for RGB-D)
  // The colour image's file relative to its sequence ("rgb/1.5.png"); per-frame pictures are
  // named after it (per_frame_png_name). A live camera frame is named as `pspslam record` would
  // store it.
  std::string name;
  // When the frame reached the run from the camera's point of view: a paced sequence's due time
  // (`--realtime`), a live camera's pairing time on the driver thread. Empty for an unpaced
  // sequence, where a frame has no arrival to measure from. The run measures the time from here
  // to the frame's pose (stats.json `latency`).
  std::optional<std::chrono::steady_clock::time_point> arrival;
};

}  // namespace pspslam
