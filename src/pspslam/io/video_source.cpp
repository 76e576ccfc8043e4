#include "pspslam/io/video_source.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

bool is_camera_index(const std::string& spec) {
  return !spec.empty() && spec.size() <= 3 &&
         std::all_of(spec.begin(), spec.end(), [](char c) { return c >= '0' && c <= '9'; });
}

class VideoSource final : public FrameSource {
 public:
  VideoSource(const std::string& spec, double fallback_fps) : spec_(spec) {
    const bool camera = is_camera_index(spec);
    if (camera) {
      capture_.open(std::stoi(spec));
    } else {
      if (!std::filesystem::is_regular_file(spec))
        throw Error("--video " + spec + ": file not found");
      capture_.open(spec);
    }
    if (!capture_.isOpened()) {
      throw Error("--video " + spec + ": cannot open " +
                  (camera ? "camera " + spec : "the file (no decoder for its format?)"));
    }
    camera_ = camera;
    const double fps = capture_.get(cv::CAP_PROP_FPS);
    fps_ = fps > 0.0 && std::isfinite(fps) ? fps : fallback_fps;
    const double frames = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    if (!camera && frames > 0.0 && std::isfinite(frames))
      frame_count_ = static_cast<size_t>(frames);
  }

  std::optional<InputFrame> next() override {
    cv::Mat image;
    if (!capture_.read(image) || image.empty()) return std::nullopt;
    InputFrame frame;
    frame.index = delivered_++;
    if (image.channels() == 1) {
      cv::cvtColor(image, frame.bgr, cv::COLOR_GRAY2BGR);
    } else {
      frame.bgr = image;
    }
    cv::cvtColor(frame.bgr, frame.gray, cv::COLOR_BGR2GRAY);
    // The container's time of the frame; index / fps where it has none or it does not advance.
    // Once it fails, every later frame is timed by its index (continuing from the last time), so
    // the times stay on one clock.
    const double msec = capture_.get(cv::CAP_PROP_POS_MSEC);
    const double container = msec / 1000.0;
    if (!index_timing_ && std::isfinite(msec) && msec >= 0.0 &&
        (frame.index == 0 || container > last_time_)) {
      frame.timestamp = container;
    } else {
      if (!index_timing_) {
        index_timing_ = true;
        const double index_time = static_cast<double>(frame.index) / fps_;
        index_offset_ = frame.index == 0 ? 0.0 : last_time_ + 1.0 / fps_ - index_time;
      }
      frame.timestamp = index_offset_ + static_cast<double>(frame.index) / fps_;
    }
    last_time_ = frame.timestamp;
    frame.depth_timestamp = frame.timestamp;
    frame.name = "frame_" + std::to_string(frame.index) + ".png";
    if (camera_) frame.arrival = std::chrono::steady_clock::now();
    return frame;
  }

  std::optional<size_t> frame_count() const override { return frame_count_; }
  std::string name() const override { return spec_; }

  std::string describe() const override {
    std::ostringstream out;
    out << "video:        " << spec_ << " (" << (camera_ ? "camera" : "file");
    if (frame_count_) out << ", " << *frame_count_ << " frames";
    out << ", " << fps_ << " fps; times from the container, else frame index / fps)\n";
    return out.str();
  }

  const std::optional<Trajectory>& ground_truth() const override { return no_ground_truth_; }
  FrameSourceStats stats() const override { return {}; }
  bool live() const override { return camera_; }

 private:
  std::string spec_;
  cv::VideoCapture capture_;
  bool camera_ = false;
  double fps_ = 30.0;
  std::optional<size_t> frame_count_;
  size_t delivered_ = 0;
  double last_time_ = -1.0;
  bool index_timing_ = false;
  double index_offset_ = 0.0;
  std::optional<Trajectory> no_ground_truth_;
};

}  // namespace

std::unique_ptr<FrameSource> open_video(const std::string& spec, double fallback_fps) {
  return std::make_unique<VideoSource>(spec, fallback_fps);
}

}  // namespace pspslam
