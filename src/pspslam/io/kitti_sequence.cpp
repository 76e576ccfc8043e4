#include "pspslam/io/kitti_sequence.h"

#include <array>
#include <cstdio>
#include <limits>

#include "pspslam/core/error.h"
#include "pspslam/io/image_files.h"
#include "pspslam/io/text_lines.h"
#include "pspslam/io/trajectory_io.h"

namespace pspslam {

KittiCalibration read_kitti_calibration(const std::filesystem::path& file, bool right_camera) {
  std::optional<std::array<double, 12>> p0, p1;
  size_t p0_line = 0, p1_line = 0;
  for_each_data_line(file, "KITTI calibration", [&](const TextLine& line) {
    const std::string_view name = line.fields[0];
    // P2, P3, Tr: other sensors; P1 too for the left camera alone.
    if (name != "P0:" && (name != "P1:" || !right_camera)) return;
    if (line.fields.size() != 13) {
      throw Error(line_prefix(file, line.line) + std::string(name) + " expected 12 numbers, got " +
                  std::to_string(line.fields.size() - 1));
    }
    std::array<double, 12> p{};
    for (size_t k = 0; k < 12; ++k) {
      p[k] = parse_number(line.fields[k + 1], file, line.line, std::string(name.substr(0, 2)));
    }
    (name == "P0:" ? p0 : p1) = p;
    (name == "P0:" ? p0_line : p1_line) = line.line;
  });
  if (!p0) throw Error(file.string() + ": no 'P0:' line (the left camera's projection matrix)");
  KittiCalibration calibration;
  calibration.fx = (*p0)[0];
  calibration.cx = (*p0)[2];
  calibration.fy = (*p0)[5];
  calibration.cy = (*p0)[6];
  if (!(calibration.fx > 0.0) || !(calibration.fy > 0.0)) {
    throw Error(line_prefix(file, p0_line) + "P0 focal lengths must be > 0");
  }
  if (!right_camera) return calibration;
  if (!p1) throw Error(file.string() + ": no 'P1:' line (the right camera's projection matrix)");
  if (std::abs((*p1)[0] - calibration.fx) > 1e-6 * calibration.fx) {
    throw Error(line_prefix(file, p1_line) + "P1 fx " + std::to_string((*p1)[0]) +
                " differs from P0's " + std::to_string(calibration.fx) + ": not a rectified pair");
  }
  calibration.baseline = -(*p1)[3] / calibration.fx;
  if (!(calibration.baseline > 0.0)) {
    throw Error(line_prefix(file, p1_line) +
                "P1 must put the right camera at a positive baseline (P1[0][3] = -fx * baseline "
                "< 0), got P1[0][3] = " +
                std::to_string((*p1)[3]));
  }
  return calibration;
}

bool KittiSequence::has_right_images(const std::filesystem::path& dir) {
  return std::filesystem::is_directory(dir / "image_1");
}

KittiSequence KittiSequence::open(const std::filesystem::path& dir,
                                  const SequenceOptions& options) {
  if (!std::filesystem::is_directory(dir)) {
    throw Error(dir.string() + ": sequence directory not found");
  }
  const SensorType sensor =
      options.sensor.value_or(has_right_images(dir) ? SensorType::stereo : SensorType::monocular);
  if (sensor == SensorType::rgbd) {
    throw Error(dir.string() + ": a KITTI odometry sequence has no depth images");
  }
  KittiSequence sequence(dir, options, sensor);
  const bool stereo = sequence.stereo();
  const std::filesystem::path times = dir / "times.txt";
  if (!std::filesystem::exists(times)) {
    throw Error(dir.string() +
                ": no times.txt (a KITTI odometry sequence needs times.txt, calib.txt and "
                "image_0/, and image_1/ for stereo)");
  }
  std::vector<FrameFiles> frames;
  std::vector<std::string> listed;
  Timestamp previous = -std::numeric_limits<double>::infinity();
  for_each_data_line(times, "KITTI times", [&](const TextLine& line) {
    if (line.fields.size() != 1) {
      throw Error(line_prefix(times, line.line) + "expected one timestamp, got " +
                  std::to_string(line.fields.size()) + " fields");
    }
    const double t = parse_number(line.fields[0], times, line.line, "timestamp");
    if (!(t > previous)) {
      throw Error(line_prefix(times, line.line) + "timestamp " + std::string(line.fields[0]) +
                  " does not increase");
    }
    previous = t;
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", frames.size());
    FrameFiles files{t, std::string("image_0/") + name, t,
                     stereo ? std::string("image_1/") + name : std::string()};
    listed.push_back(files.rgb_file);
    if (stereo) listed.push_back(files.depth_file);
    frames.push_back(std::move(files));
  });
  sequence.listed_rgb_ = frames.size();
  sequence.listed_depth_ = stereo ? frames.size() : 0;
  std::vector<Timestamp> stamps;
  for (const FrameFiles& f : frames) stamps.push_back(f.rgb_timestamp);
  sequence.keep_present_frames(std::move(frames), listed);
  if (sequence.frames_.empty()) {
    throw Error(dir.string() + ": no " + to_string(sensor) + " frame: " +
                std::to_string(sequence.listed_rgb_) + " listed in times.txt, none with " +
                (stereo ? "both image_0/ and image_1/ files" : "its image_0/ file") + " present");
  }
  sequence.calibration_ = read_kitti_calibration(dir / "calib.txt", stereo);
  sequence.ground_truth_file_ = "poses.txt";
  const std::filesystem::path poses = dir / sequence.ground_truth_file_;
  if (std::filesystem::exists(poses)) sequence.ground_truth_ = read_kitti_trajectory(poses, stamps);
  return sequence;
}

std::string KittiSequence::listing() const {
  char text[256];
  if (stereo()) {
    std::snprintf(text, sizeof(text),
                  "%zu colour and %zu right files listed, paired as the kitti layout lists them",
                  listed_rgb_, listed_depth_);
  } else {
    std::snprintf(text, sizeof(text), "%zu left images listed in times.txt, image_0/ alone",
                  listed_rgb_);
  }
  return text;
}

std::optional<LayoutCamera> KittiSequence::layout_camera() const {
  LayoutCamera camera;
  camera.size = read_color_image(dir_ / frames_.front().rgb_file).size();
  camera.fx = calibration_.fx;
  camera.fy = calibration_.fy;
  camera.cx = calibration_.cx;
  camera.cy = calibration_.cy;
  camera.baseline = calibration_.baseline;
  // times.txt's mean rate.
  if (size() > 1) {
    camera.rate_hz = static_cast<double>(size() - 1) / (timestamp(size() - 1) - timestamp(0));
  }
  return camera;
}

}  // namespace pspslam
