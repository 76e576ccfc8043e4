#include "pspslam/io/sequence_setup.h"

#include <cstdio>
#include <sstream>

#include "pspslam/core/error.h"
#include "pspslam/io/euroc_sequence.h"
#include "pspslam/io/kitti_sequence.h"
#include "pspslam/io/tum_sequence.h"

namespace pspslam {

void apply_sensor_override(SystemConfig& config, SensorType sensor,
                           const std::filesystem::path& config_file) {
  if (config.camera.type == sensor) return;
  if (sensor == SensorType::monocular) {
    // Any camera has a colour (left) image: an RGB-D config's depth keys are simply not used.
    config.camera.type = SensorType::monocular;
    return;
  }
  if (sensor == SensorType::stereo) {
    throw Error("--sensor stereo: " + config_file.string() +
                " describes an rgbd camera and gives no camera.baseline (use a stereo config, "
                "e.g. the one `pspslam synth --stereo` writes)");
  }
  throw Error("--sensor rgbd: " + config_file.string() + " describes a " +
              to_string(config.camera.type) + " camera (no depth_factor); it has no depth image");
}

SequenceLayout detect_sequence_layout(const std::filesystem::path& dir) {
  if (std::filesystem::exists(dir / "times.txt") && std::filesystem::exists(dir / "calib.txt"))
    return SequenceLayout::kitti;
  if (std::filesystem::exists(dir / "mav0" / "cam0" / "data.csv") ||
      std::filesystem::exists(dir / "cam0" / "data.csv"))
    return SequenceLayout::euroc;
  return SequenceLayout::tum;
}

namespace {

// The sensor a self-calibrating layout (KITTI, EuRoC) is read as: `requested` (`--sensor`) when
// given, else stereo when the right camera's images are there and monocular when they are not.
// Neither layout has depth images; stereo needs the right camera.
SensorType layout_sensor(const std::filesystem::path& dir, SequenceLayout layout,
                         std::optional<SensorType> requested) {
  const bool kitti = layout == SequenceLayout::kitti;
  const bool right =
      kitti ? KittiSequence::has_right_images(dir) : EurocSequence::has_right_camera(dir);
  if (!requested) return right ? SensorType::stereo : SensorType::monocular;
  if (*requested == SensorType::rgbd || (*requested == SensorType::stereo && !right)) {
    throw Error("--sensor " + to_string(*requested) + ": " + dir.string() + " is " +
                (kitti ? "a KITTI odometry sequence" : "a EuRoC MAV sequence") +
                (right   ? " (stereo)"
                 : kitti ? " (monocular: image_0/ without image_1/)"
                         : " (monocular: cam0 without cam1/data.csv)"));
  }
  return *requested;
}

std::unique_ptr<const RecordedSequence> open_layout(const std::filesystem::path& dir,
                                                    SequenceLayout layout,
                                                    const SequenceOptions& options) {
  switch (layout) {
    case SequenceLayout::kitti:
      return std::make_unique<const KittiSequence>(KittiSequence::open(dir, options));
    case SequenceLayout::euroc:
      return std::make_unique<const EurocSequence>(EurocSequence::open(dir, options));
    case SequenceLayout::tum:
      break;
  }
  return std::make_unique<const TumSequence>(TumSequence::open(dir, options));
}

// KITTI and EuRoC: the camera is the layout's own calibration (LayoutCamera); the config, when
// given, supplies the rest.
SequenceSetup open_calibrated_layout(const std::filesystem::path& dir, SequenceLayout layout,
                                     const std::optional<std::filesystem::path>& config_file,
                                     std::ostream* warnings, std::optional<SensorType> sensor) {
  const bool kitti = layout == SequenceLayout::kitti;
  SystemConfig config;
  std::filesystem::path config_path =
      kitti ? dir / "calib.txt" : dir / "mav0" / "cam0" / "sensor.yaml";
  if (config_file) {
    config = load_config(*config_file);
    config_path = *config_file;
  }
  SequenceOptions options;
  options.warnings = warnings;
  options.sensor = layout_sensor(dir, layout, sensor);
  std::unique_ptr<const RecordedSequence> sequence = open_layout(dir, layout, options);
  const LayoutCamera calibration = *sequence->layout_camera();
  CameraConfig& camera = config.camera;
  camera.type = sequence->sensor();
  camera.pinhole.width = calibration.size.width;
  camera.pinhole.height = calibration.size.height;
  camera.pinhole.fx = calibration.fx;
  camera.pinhole.fy = calibration.fy;
  camera.pinhole.cx = calibration.cx;
  camera.pinhole.cy = calibration.cy;
  camera.pinhole.distortion = {};  // the frames are rectified, by the dataset or as they load
  camera.baseline = calibration.baseline;
  if (!config_file) {
    camera.name = to_string(layout);
    if (sequence->stereo()) camera.depth_threshold = 40.0 * camera.baseline;
    if (calibration.rate_hz > 0.0) camera.fps = calibration.rate_hz;
  }
  return SequenceSetup{config_path, config, std::move(sequence)};
}

}  // namespace

SequenceSetup open_sequence_with_config(const std::filesystem::path& dir,
                                        const std::optional<std::filesystem::path>& config_file,
                                        std::ostream* warnings, std::optional<SensorType> sensor) {
  if (!std::filesystem::is_directory(dir)) {
    throw Error(dir.string() + ": sequence directory not found");
  }
  const SequenceLayout layout = detect_sequence_layout(dir);
  if (layout != SequenceLayout::tum)
    return open_calibrated_layout(dir, layout, config_file, warnings, sensor);
  std::filesystem::path config_path;
  if (config_file) {
    config_path = *config_file;
  } else if (std::filesystem::exists(dir / "config.yaml")) {
    config_path = dir / "config.yaml";
  } else {
    throw Error(dir.string() + ": no camera config: --config was not given and " +
                (dir / "config.yaml").string() +
                " does not exist (pass a preset, e.g. --config config/bonn.yaml)");
  }
  SystemConfig config = load_config(config_path);
  if (sensor) apply_sensor_override(config, *sensor, config_path);
  SequenceOptions options;
  options.sensor = config.camera.type;
  options.depth_factor = config.camera.depth_factor;
  options.depth_shift_x = config.camera.depth_shift_x;
  options.depth_shift_y = config.camera.depth_shift_y;
  options.warnings = warnings;
  return SequenceSetup{config_path, config, open_layout(dir, layout, options)};
}

std::string describe_sequence(const SequenceSetup& setup) {
  const RecordedSequence& s = *setup.sequence;
  std::ostringstream out;
  char line[512];
  out << "sequence:     " << s.directory().string() << "\n";
  std::snprintf(line, sizeof(line),
                "frames:       %zu (%s; %zu listed files missing, %zu frames skipped)\n", s.size(),
                s.listing().c_str(), s.missing_files(), s.skipped_frames());
  out << line;
  std::snprintf(line, sizeof(line), "time span:    %.3f s (%.5f .. %.5f)\n",
                s.timestamp(s.size() - 1) - s.timestamp(0), s.timestamp(0),
                s.timestamp(s.size() - 1));
  out << line;
  if (s.ground_truth()) {
    out << "ground truth: yes (" << s.ground_truth()->size() << " poses in "
        << s.ground_truth_file().string() << ")\n";
  } else {
    out << "ground truth: no (no " << s.ground_truth_file().string() << ")\n";
  }
  const CameraConfig& camera = setup.config.camera;
  if (camera.type == SensorType::monocular) {
    std::snprintf(line, sizeof(line), "config:       %s (camera '%s', monocular, %dx%d",
                  setup.config_file.string().c_str(), camera.name.c_str(), camera.pinhole.width,
                  camera.pinhole.height);
  } else if (camera.type == SensorType::stereo) {
    std::snprintf(line, sizeof(line),
                  "config:       %s (camera '%s', stereo, %dx%d, baseline %.4g m, layout %s",
                  setup.config_file.string().c_str(), camera.name.c_str(), camera.pinhole.width,
                  camera.pinhole.height, camera.baseline, to_string(s.layout()).c_str());
  } else {
    std::snprintf(line, sizeof(line), "config:       %s (camera '%s', %dx%d, depth factor %g",
                  setup.config_file.string().c_str(), camera.name.c_str(), camera.pinhole.width,
                  camera.pinhole.height, camera.depth_factor);
  }
  out << line;
  if (camera.type == SensorType::rgbd && (camera.depth_shift_x != 0 || camera.depth_shift_y != 0))
    out << ", depth registration shift " << camera.depth_shift_x << ", " << camera.depth_shift_y
        << " px";
  out << ")\n";
  return out.str();
}

}  // namespace pspslam
