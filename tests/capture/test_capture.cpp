// Unit tests of the camera input pieces that need no device: raw Kinect depth, the device clock,
// the newest-frame-wins queue, --camera parsing, the USB error mapping, the TUM recorder and the
// paced sequence source.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "pspslam/capture/camera_spec.h"
#include "pspslam/capture/device_clock.h"
#include "pspslam/capture/kinect_depth.h"
#include "pspslam/capture/sequence_recorder.h"
#include "pspslam/core/error.h"
#include "pspslam/core/latest_queue.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/io/sequence_source.h"
#include "pspslam/io/tum_sequence.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

using testing::error_of;

TEST(KinectDepth, RawAndMetresRoundTripWithinOneDisparityStep) {
  EXPECT_EQ(kinect_raw_to_metres(kKinectRawNoReading), 0.0f);
  EXPECT_EQ(kinect_raw_to_metres(2000), 0.0f);  // beyond the fit's range: no reading
  EXPECT_EQ(kinect_metres_to_raw(0.0), kKinectRawNoReading);
  EXPECT_EQ(kinect_metres_to_raw(20.0), kKinectRawNoReading);
  // The fit: raw 0 is 0.30 m; 1 m and 2 m lie near raw 759 and 922.
  EXPECT_NEAR(kinect_raw_to_metres(0), 1.0 / 3.3309495161, 1e-6);
  EXPECT_EQ(kinect_metres_to_raw(1.0), 759);
  EXPECT_EQ(kinect_metres_to_raw(2.0), 922);
  for (uint16_t raw = 0; raw < 1050; ++raw) {
    const float metres = kinect_raw_to_metres(raw);
    ASSERT_GT(metres, 0.0f) << raw;
    EXPECT_EQ(kinect_metres_to_raw(metres), raw);
  }
  // One disparity step is d^2 * 0.00307 m: the quantisation a replay dump adds.
  for (const double metres : {0.8, 1.5, 2.5, 4.0}) {
    const double back = kinect_raw_to_metres(kinect_metres_to_raw(metres));
    EXPECT_LE(std::abs(back - metres), 0.5 * metres * metres * 0.0030711016 + 1e-6) << metres;
  }
  const KinectRawDepthTable table;
  cv::Mat raw(2, 3, CV_16UC1);
  raw.at<uint16_t>(0, 0) = 759;
  raw.at<uint16_t>(0, 1) = 2047;
  raw.at<uint16_t>(0, 2) = 922 | 0xf800;  // bits above the 11 are ignored
  raw.at<uint16_t>(1, 0) = 0;
  raw.at<uint16_t>(1, 1) = 1200;
  raw.at<uint16_t>(1, 2) = 500;
  const cv::Mat metres = table.convert(raw);
  ASSERT_EQ(metres.type(), CV_32FC1);
  EXPECT_FLOAT_EQ(metres.at<float>(0, 0), kinect_raw_to_metres(759));
  EXPECT_EQ(metres.at<float>(0, 1), 0.0f);
  EXPECT_FLOAT_EQ(metres.at<float>(0, 2), kinect_raw_to_metres(922));
  EXPECT_EQ(metres.at<float>(1, 1), 0.0f);
  EXPECT_FLOAT_EQ(metres.at<float>(1, 2), kinect_raw_to_metres(500));
}

TEST(DeviceClock, SixtyMegahertzTicksUnwrapAcrossTheThirtyTwoBitWrap) {
  DeviceClock clock(1000.0);
  const uint32_t start = 0xffffffffu - 30'000'000u;  // wraps 0.5 s in
  EXPECT_DOUBLE_EQ(clock.seconds(start), 1000.0);
  EXPECT_NEAR(clock.seconds(start + 2'000'000u), 1000.0 + 1.0 / 30.0, 1e-9);
  EXPECT_NEAR(clock.seconds(start + 1'990'000u), 1000.0 + 0.033166667, 1e-9);  // other stream
  uint32_t ticks = start;
  for (int i = 0; i < 300; ++i) ticks += 2'000'000u;  // 10 s, across the wrap
  EXPECT_LT(ticks, start);
  EXPECT_NEAR(clock.seconds(ticks), 1010.0, 1e-9);
  ticks += 2'000'000u * 3000u;  // 100 s more: past a second wrap, stamped every 1/30 s
  for (int i = 0; i < 3000; ++i) clock.seconds(ticks - 2'000'000u * (2999u - i));
  EXPECT_NEAR(clock.seconds(ticks), 1110.0, 1e-6);
}

TEST(LatestQueue, FullQueueDropsTheOldestAndNeverBlocksTheProducer) {
  LatestQueue<int> queue(2);
  for (int i = 0; i < 5; ++i) queue.push(i);
  EXPECT_EQ(queue.dropped(), 3u);
  EXPECT_EQ(queue.pop(std::chrono::milliseconds(0)), 3);
  EXPECT_EQ(queue.pop(std::chrono::milliseconds(0)), 4);
  const auto before = std::chrono::steady_clock::now();
  EXPECT_EQ(queue.pop(std::chrono::milliseconds(50)), std::nullopt);
  EXPECT_GE(std::chrono::steady_clock::now() - before, std::chrono::milliseconds(45));
  EXPECT_FALSE(queue.closed());
  // A waiting consumer wakes for a frame from another thread, and for the end of the stream.
  std::jthread producer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    queue.push(7);
    queue.close("unplugged");
    queue.push(8);  // after close: ignored
  });
  EXPECT_EQ(queue.pop(std::chrono::seconds(5)), 7);
  producer.join();
  queue.close("second reason");
  EXPECT_EQ(queue.pop(std::chrono::seconds(5)), std::nullopt);
  EXPECT_TRUE(queue.closed());
  EXPECT_EQ(queue.close_reason(), "unplugged");
  EXPECT_EQ(queue.dropped(), 3u);
}

TEST(CameraSpec, DriverAndIndexAreParsedAndBadValuesNamed) {
  EXPECT_EQ(parse_camera_spec("freenect").text(), "freenect:0");
  EXPECT_EQ(parse_camera_spec("freenect:2").index, 2);
  EXPECT_EQ(error_of([] { parse_camera_spec("openni2"); }),
            "--camera: unknown camera driver 'openni2' (supported: freenect, a Kinect v1 "
            "through libfreenect)");
  for (const std::string bad : {"freenect:", "freenect:x", "freenect:-1", "freenect:1x"}) {
    EXPECT_EQ(error_of([&] { parse_camera_spec(bad); }),
              "--camera: '" + bad + "': INDEX must be a device number (0, 1, ...)");
  }
  EXPECT_EQ(camera_config_preset(parse_camera_spec("freenect")),
            data_dir() / "config" / "kinect_v1.yaml");
  EXPECT_TRUE(std::filesystem::exists(camera_config_preset(parse_camera_spec("freenect"))));
}

TEST(CameraErrors, PermissionDeniedNamesTheUdevRuleAndGroup) {
  const std::string denied = explain_camera_failure(0, 1, {{"/dev/bus/usb/001/007", false}});
  EXPECT_NE(denied.find("--camera freenect:0: permission denied on the Kinect's USB device "
                        "/dev/bus/usb/001/007"),
            std::string::npos)
      << denied;
  EXPECT_NE(denied.find("/lib/udev/rules.d/60-libfreenect0.5.rules"), std::string::npos);
  EXPECT_NE(denied.find("plugdev"), std::string::npos);
  // libfreenect itself sees no device when it may not open it: still the permission message.
  EXPECT_EQ(explain_camera_failure(0, 0, {{"/dev/bus/usb/001/007", false}}), denied);

  EXPECT_EQ(explain_camera_failure(0, 0, {}),
            "--camera freenect:0: no Kinect v1 found (libfreenect sees no device and the USB bus "
            "lists no 045e:02ae 'Xbox NUI Camera'): is it plugged in and on its own power "
            "supply?");
  EXPECT_EQ(explain_camera_failure(2, 1, {{"/dev/bus/usb/001/007", true}}),
            "--camera freenect:2: only 1 Kinect found (indices 0..0)");
  EXPECT_NE(explain_camera_failure(0, 1, {{"/dev/bus/usb/001/007", true}})
                .find("cannot open the Kinect (is another program using it?"),
            std::string::npos);
}

TEST(CameraErrors, KinectCamerasAreFoundInSysfsWithTheirDeviceFiles) {
  const auto root = testing::make_temp_dir("capture_sysfs");
  const auto device = [&](const std::string& name, const std::string& vendor,
                          const std::string& product, int bus, int number) {
    const auto dir = root / "sys" / name;
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "idVendor") << vendor << "\n";
    std::ofstream(dir / "idProduct") << product << "\n";
    std::ofstream(dir / "busnum") << bus << "\n";
    std::ofstream(dir / "devnum") << number << "\n";
  };
  device("1-1", "045e", "02ae", 1, 7);   // Kinect camera, device file present
  device("1-2", "045e", "02b0", 1, 8);   // Kinect motor: not a camera
  device("2-1", "046d", "0825", 2, 3);   // a webcam
  device("3-4", "045e", "02ae", 3, 12);  // Kinect camera whose device file is missing
  std::filesystem::create_directories(root / "dev" / "001");
  std::ofstream(root / "dev" / "001" / "007") << "";
  std::vector<UsbCameraNode> found = find_kinect_cameras(root / "sys", root / "dev");
  std::sort(found.begin(), found.end(),
            [](const auto& a, const auto& b) { return a.device_file < b.device_file; });
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].device_file, (root / "dev" / "001" / "007").string());
  EXPECT_TRUE(found[0].accessible);
  EXPECT_EQ(found[1].device_file, (root / "dev" / "003" / "012").string());
  EXPECT_FALSE(found[1].accessible);
  EXPECT_TRUE(find_kinect_cameras(root / "absent", root / "dev").empty());
}

TEST(SequenceRecorder, WritesATumSequenceThatReadsBackFramePerFrame) {
  const auto dir = testing::make_temp_dir("capture_recorder");
  const auto config = dir / "camera.yaml";
  std::ofstream(config) << "camera:\n  width: 8\n  height: 6\n  fx: 10\n  fy: 10\n  cx: 4\n"
                           "  cy: 3\n  distortion: [0, 0, 0, 0]\n  fps: 30\n  depth_factor: 1000\n"
                           "  depth_threshold: 3\n";
  {
    SequenceRecorder recorder(dir / "rec", config, 1000.0);
    for (int i = 0; i < 3; ++i) {
      InputFrame frame;
      frame.timestamp = 1700000000.5 + i / 30.0;
      frame.depth_timestamp = frame.timestamp + 0.004;
      frame.bgr = cv::Mat(6, 8, CV_8UC3, cv::Scalar(10 * i, 20, 30));
      frame.depth = cv::Mat(6, 8, CV_32FC1, cv::Scalar(1.2346f + i));
      frame.depth.at<float>(0, 0) = 0.0f;
      frame.depth.at<float>(0, 1) = 70.0f;  // beyond 65.535 m at factor 1000: clipped
      recorder.add(frame);
      // Flushed per frame: what is on disk now is a valid sequence (Ctrl-C leaves it so).
      const TumSequence partial = TumSequence::open(dir / "rec", {.depth_factor = 1000.0});
      EXPECT_EQ(partial.size(), static_cast<size_t>(i + 1));
    }
    EXPECT_EQ(recorder.frames(), 3u);
  }
  const SequenceSetup setup = open_sequence_with_config(dir / "rec", std::nullopt, nullptr);
  EXPECT_EQ(setup.config.camera.depth_factor, 1000.0);
  ASSERT_EQ(setup.sequence->size(), 3u);
  const InputFrame back = setup.sequence->load(2);
  EXPECT_EQ(back.name, "rgb/1700000000.566667.png");
  EXPECT_NEAR(back.timestamp, 1700000000.5 + 2 / 30.0, 1e-6);
  EXPECT_NEAR(back.depth_timestamp, back.timestamp + 0.004, 1e-6);
  EXPECT_EQ(back.bgr.at<cv::Vec3b>(3, 3), cv::Vec3b(20, 20, 30));
  EXPECT_FLOAT_EQ(back.depth.at<float>(3, 3), 3.235f);  // 3.2346 m in mm, rounded
  EXPECT_EQ(back.depth.at<float>(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(back.depth.at<float>(0, 1), 65.535f);

  EXPECT_NE(error_of([&] {
              SequenceRecorder(dir / "rec", config, 1000.0);
            }).find("--out: " + (dir / "rec").string() + " exists and is not an empty folder"),
            std::string::npos);
}

// Records an 8x6 sequence of `frames` frames at `fps` into DIR/seq (returned): frame i is grey
// level grey_step * i with 1 m depth everywhere.
std::filesystem::path record_tiny_sequence(const std::filesystem::path& dir, int frames, int fps,
                                           int grey_step) {
  const auto config = dir / "camera.yaml";
  std::ofstream(config) << "camera:\n  width: 8\n  height: 6\n  fx: 10\n  fy: 10\n  cx: 4\n"
                           "  cy: 3\n  distortion: [0, 0, 0, 0]\n  fps: "
                        << fps << "\n  depth_factor: 5000\n  depth_threshold: 3\n";
  SequenceRecorder recorder(dir / "seq", config, 5000.0);
  for (int i = 0; i < frames; ++i) {
    InputFrame frame;
    frame.timestamp = frame.depth_timestamp = 50.0 + i / static_cast<double>(fps);
    frame.bgr = cv::Mat(6, 8, CV_8UC3, cv::Scalar::all(grey_step * i));
    frame.depth = cv::Mat(6, 8, CV_32FC1, cv::Scalar(1.0f));
    recorder.add(frame);
  }
  return dir / "seq";
}

TEST(SequenceSource, DeterministicGivesEveryFrameAndPacedDropsLateOnes) {
  const auto dir = testing::make_temp_dir("capture_source");
  record_tiny_sequence(dir, 20, 100, 1);
  SequenceSource all(open_sequence_with_config(dir / "seq", std::nullopt, nullptr), 15, false);
  EXPECT_EQ(all.frame_count(), 15u);
  EXPECT_EQ(all.name(), (dir / "seq").string());
  size_t count = 0;
  while (const std::optional<InputFrame> frame = all.next()) {
    EXPECT_EQ(frame->index, count++);
    EXPECT_FALSE(frame->arrival) << "an unpaced frame has no arrival to measure latency from";
  }
  EXPECT_EQ(count, 15u);
  EXPECT_EQ(all.stats().dropped, 0u);
  EXPECT_FALSE(all.stats().disconnected);

  // Paced: a consumer that takes 35 ms per frame of a 100 Hz sequence sees about every 4th.
  SequenceSource paced(open_sequence_with_config(dir / "seq", std::nullopt, nullptr), 0, true);
  size_t delivered = 0;
  size_t last = 0;
  std::optional<std::chrono::steady_clock::time_point> first_arrival;
  while (const std::optional<InputFrame> frame = paced.next()) {
    // A frame arrives when it is due (10 ms per frame from the first), even when the busy
    // consumer takes it later: that wait is part of its latency.
    ASSERT_TRUE(frame->arrival);
    if (!first_arrival) first_arrival = frame->arrival;
    const double due_ms =
        std::chrono::duration<double, std::milli>(*frame->arrival - *first_arrival).count();
    EXPECT_NEAR(due_ms, 10.0 * static_cast<double>(frame->index), 1e-3) << frame->index;
    EXPECT_LE(*frame->arrival, std::chrono::steady_clock::now());
    // Skips at least one frame each time, except where it reaches the last frame.
    if (delivered++ > 0 && frame->index + 1 < 20) {
      EXPECT_GT(frame->index, last + 1);
    }
    last = frame->index;
    std::this_thread::sleep_for(std::chrono::milliseconds(35));
  }
  EXPECT_LT(delivered, 10u);
  EXPECT_EQ(delivered + paced.stats().dropped, 20u);
}

// --preload: a consumer that keeps up gets every frame, decoded before the clock started, each
// at its due time; preloading an unpaced source is refused.
TEST(SequenceSource, PreloadedPacedSourceDeliversEveryFrameWhenDue) {
  const auto dir = testing::make_temp_dir("capture_preload");
  record_tiny_sequence(dir, 12, 50, 10);
  SequenceSource source(open_sequence_with_config(dir / "seq", std::nullopt, nullptr), 0, true,
                        Preload::on);
  size_t delivered = 0;
  std::optional<std::chrono::steady_clock::time_point> first_arrival;
  while (const std::optional<InputFrame> frame = source.next()) {
    EXPECT_EQ(frame->index, delivered);
    EXPECT_EQ(frame->bgr.at<cv::Vec3b>(0, 0)[0], 10 * delivered);
    ASSERT_TRUE(frame->arrival);
    if (!first_arrival) first_arrival = frame->arrival;
    const double due_ms =
        std::chrono::duration<double, std::milli>(*frame->arrival - *first_arrival).count();
    EXPECT_NEAR(due_ms, 20.0 * static_cast<double>(frame->index), 1e-3);
    ++delivered;
  }
  EXPECT_EQ(delivered, 12u);
  EXPECT_EQ(source.stats().dropped, 0u);
  EXPECT_TRUE(source.describe().ends_with(
      "replay:       paced at the recording's rate; every frame decoded before the start (0.00 "
      "GiB, --preload)\n"))
      << source.describe();
  try {
    SequenceSource unpaced(open_sequence_with_config(dir / "seq", std::nullopt, nullptr), 0, false,
                           Preload::on);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "--preload: only a --realtime run replays at the camera's rate");
  }
}

}  // namespace
}  // namespace pspslam
