#include "pspslam/io/sequence_setup.h"

#include <cstdio>
#include <sstream>

#include "pspslam/core/error.h"

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

namespace {

// The camera of a rectified stereo layout, from its calibration: pinhole of the rectified left
// image, no distortion (the frames are rectified, by the dataset or as they load), the baseline.
void set_rectified_stereo_camera(CameraConfig& camera, cv::Size size, double fx, double fy,
                                 double cx, double cy, double baseline) {
  camera.type = SensorType::stereo;
  camera.pinhole.width = size.width;
  camera.pinhole.height = size.height;
  camera.pinhole.fx = fx;
  camera.pinhole.fy = fy;
  camera.pinhole.cx = cx;
  camera.pinhole.cy = cy;
  camera.pinhole.distortion = {};
  camera.baseline = baseline;
}

SequenceSetup open_kitti_with_config(const std::filesystem::path& dir,
                                     const std::optional<std::filesystem::path>& config_file,
                                     std::ostream* warnings) {
  SystemConfig config;
  std::filesystem::path config_path = dir / "calib.txt";
  if (config_file) {
    config = load_config(*config_file);
    config_path = *config_file;
  }
  const KittiCalibration calibration = read_kitti_calibration(dir / "calib.txt");
  SequenceOptions options;
  options.warnings = warnings;
  RgbdSequence sequence = RgbdSequence::open_kitti(dir, options);
  const InputFrame first = sequence.load(0);
  CameraConfig& camera = config.camera;
  if (!config_file) camera.name = "kitti";
  set_rectified_stereo_camera(camera, first.bgr.size(), calibration.fx, calibration.fy,
                              calibration.cx, calibration.cy, calibration.baseline);
  if (!config_file || camera.depth_threshold <= 0.0)
    camera.depth_threshold = 40.0 * camera.baseline;
  if (!config_file && sequence.size() > 1) {
    camera.fps = static_cast<double>(sequence.size() - 1) /
                 (sequence.timestamp(sequence.size() - 1) - sequence.timestamp(0));
  }
  return SequenceSetup{config_path, config, std::move(sequence)};
}

SequenceSetup open_euroc_with_config(const std::filesystem::path& dir,
                                     const std::optional<std::filesystem::path>& config_file,
                                     std::ostream* warnings) {
  SystemConfig config;
  std::filesystem::path config_path = dir / "mav0" / "cam0" / "sensor.yaml";
  if (config_file) {
    config = load_config(*config_file);
    config_path = *config_file;
  }
  SequenceOptions options;
  options.warnings = warnings;
  RgbdSequence sequence = RgbdSequence::open_euroc(dir, options);
  const StereoRectification& rect = *sequence.rectification();
  const EurocCamera left = read_euroc_camera(sequence.directory() / "cam0" / "sensor.yaml");
  CameraConfig& camera = config.camera;
  if (!config_file) camera.name = "euroc";
  set_rectified_stereo_camera(camera, rect.size, rect.fx, rect.fy, rect.cx, rect.cy, rect.baseline);
  if (!config_file) {
    camera.depth_threshold = 40.0 * camera.baseline;
    camera.fps = left.rate_hz;
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
  if (std::filesystem::exists(dir / "times.txt") && std::filesystem::exists(dir / "calib.txt")) {
    if (sensor && *sensor != SensorType::stereo) {
      throw Error("--sensor " + to_string(*sensor) + ": " + dir.string() +
                  " is a KITTI odometry sequence (stereo)");
    }
    return open_kitti_with_config(dir, config_file, warnings);
  }
  if (std::filesystem::exists(dir / "mav0" / "cam0" / "data.csv") ||
      (std::filesystem::exists(dir / "cam0" / "data.csv") &&
       std::filesystem::exists(dir / "cam1" / "data.csv"))) {
    if (sensor && *sensor != SensorType::stereo) {
      throw Error("--sensor " + to_string(*sensor) + ": " + dir.string() +
                  " is a EuRoC MAV sequence (stereo)");
    }
    return open_euroc_with_config(dir, config_file, warnings);
  }
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
  options.stereo = config.camera.type == SensorType::stereo;
  options.colour_only = config.camera.type == SensorType::monocular;
  options.depth_factor = config.camera.depth_factor;
  options.depth_shift_x = config.camera.depth_shift_x;
  options.depth_shift_y = config.camera.depth_shift_y;
  options.warnings = warnings;
  return SequenceSetup{config_path, config, RgbdSequence::open(dir, options)};
}

std::string describe_sequence(const SequenceSetup& setup) {
  const RgbdSequence& s = setup.sequence;
  std::ostringstream out;
  char line[512];
  out << "sequence:     " << s.directory().string() << "\n";
  char how[64];
  if (s.layout() != SequenceLayout::tum) {
    std::snprintf(how, sizeof(how), "paired as the %s layout lists them",
                  to_string(s.layout()).c_str());
  } else if (s.used_associations_file()) {
    std::snprintf(how, sizeof(how), "in associations.txt");
  } else {
    std::snprintf(how, sizeof(how), "associated within %g s", s.options().max_difference);
  }
  if (!s.options().colour_only) {
    std::snprintf(line, sizeof(line),
                  "frames:       %zu (%zu colour and %zu %s files listed, %s; %zu listed files "
                  "missing, %zu frames skipped)\n",
                  s.size(), s.listed_rgb(), s.listed_depth(), s.stereo() ? "right" : "depth", how,
                  s.missing_files(), s.skipped_frames());
  } else {
    std::snprintf(line, sizeof(line),
                  "frames:       %zu (%zu colour files listed in rgb.txt, colour only; %zu listed "
                  "files missing, %zu frames skipped)\n",
                  s.size(), s.listed_rgb(), s.missing_files(), s.skipped_frames());
  }
  out << line;
  std::snprintf(line, sizeof(line), "time span:    %.3f s (%.5f .. %.5f)\n",
                s.timestamp(s.size() - 1) - s.timestamp(0), s.timestamp(0),
                s.timestamp(s.size() - 1));
  out << line;
  if (s.ground_truth()) {
    out << "ground truth: yes (" << s.ground_truth()->size() << " poses in groundtruth.txt)\n";
  } else {
    out << "ground truth: no (no groundtruth.txt)\n";
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
