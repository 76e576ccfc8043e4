// The Kinect v1 through libfreenect (Debian libfreenect-dev). Also runs under libfreenect's
// replay library fakenect (LD_LIBRARY_PATH=/usr/lib/<arch>/fakenect FAKENECT_PATH=DUMP), which
// is how the tests drive it without a device; so only functions fakenect also provides are used.
#include <libfreenect.h>
#include <sys/time.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <thread>

#include <opencv2/imgproc.hpp>

#include "pspslam/capture/camera_spec.h"
#include "pspslam/capture/device_clock.h"
#include "pspslam/capture/kinect_depth.h"
#include "pspslam/core/error.h"
#include "pspslam/core/interrupt.h"
#include "pspslam/core/latest_queue.h"

namespace pspslam {
namespace {

// A colour/depth pair as the driver thread hands it over: copies of the driver's buffers,
// converted by the consumer, so the callbacks stay short and dropped frames cost nothing more.
struct RawFrame {
  size_t index = 0;
  Timestamp colour_time = 0.0;
  Timestamp depth_time = 0.0;
  cv::Mat rgb;    // CV_8UC3, RGB order as the device sends it
  cv::Mat depth;  // CV_16UC1: millimetres (registered mode) or raw 11-bit disparity
  std::chrono::steady_clock::time_point arrival;  // when the pair was complete
};

struct ContextDeleter {
  void operator()(freenect_context* context) const { freenect_shutdown(context); }
};
struct DeviceDeleter {
  void operator()(freenect_device* device) const { freenect_close_device(device); }
};

double wall_clock_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::optional<freenect_frame_mode> find_depth_mode(freenect_depth_format format) {
  const int count = freenect_get_depth_mode_count();
  for (int i = 0; i < count; ++i) {
    const freenect_frame_mode mode = freenect_get_depth_mode(i);
    if (mode.is_valid && mode.resolution == FREENECT_RESOLUTION_MEDIUM &&
        mode.depth_format == format)
      return mode;
  }
  return std::nullopt;
}

class FreenectSource final : public FrameSource {
 public:
  FreenectSource(const CameraSpec& spec, const CameraOptions& options)
      : spec_(spec), options_(options), queue_(options.queue_capacity) {
    // fakenect ends the process when its dump is missing; say so as a user error instead.
    if (const char* dump = std::getenv("FAKENECT_PATH")) {
      const std::filesystem::path index = std::filesystem::path(dump) / "INDEX.txt";
      if (!std::filesystem::exists(index)) {
        throw Error("--camera " + spec.text() + ": FAKENECT_PATH is set but " + index.string() +
                    " does not exist (no fakenect dump to replay)");
      }
    }
    freenect_context* context = nullptr;
    if (freenect_init(&context, nullptr) < 0 || context == nullptr) {
      throw Error("--camera " + spec.text() + ": libfreenect cannot initialise libusb");
    }
    context_.reset(context);
    freenect_set_log_level(context, FREENECT_LOG_FATAL);
    freenect_select_subdevices(context, FREENECT_DEVICE_CAMERA);
    const int devices = freenect_num_devices(context);
    freenect_device* device = nullptr;
    if (devices <= spec.index || freenect_open_device(context, &device, spec.index) < 0 ||
        device == nullptr) {
      throw Error(explain_camera_failure(spec.index, std::max(devices, 0), find_kinect_cameras()));
    }
    device_.reset(device);
    freenect_set_user(device, this);

    const freenect_frame_mode video =
        freenect_find_video_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_VIDEO_RGB);
    // The registered (colour-aligned, millimetre) depth mode when the driver offers it;
    // fakenect offers only raw 11-bit disparity.
    std::optional<freenect_frame_mode> depth = find_depth_mode(FREENECT_DEPTH_REGISTERED);
    registered_ = depth.has_value();
    if (!depth) depth = find_depth_mode(FREENECT_DEPTH_11BIT);
    if (!video.is_valid || !depth || freenect_set_video_mode(device, video) < 0 ||
        freenect_set_depth_mode(device, *depth) < 0) {
      throw Error("--camera " + spec.text() +
                  ": the device offers no 640x480 RGB video and depth mode");
    }
    width_ = video.width;
    height_ = video.height;
    freenect_set_video_callback(device, &FreenectSource::on_video);
    freenect_set_depth_callback(device, &FreenectSource::on_depth);
    if (freenect_start_video(device) < 0 || freenect_start_depth(device) < 0) {
      throw Error("--camera " + spec.text() + ": cannot start the colour and depth streams");
    }
    driver_ = std::jthread([this](std::stop_token stop) { drive(stop); });
  }

  ~FreenectSource() override {
    driver_.request_stop();
    if (driver_.joinable()) driver_.join();
    if (device_) {
      freenect_stop_depth(device_.get());
      freenect_stop_video(device_.get());
    }
  }

  std::optional<InputFrame> next() override {
    const double limit =
        delivered_ == 0 ? options_.first_frame_timeout_s : options_.silence_timeout_s;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit);
    // Short waits, so Ctrl-C (which only raises a flag) ends a run waiting for a camera.
    while (!interrupted()) {
      if (std::optional<RawFrame> raw = queue_.pop(std::chrono::milliseconds(100)))
        return convert(std::move(*raw));
      if (queue_.closed()) {
        end_reason_ = queue_.close_reason();
        return std::nullopt;
      }
      if (std::chrono::steady_clock::now() > deadline) {
        char reason[160];
        std::snprintf(reason, sizeof(reason),
                      "camera %s stopped: no frame for %.1f s (unplugged or hung)",
                      spec_.text().c_str(), limit);
        end_reason_ = reason;
        queue_.close(end_reason_);
        return std::nullopt;
      }
    }
    return std::nullopt;
  }

  std::string name() const override { return spec_.text(); }

  std::string describe() const override {
    return "camera:       " + spec_.text() + " (Kinect v1 through libfreenect, " +
           std::to_string(width_) + "x" + std::to_string(height_) + ", depth " +
           (registered_ ? "registered to colour by the driver, mm"
                        : "raw 11-bit disparity converted with the Kinect fit, not registered") +
           ")\n";
  }

  const std::optional<Trajectory>& ground_truth() const override { return no_ground_truth_; }

  FrameSourceStats stats() const override {
    return {.dropped = queue_.dropped(),
            .disconnected = !end_reason_.empty(),
            .end_reason = end_reason_};
  }

  bool live() const override { return true; }

 private:
  static FreenectSource& of(freenect_device* device) {
    return *static_cast<FreenectSource*>(freenect_get_user(device));
  }
  static void on_video(freenect_device* device, void* data, uint32_t ticks) {
    FreenectSource& self = of(device);
    self.pending_rgb_ = cv::Mat(self.height_, self.width_, CV_8UC3, data).clone();
    self.pending_colour_time_ = self.clock_time(ticks);
    self.pair_if_complete();
  }
  static void on_depth(freenect_device* device, void* data, uint32_t ticks) {
    FreenectSource& self = of(device);
    self.pending_depth_ = cv::Mat(self.height_, self.width_, CV_16UC1, data).clone();
    self.pending_depth_time_ = self.clock_time(ticks);
    self.pair_if_complete();
  }

  // Driver thread only.
  Timestamp clock_time(uint32_t ticks) {
    if (!clock_) clock_.emplace(wall_clock_now());
    return clock_->seconds(ticks);
  }

  // Driver thread only: colour and depth arrive separately; whichever completes a pair sends it.
  void pair_if_complete() {
    if (pending_rgb_.empty() || pending_depth_.empty()) return;
    queue_.push({captured_++, pending_colour_time_, pending_depth_time_, std::move(pending_rgb_),
                 std::move(pending_depth_), std::chrono::steady_clock::now()});
    pending_rgb_ = cv::Mat();
    pending_depth_ = cv::Mat();
  }

  void drive(std::stop_token stop) {
    while (!stop.stop_requested()) {
      timeval timeout{0, 100000};
      const int status = freenect_process_events_timeout(context_.get(), &timeout);
      if (status < 0) {
        queue_.close("camera " + spec_.text() + " stopped: libfreenect's event loop failed (code " +
                     std::to_string(status) +
                     "): the Kinect was unplugged, or a fakenect replay reached the end of its "
                     "INDEX.txt");
        return;
      }
    }
  }

  InputFrame convert(RawFrame raw) {
    InputFrame frame;
    frame.index = raw.index;
    frame.timestamp = raw.colour_time;
    frame.depth_timestamp = raw.depth_time;
    frame.arrival = raw.arrival;
    cv::cvtColor(raw.rgb, frame.bgr, cv::COLOR_RGB2BGR);
    cv::cvtColor(frame.bgr, frame.gray, cv::COLOR_BGR2GRAY);
    if (registered_) {
      raw.depth.convertTo(frame.depth, CV_32F, 1.0 / 1000.0);
    } else {
      frame.depth = raw_depth_.convert(raw.depth);
    }
    char name[48];
    std::snprintf(name, sizeof(name), "rgb/%.6f.png", frame.timestamp);
    frame.name = name;
    ++delivered_;
    return frame;
  }

  CameraSpec spec_;
  CameraOptions options_;
  LatestQueue<RawFrame> queue_;
  std::unique_ptr<freenect_context, ContextDeleter> context_;
  std::unique_ptr<freenect_device, DeviceDeleter> device_;
  bool registered_ = false;
  int width_ = 640;
  int height_ = 480;
  KinectRawDepthTable raw_depth_;
  // Driver thread only.
  std::optional<DeviceClock> clock_;
  cv::Mat pending_rgb_;
  cv::Mat pending_depth_;
  Timestamp pending_colour_time_ = 0.0;
  Timestamp pending_depth_time_ = 0.0;
  size_t captured_ = 0;
  // Consumer thread only.
  size_t delivered_ = 0;
  std::string end_reason_;
  std::optional<Trajectory> no_ground_truth_;
  // Last member: joined (in the destructor) before the rest goes away.
  std::jthread driver_;
};

}  // namespace

std::unique_ptr<FrameSource> open_camera(const CameraSpec& spec, const CameraOptions& options) {
  return std::make_unique<FreenectSource>(spec, options);
}

}  // namespace pspslam
