#pragma once

#include <memory>
#include <string>

#include "pspslam/io/frame_source.h"

namespace pspslam {

// A video file or a camera index read through cv::VideoCapture, as a monocular FrameSource
// (`pspslam run --video FILE|INDEX`). A frame's timestamp is the time the container gives it
// (CAP_PROP_POS_MSEC); where it gives none, or time stands still or runs back, the frame index
// over the frame rate (CAP_PROP_FPS, else `fallback_fps`, the config's). `spec` that is all
// digits is a camera index. Throws pspslam::Error when it cannot be opened.
std::unique_ptr<FrameSource> open_video(const std::string& spec, double fallback_fps);

}  // namespace pspslam
