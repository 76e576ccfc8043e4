// End to end without a Kinect: libfreenect's replay library fakenect plays a dump made from a
// synthetic sequence in place of the device, and the built `pspslam` runs on it (`run --camera
// freenect`, `record`) exactly as it would on a Kinect v1.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <fstream>
#include <iterator>

#include "fakenect_dump.h"
#include "pspslam/capture/camera_spec.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/io/tum_sequence.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

struct Result {
  int status = 0;
  std::string output;
};

Result shell(const std::string& command) {
  Result result;
  result.status = testing::run_shell(command, &result.output);
  return result;
}

Result pspslam(const std::string& arguments) {
  return shell(std::string(PSPSLAM_CLI_PATH) + " " + arguments);
}

// `pspslam ARGUMENTS` with fakenect replaying `dump` as the Kinect.
Result replayed(const std::filesystem::path& dump, const std::string& arguments) {
  return shell(testing::fakenect_environment(dump) + PSPSLAM_CLI_PATH + " " + arguments);
}

using testing::contains;

nlohmann::json read_json(const std::filesystem::path& file) {
  std::ifstream stream(file);
  return nlohmann::json::parse(stream);
}

size_t data_lines(const std::filesystem::path& file) {
  std::ifstream stream(file);
  size_t lines = 0;
  for (std::string line; std::getline(stream, line);) lines += !line.empty() && line[0] != '#';
  return lines;
}

// Each test in its own folder (ctest runs them in parallel): a synthetic sequence (people
// walking, 640x480) and its fakenect dumps, made by the tests that replay them.
class Fakenect : public ::testing::Test {
 protected:
  static constexpr size_t kFrames = 40;

  void SetUp() override {
    if (testing::fakenect_library_dir().empty())
      GTEST_SKIP() << "fakenect is not installed (Debian libfreenect0.5)";
    root_ = testing::make_temp_dir("fakenect");
  }

  // seq/: the sequence; dump/: all of it played at 4 frames/s (slow enough that a run keeps up
  // and drops nothing), the device clock starting half a second before its 32-bit wrap;
  // fast/: the same at 6.7 frames/s (for recording); live/: at the Kinect's 30 frames/s;
  // short/: the first 12 frames at 5 frames/s. (The slow rates keep runs and recordings free of
  // drops also while ctest runs other tests beside them.)
  void make_sequence_and_dumps() {
    const Result synth = pspslam("synth --out " + (root_ / "seq").string() + " --frames " +
                                 std::to_string(kFrames) + " --bodies 2 --seed 4 -q");
    ASSERT_EQ(synth.status, 0) << synth.output;
    const TumSequence sequence = TumSequence::open(root_ / "seq");
    testing::write_fakenect_dump(sequence, root_ / "dump",
                                 {.interval_s = 0.25, .first_ticks = 0xffffffffu - 30'000'000u});
    testing::write_fakenect_dump(sequence, root_ / "fast", {.interval_s = 0.15});
    testing::write_fakenect_dump(sequence, root_ / "live", {.interval_s = 1.0 / 30.0});
    testing::write_fakenect_dump(sequence, root_ / "short", {.frames = 12, .interval_s = 0.2});
  }
  const std::filesystem::path& root() const { return root_; }

 private:
  std::filesystem::path root_;
};

// ATE RMSE (m) of `estimate` against `reference` after moving the estimate onto the reference's
// clock (the camera stamps with the wall clock): both must hold the same frames.
double ate_between(const std::filesystem::path& reference, const std::filesystem::path& estimate,
                   const std::filesystem::path& shifted_file) {
  const Trajectory a = read_tum_trajectory(reference);
  Trajectory b = read_tum_trajectory(estimate);
  EXPECT_EQ(a.size(), b.size());
  if (a.empty() || b.empty()) return 1e9;
  const double offset = a[0].timestamp - b[0].timestamp;
  for (StampedPose& pose : b) pose.timestamp += offset;
  write_tum_trajectory(shifted_file, b);
  const Result eval =
      pspslam("eval --gt " + reference.string() + " --est " + shifted_file.string() + " --json");
  EXPECT_EQ(eval.status, 0) << eval.output;
  const nlohmann::json error = nlohmann::json::parse(eval.output)["ate"]["error_m"];
  EXPECT_EQ(error["count"], a.size()) << eval.output;
  return error["rmse"].get<double>();
}

// The camera run on the replayed dump is the folder run of the same frames: `record` the dump,
// run on the recording, run on the camera: same number of poses, timestamps from the device clock
// (across its wrap) spaced as the sequence's, ATE between the two trajectories under 2 mm.
// Against the run on the original synthetic folder the dump differs by the Kinect's raw
// disparity steps (kinect_depth.h), which moves the trajectory by about as much as the run's own
// error against the ground truth: checked under 3 mm.
TEST_F(Fakenect, CameraRunMatchesTheFolderRun) {
  make_sequence_and_dumps();
  const Result record = replayed(
      root() / "fast", "record --camera freenect --out " + (root() / "recording").string() +
                           " --frames " + std::to_string(kFrames) + " --config " +
                           (root() / "seq/config.yaml").string() + " -q");
  ASSERT_EQ(record.status, 0) << record.output;
  const std::string common = " --dynamic geometry --loop-closing off -q";
  for (const std::string folder : {"seq", "recording"}) {
    const Result run = pspslam("run --sequence " + (root() / folder).string() + " --out " +
                               (root() / (folder + "_out")).string() + common);
    ASSERT_EQ(run.status, 0) << run.output;
  }
  // A camera run is live: a frame that arrives while the previous one is still being tracked is
  // dropped, and the replay then ends before --max-frames (exit 4). The dump's 4 frames/s leave
  // room for ctest's other tests; a machine loaded far beyond that can still drop one, which is
  // the camera behaving as it should, so such a run is repeated (at most twice) rather than
  // compared.
  Result camera;
  for (int attempt = 1;; ++attempt) {
    camera = replayed(root() / "dump", "run --camera freenect --config " +
                                           (root() / "seq/config.yaml").string() +
                                           " --max-frames " + std::to_string(kFrames) + " --out " +
                                           (root() / "camera_out").string() + common);
    const auto stats_file = root() / "camera_out/stats.json";
    if (attempt == 3 || !std::filesystem::exists(stats_file) ||
        read_json(stats_file)["input"]["dropped_frames"] == 0)
      break;
    std::cout << "camera run " << attempt << " dropped a frame (machine load); running it again\n";
  }
  ASSERT_EQ(camera.status, 0) << camera.output;
  EXPECT_TRUE(contains(camera.output,
                       "camera:       freenect:0 (Kinect v1 through libfreenect, "
                       "640x480, depth raw 11-bit disparity"))
      << camera.output;

  const nlohmann::json stats = read_json(root() / "camera_out/stats.json");
  EXPECT_EQ(stats["sequence"], "freenect:0");
  EXPECT_EQ(stats["frames"], kFrames);
  EXPECT_EQ(stats["input"]["dropped_frames"], 0);
  EXPECT_EQ(stats["input"]["disconnected"], false);

  const Trajectory from_folder = read_tum_trajectory(root() / "seq_out/trajectory.txt");
  const Trajectory from_camera = read_tum_trajectory(root() / "camera_out/trajectory.txt");
  ASSERT_EQ(from_camera.size(), from_folder.size());
  ASSERT_GE(from_camera.size(), kFrames - 2);
  for (size_t i = 1; i < from_camera.size(); ++i) {
    EXPECT_NEAR(from_camera[i].timestamp - from_camera[0].timestamp,
                from_folder[i].timestamp - from_folder[0].timestamp, 2e-6)
        << i;
  }
  const double same_frames =
      ate_between(root() / "recording_out/trajectory.txt", root() / "camera_out/trajectory.txt",
                  root() / "camera_on_recording_clock.txt");
  const double original =
      ate_between(root() / "seq_out/trajectory.txt", root() / "camera_out/trajectory.txt",
                  root() / "camera_on_sequence_clock.txt");
  EXPECT_LT(same_frames, 0.002);
  EXPECT_LT(original, 0.003);
  std::cout << "ATE RMSE camera run vs run on its recording: " << same_frames
            << " m; vs run on the synthetic folder: " << original << " m\n";
}

// `record` writes the replayed Kinect as a TUM folder that `run --sequence` reads back, frame
// for frame, with the preset config and depth at its depth factor.
TEST_F(Fakenect, RecordingRoundTripsThroughRun) {
  make_sequence_and_dumps();
  const auto rec = root() / "recording";
  const Result record = replayed(
      root() / "fast", "record --camera freenect:0 --out " + rec.string() + " --frames 10 -q");
  ASSERT_EQ(record.status, 0) << record.output;
  EXPECT_TRUE(contains(record.output, "recorded:     10 frames, 0 dropped")) << record.output;
  EXPECT_EQ(data_lines(rec / "rgb.txt"), 10u);
  EXPECT_EQ(data_lines(rec / "depth.txt"), 10u);
  std::ifstream preset(camera_config_preset(parse_camera_spec("freenect")));
  std::ifstream copied(rec / "config.yaml");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(copied), {}),
            std::string(std::istreambuf_iterator<char>(preset), {}));

  // The recorded depth is the sequence's depth through the Kinect's disparity steps.
  const TumSequence original = TumSequence::open(root() / "seq");
  const TumSequence recorded = TumSequence::open(rec);
  ASSERT_EQ(recorded.size(), 10u);
  const cv::Mat a = original.load(3).depth, b = recorded.load(3).depth;
  double worst = 0.0;
  for (int y = 0; y < a.rows; ++y)
    for (int x = 0; x < a.cols; ++x)
      if (a.at<float>(y, x) > 0 && a.at<float>(y, x) < 8)
        worst = std::max(worst, std::abs(double{a.at<float>(y, x)} - b.at<float>(y, x)) /
                                    (double{a.at<float>(y, x)} * a.at<float>(y, x)));
  EXPECT_LT(worst, 0.5 * 0.0031 + 0.0002);  // half a disparity step, + 1/5000 m rounding
  EXPECT_EQ(cv::norm(original.load(3).bgr, recorded.load(3).bgr, cv::NORM_INF), 0.0);

  const Result run = pspslam("run --sequence " + rec.string() + " --out " +
                             (root() / "recording_out").string() + " --dynamic off -q");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(read_json(root() / "recording_out/stats.json")["frames"], 10);
}

// A dump that ends early is a Kinect unplugged mid-run: the run ends cleanly with status 4,
// every output written and the reason in the summary and stats.json; `record` keeps a valid
// folder of what it got, also with status 4.
TEST_F(Fakenect, UnpluggedMidRunEndsWithStatusFourAndEveryOutput) {
  make_sequence_and_dumps();
  const Result run = replayed(root() / "short", "run --camera freenect --config " +
                                                    (root() / "seq/config.yaml").string() +
                                                    " --out " + (root() / "short_out").string() +
                                                    " --dynamic off --loop-closing off -q");
  EXPECT_EQ(run.status, 4) << run.output;
  EXPECT_TRUE(contains(run.output,
                       "error: camera freenect:0 stopped: libfreenect's event loop "
                       "failed (code -1): the Kinect was unplugged, or a fakenect "
                       "replay reached the end of its INDEX.txt after 12 frames"))
      << run.output;
  const nlohmann::json stats = read_json(root() / "short_out/stats.json");
  EXPECT_EQ(stats["frames"], 12);
  EXPECT_EQ(stats["input"]["disconnected"], true);
  EXPECT_TRUE(contains(stats["input"]["end_reason"].get<std::string>(), "unplugged"));
  EXPECT_GE(read_tum_trajectory(root() / "short_out/trajectory.txt").size(), 10u);
  EXPECT_TRUE(std::filesystem::exists(root() / "short_out/trajectory_refined.txt"));

  const auto rec = root() / "short_recording";
  const Result record =
      replayed(root() / "short", "record --camera freenect --out " + rec.string() + " -q");
  EXPECT_EQ(record.status, 4) << record.output;
  EXPECT_EQ(TumSequence::open(rec).size(), 12u);
}

// At the device's rate a run that cannot keep up never holds the driver back: the newest frames
// win, and every captured frame is either processed or counted as dropped (summary and
// stats.json). The replay's end is then the camera going away: status 4.
// (Deterministic `full` waits for each PSPNet mask, which on a small CPU takes longer than a
// frame interval, so frames are dropped there.)
TEST_F(Fakenect, RunAtThirtyHertzCountsEveryDroppedFrame) {
  make_sequence_and_dumps();
  const Result run =
      replayed(root() / "live", "run --camera freenect --dynamic full --config " +
                                    (root() / "seq/config.yaml").string() + " --out " +
                                    (root() / "live_out").string() + " -q");
  EXPECT_EQ(run.status, 4) << run.output;
  const nlohmann::json stats = read_json(root() / "live_out/stats.json");
  const size_t processed = stats["frames"], dropped = stats["input"]["dropped_frames"];
  EXPECT_EQ(processed + dropped, kFrames) << run.output;
  EXPECT_EQ(stats["realtime_dropped_frames"], dropped);
  EXPECT_TRUE(
      contains(run.output, std::to_string(dropped) + " frames dropped by the real-time feed"))
      << run.output;
  std::cout << "30 Hz replay, --dynamic full: " << processed << " processed, " << dropped
            << " dropped\n";
}

// A camera that stays connected but sends nothing (here a replay that stalls for 5 s after frame
// 5) ends the run after 3 s of silence like an unplug: status 4, the reason, every output.
TEST_F(Fakenect, SilentCameraEndsTheRunAfterThreeSeconds) {
  make_sequence_and_dumps();
  const TumSequence sequence = TumSequence::open(root() / "seq");
  testing::write_fakenect_dump(sequence, root() / "stall",
                               {.frames = 10, .interval_s = 0.2, .pause_after = 5, .pause_s = 5.0});
  const Result run =
      replayed(root() / "stall", "run --camera freenect --dynamic off --config " +
                                     (root() / "seq/config.yaml").string() + " --out " +
                                     (root() / "stall_out").string() + " -q");
  EXPECT_EQ(run.status, 4) << run.output;
  EXPECT_TRUE(contains(run.output,
                       "error: camera freenect:0 stopped: no frame for 3.0 s "
                       "(unplugged or hung) after 6 frames"))
      << run.output;
  const nlohmann::json stats = read_json(root() / "stall_out/stats.json");
  EXPECT_EQ(stats["frames"], 6);
  EXPECT_EQ(stats["input"]["disconnected"], true);
}

// Ctrl-C ends a camera run with status 130 and every output, like a folder run.
TEST_F(Fakenect, InterruptedCameraRunWritesEveryOutput) {
  make_sequence_and_dumps();
  const Result run =
      shell(testing::fakenect_environment(root() / "dump") + PSPSLAM_CLI_PATH +
            " run --camera freenect --dynamic off --config " +
            (root() / "seq/config.yaml").string() + " --out " + (root() / "int_out").string() +
            " -q & pid=$!; sleep 3; kill -INT $pid; wait $pid");
  EXPECT_EQ(run.status, 130) << run.output;
  EXPECT_TRUE(contains(run.output, "interrupted after ")) << run.output;
  const nlohmann::json stats = read_json(root() / "int_out/stats.json");
  EXPECT_EQ(stats["interrupted"], true);
  EXPECT_GE(stats["frames"].get<size_t>(), 3u);
  EXPECT_LT(stats["frames"].get<size_t>(), kFrames);
}

// Ctrl-C ends an open-ended recording with status 0 and a valid folder.
TEST_F(Fakenect, InterruptedRecordingIsAValidSequence) {
  make_sequence_and_dumps();
  const auto rec = root() / "interrupted";
  const Result record = shell(testing::fakenect_environment(root() / "dump") + PSPSLAM_CLI_PATH +
                              " record --camera freenect --out " + rec.string() +
                              " -q & pid=$!; sleep 2.5; kill -INT $pid; wait $pid");
  EXPECT_EQ(record.status, 0) << record.output;
  const TumSequence recorded = TumSequence::open(rec);
  EXPECT_GE(recorded.size(), 4u);
  EXPECT_LT(recorded.size(), kFrames);
  EXPECT_EQ(data_lines(rec / "depth.txt"), recorded.size());
}

// No dump to replay, and no device at all: status 2 with the reason, before any run.
TEST_F(Fakenect, NoDeviceIsAUserErrorWithStatusTwo) {
  const Result missing = replayed(
      root() / "absent", "run --camera freenect --out " + (root() / "absent_out").string() + " -q");
  EXPECT_EQ(missing.status, 2);
  EXPECT_EQ(missing.output, "error: --camera freenect:0: FAKENECT_PATH is set but " +
                                (root() / "absent/INDEX.txt").string() +
                                " does not exist (no fakenect dump to replay)\n");
  if (!find_kinect_cameras().empty()) GTEST_SKIP() << "a Kinect is plugged in";
  // The real libfreenect, no Kinect on the bus.
  for (const std::string& command :
       {"run --camera freenect --out " + (root() / "none_out").string(),
        "record --camera freenect:1 --out " + (root() / "none_rec").string()}) {
    const Result none = pspslam(command + " -q");
    EXPECT_EQ(none.status, 2) << command;
    EXPECT_TRUE(contains(none.output,
                         ": no Kinect v1 found (libfreenect sees no device and the "
                         "USB bus lists no 045e:02ae 'Xbox NUI Camera')"))
        << none.output;
  }
}

}  // namespace
}  // namespace pspslam
