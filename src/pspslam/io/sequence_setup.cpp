#include "pspslam/io/sequence_setup.h"

#include <cstdio>
#include <sstream>

#include "pspslam/core/error.h"

namespace pspslam {

SequenceSetup open_sequence_with_config(const std::filesystem::path& dir,
                                        const std::optional<std::filesystem::path>& config_file,
                                        std::ostream* warnings) {
  if (!std::filesystem::is_directory(dir)) {
    throw Error(dir.string() + ": sequence directory not found");
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
  SequenceOptions options;
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
  if (s.used_associations_file()) {
    std::snprintf(how, sizeof(how), "in associations.txt");
  } else {
    std::snprintf(how, sizeof(how), "associated within %g s", s.options().max_difference);
  }
  std::snprintf(line, sizeof(line),
                "frames:       %zu (%zu colour and %zu depth files listed, %s; %zu listed files "
                "missing, %zu frames skipped)\n",
                s.size(), s.listed_rgb(), s.listed_depth(), how, s.missing_files(),
                s.skipped_frames());
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
  std::snprintf(line, sizeof(line), "config:       %s (camera '%s', %dx%d, depth factor %g",
                setup.config_file.string().c_str(), camera.name.c_str(), camera.pinhole.width,
                camera.pinhole.height, camera.depth_factor);
  out << line;
  if (camera.depth_shift_x != 0 || camera.depth_shift_y != 0)
    out << ", depth registration shift " << camera.depth_shift_x << ", " << camera.depth_shift_y
        << " px";
  out << ")\n";
  return out.str();
}

}  // namespace pspslam
