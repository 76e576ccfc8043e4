#include "pspslam/config/config.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <vector>

#include "pspslam/core/error.h"
#include "pspslam/core/yaml_section.h"

namespace pspslam {
namespace {

void require_positive(double value, const YamlSection& section, const std::string& key) {
  if (!(value > 0.0)) {
    throw Error(section.file() + ": key '" + section.qualified(key) + "' must be > 0");
  }
}

// The keys that describe a depth image make no sense for a stereo pair or a single colour
// camera: name them rather than call them unknown (they are valid keys, for another sensor).
void refuse_depth_image_keys(const YamlSection& section, SensorType type) {
  for (const char* key :
       {"depth_factor", "depth_noise", "depth_noise_scale", "depth_registration_shift_px"}) {
    if (section.contains(key)) {
      throw section.invalid(key,
                            "is for rgbd cameras only (camera.type is " + to_string(type) + ")");
    }
  }
}

void read_stereo_baseline(YamlSection& section, CameraConfig& camera) {
  const bool has_baseline = section.contains("baseline");
  const bool has_bf = section.contains("bf");
  if (has_baseline == has_bf) {
    throw Error(section.file() + ": a stereo camera needs exactly one of '" +
                section.qualified("baseline") + "' (metres) and '" + section.qualified("bf") +
                "' (fx * baseline)" + (has_bf ? ", got both" : ", got neither"));
  }
  if (has_baseline) {
    camera.baseline = section.required<double>("baseline");
    require_positive(camera.baseline, section, "baseline");
  } else {
    const double bf = section.required<double>("bf");
    require_positive(bf, section, "bf");
    camera.baseline = bf / camera.pinhole.fx;
  }
}

CameraConfig read_camera(YamlSection section) {
  CameraConfig camera;
  camera.name = section.optional<std::string>("name", camera.name);
  if (section.contains("type")) {
    camera.type =
        parse_sensor_type(section.required<std::string>("type"),
                          section.where("type") + "key '" + section.qualified("type") + "'");
  }
  PinholeCamera& p = camera.pinhole;
  p.width = section.required<int>("width");
  p.height = section.required<int>("height");
  p.fx = section.required<double>("fx");
  p.fy = section.required<double>("fy");
  p.cx = section.required<double>("cx");
  p.cy = section.required<double>("cy");
  const auto distortion = section.required<std::vector<double>>("distortion");
  if (distortion.size() != 4 && distortion.size() != 5) {
    throw Error(section.file() + ": key '" + section.qualified("distortion") +
                "' must list 4 or 5 values (k1 k2 p1 p2 [k3]), got " +
                std::to_string(distortion.size()));
  }
  for (size_t i = 0; i < distortion.size(); ++i) p.distortion[i] = distortion[i];
  camera.fps = section.required<double>("fps");
  require_positive(p.width, section, "width");
  require_positive(p.height, section, "height");
  require_positive(p.fx, section, "fx");
  require_positive(p.fy, section, "fy");
  require_positive(camera.fps, section, "fps");
  camera.rolling_shutter_readout_s = section.optional("rolling_shutter_readout", 0.0);
  if (!(std::abs(camera.rolling_shutter_readout_s) <= 1.0 / camera.fps)) {
    throw section.invalid("rolling_shutter_readout",
                          "must be seconds within +-1/fps (a sensor reads its rows within one "
                          "frame; negative: bottom row first), got " +
                              std::to_string(camera.rolling_shutter_readout_s));
  }
  if (camera.type == SensorType::monocular) {
    // No depth at all: nothing is "close" or "far" (depth_threshold is not read).
    refuse_depth_image_keys(section, camera.type);
    for (const char* key : {"baseline", "bf", "depth_threshold"}) {
      if (section.contains(key)) {
        throw section.invalid(key,
                              "has no meaning for a monocular camera (camera.type is monocular)");
      }
    }
    section.finish();
    return camera;
  }
  if (camera.type == SensorType::stereo) {
    refuse_depth_image_keys(section, camera.type);
    read_stereo_baseline(section, camera);
    camera.depth_threshold = section.optional("depth_threshold", 40.0 * camera.baseline);
    require_positive(camera.depth_threshold, section, "depth_threshold");
    section.finish();
    return camera;
  }
  camera.depth_factor = section.required<double>("depth_factor");
  camera.depth_threshold = section.required<double>("depth_threshold");
  const auto depth_noise = section.optional<std::string>("depth_noise", "none");
  if (depth_noise == "kinect_v1") {
    camera.depth_noise = CameraConfig::DepthNoise::kinect_v1;
  } else if (depth_noise != "none") {
    throw Error(section.file() + ": key '" + section.qualified("depth_noise") +
                "' must be none or kinect_v1, got '" + depth_noise + "'");
  }
  camera.depth_noise_scale = section.optional("depth_noise_scale", camera.depth_noise_scale);
  const auto shift = section.optional<std::vector<int>>("depth_registration_shift_px", {0, 0});
  constexpr int kMaxDepthShift = 16;
  if (shift.size() != 2 || std::abs(shift[0]) > kMaxDepthShift ||
      std::abs(shift[1]) > kMaxDepthShift) {
    throw Error(section.file() + ": key '" + section.qualified("depth_registration_shift_px") +
                "' must be two whole pixel offsets [dx, dy], each within +-" +
                std::to_string(kMaxDepthShift));
  }
  camera.depth_shift_x = shift[0];
  camera.depth_shift_y = shift[1];
  require_positive(camera.depth_factor, section, "depth_factor");
  require_positive(camera.depth_threshold, section, "depth_threshold");
  require_positive(camera.depth_noise_scale, section, "depth_noise_scale");
  section.finish();
  return camera;
}

}  // namespace

ConfigSection::ConfigSection(const YAML::Node& node, std::string document, std::string key)
    : node_(std::make_shared<const YAML::Node>(node)),
      document_(std::move(document)),
      key_(std::move(key)) {}

YamlSection ConfigSection::reader() const {
  return YamlSection(node_ ? *node_ : YAML::Node(), document_, key_);
}

SensorType parse_sensor_type(const std::string& name, const std::string& where) {
  if (name == "rgbd") return SensorType::rgbd;
  if (name == "stereo") return SensorType::stereo;
  if (name == "monocular") return SensorType::monocular;
  throw Error(where + ": must be rgbd, stereo or monocular, got '" + name + "'");
}

std::string to_string(SensorType type) {
  switch (type) {
    case SensorType::stereo:
      return "stereo";
    case SensorType::monocular:
      return "monocular";
    case SensorType::rgbd:
      break;
  }
  return "rgbd";
}

namespace {

// A module's section, kept for the module to read: its keys are the module's to check; here it
// must only be a mapping (YamlSection::section refuses anything else, naming the line).
ConfigSection module_section(YamlSection& top, const YAML::Node& root, const std::string& name,
                             const std::string& key) {
  top.section(key);
  const YAML::Node node = root[key];
  return node && node.IsMap() ? ConfigSection(node, name, key) : ConfigSection();
}

SystemConfig read_config(const YAML::Node& root, const std::string& name) {
  YamlSection top(root, name, "");
  if (!top.contains("camera")) throw Error(name + ": missing key 'camera'");
  SystemConfig config;
  config.camera = read_camera(top.section("camera"));
  config.orb = module_section(top, root, name, "orb");
  config.geometry = module_section(top, root, name, "geometry");
  top.finish();
  return config;
}

}  // namespace

SystemConfig load_config(const std::filesystem::path& file) {
  if (!std::filesystem::exists(file)) throw Error(file.string() + ": config file not found");
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
  } catch (const YAML::Exception& e) {
    throw Error(file.string() + ":" + std::to_string(e.mark.line + 1) + ": invalid YAML: " + e.msg);
  }
  return read_config(root, file.string());
}

SystemConfig parse_config(const std::string& yaml, const std::string& name) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw Error(name + ":" + std::to_string(e.mark.line + 1) + ": invalid YAML: " + e.msg);
  }
  return read_config(root, name);
}

void save_config(const std::filesystem::path& file, const SystemConfig& config) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "camera" << YAML::Value << YAML::BeginMap;
  const PinholeCamera& p = config.camera.pinhole;
  out << YAML::Key << "name" << YAML::Value << config.camera.name;
  const bool stereo = config.camera.type == SensorType::stereo;
  const bool monocular = config.camera.type == SensorType::monocular;
  if (config.camera.type != SensorType::rgbd)
    out << YAML::Key << "type" << YAML::Value << to_string(config.camera.type);
  out << YAML::Key << "width" << YAML::Value << p.width;
  out << YAML::Key << "height" << YAML::Value << p.height;
  out << YAML::Key << "fx" << YAML::Value << p.fx;
  out << YAML::Key << "fy" << YAML::Value << p.fy;
  out << YAML::Key << "cx" << YAML::Value << p.cx;
  out << YAML::Key << "cy" << YAML::Value << p.cy;
  out << YAML::Key << "distortion" << YAML::Value << YAML::Flow
      << std::vector<double>(p.distortion.begin(), p.distortion.end());
  out << YAML::Key << "fps" << YAML::Value << config.camera.fps;
  if (config.camera.rolling_shutter_readout_s != 0.0) {
    out << YAML::Key << "rolling_shutter_readout" << YAML::Value
        << config.camera.rolling_shutter_readout_s;
  }
  if (stereo) {
    out << YAML::Key << "baseline" << YAML::Value << config.camera.baseline;
    out << YAML::Key << "depth_threshold" << YAML::Value << config.camera.depth_threshold;
  }
  if (!stereo && !monocular) {
    out << YAML::Key << "depth_factor" << YAML::Value << config.camera.depth_factor;
    out << YAML::Key << "depth_threshold" << YAML::Value << config.camera.depth_threshold;
    out << YAML::Key << "depth_noise" << YAML::Value
        << (config.camera.depth_noise == CameraConfig::DepthNoise::kinect_v1 ? "kinect_v1"
                                                                             : "none");
    out << YAML::Key << "depth_noise_scale" << YAML::Value << config.camera.depth_noise_scale;
  }
  if (!stereo && !monocular &&
      (config.camera.depth_shift_x != 0 || config.camera.depth_shift_y != 0)) {
    out << YAML::Key << "depth_registration_shift_px" << YAML::Value << YAML::Flow
        << std::vector<int>{config.camera.depth_shift_x, config.camera.depth_shift_y};
  }
  out << YAML::EndMap;
  if (!config.orb.empty()) out << YAML::Key << "orb" << YAML::Value << *config.orb.node();
  if (!config.geometry.empty())
    out << YAML::Key << "geometry" << YAML::Value << *config.geometry.node();
  out << YAML::EndMap;
  std::ofstream stream(file);
  if (!stream) throw Error(file.string() + ": cannot write config file");
  stream << out.c_str() << "\n";
}

}  // namespace pspslam
