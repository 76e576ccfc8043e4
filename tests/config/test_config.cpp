#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include "pspslam/config/config.h"
#include "pspslam/core/error.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/feature/orb_config.h"
#include "pspslam/geometry/geometry_config.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

constexpr const char* kValidCamera =
    "camera:\n"
    "  name: test\n"
    "  width: 640\n"
    "  height: 480\n"
    "  fx: 500.5\n"
    "  fy: 501.25\n"
    "  cx: 319.5\n"
    "  cy: 239.5\n"
    "  distortion: [0.1, -0.2, 0.001, 0.002]\n"
    "  fps: 30\n"
    "  depth_factor: 5000\n"
    "  depth_threshold: 4.0\n";

std::filesystem::path write_file(const std::filesystem::path& dir, const std::string& text) {
  const std::filesystem::path file = dir / "config.yaml";
  std::ofstream(file) << text;
  return file;
}

// The error of loading `file` and reading every module's section, as a System does.
std::string load_error(const std::filesystem::path& file) {
  try {
    const SystemConfig config = load_config(file);
    read_orb_config(config.orb);
    read_geometry_config(config.geometry);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(Config, SaveLoadRoundTrip) {
  const auto dir = testing::make_temp_dir("config");
  SystemConfig config;
  config.camera.name = "round trip";
  config.camera.pinhole.width = 320;
  config.camera.pinhole.height = 240;
  config.camera.pinhole.fx = 271.123456789012;
  config.camera.pinhole.fy = 272.5;
  config.camera.pinhole.cx = 159.75;
  config.camera.pinhole.cy = 119.25;
  config.camera.pinhole.distortion = {0.01, -0.02, 0.003, -0.004, 0.005};
  config.camera.fps = 15.0;
  config.camera.depth_factor = 1000.0;
  config.camera.depth_threshold = 3.5;
  config.camera.depth_noise = CameraConfig::DepthNoise::kinect_v1;
  config.camera.depth_noise_scale = 1.5;
  config.camera.depth_shift_x = -2;
  config.camera.depth_shift_y = 1;
  config.camera.rolling_shutter_readout_s = -0.0275;  // 15 fps: within 1/fps, bottom row first
  config.orb = parse_config(std::string(kValidCamera) +
                                "orb:\n  n_features: 1500\n  scale_factor: 1.3\n  n_levels: 6\n"
                                "  initial_fast_threshold: 25\n  min_fast_threshold: 9\n"
                                "  mask_compensation: true\n",
                            "orb.yaml")
                   .orb;
  save_config(dir / "saved.yaml", config);
  const SystemConfig loaded = load_config(dir / "saved.yaml");
  EXPECT_EQ(loaded.camera.name, config.camera.name);
  EXPECT_EQ(loaded.camera.pinhole.width, 320);
  EXPECT_EQ(loaded.camera.pinhole.height, 240);
  EXPECT_EQ(loaded.camera.pinhole.fx, config.camera.pinhole.fx);
  EXPECT_EQ(loaded.camera.pinhole.fy, config.camera.pinhole.fy);
  EXPECT_EQ(loaded.camera.pinhole.cx, config.camera.pinhole.cx);
  EXPECT_EQ(loaded.camera.pinhole.cy, config.camera.pinhole.cy);
  EXPECT_EQ(loaded.camera.pinhole.distortion, config.camera.pinhole.distortion);
  EXPECT_EQ(loaded.camera.fps, 15.0);
  EXPECT_EQ(loaded.camera.depth_factor, 1000.0);
  EXPECT_EQ(loaded.camera.depth_threshold, 3.5);
  EXPECT_EQ(loaded.camera.depth_noise, CameraConfig::DepthNoise::kinect_v1);
  EXPECT_EQ(loaded.camera.depth_noise_scale, 1.5);
  EXPECT_EQ(loaded.camera.depth_shift_x, -2);
  EXPECT_EQ(loaded.camera.depth_shift_y, 1);
  EXPECT_EQ(loaded.camera.rolling_shutter_readout_s, -0.0275);
  const OrbConfig orb = read_orb_config(loaded.orb);
  EXPECT_EQ(orb.n_features, 1500);
  EXPECT_EQ(orb.scale_factor, 1.3);
  EXPECT_EQ(orb.n_levels, 6);
  EXPECT_EQ(orb.initial_fast_threshold, 25);
  EXPECT_EQ(orb.min_fast_threshold, 9);
  EXPECT_TRUE(orb.mask_compensation);
  // A module section that was not given is not written: its keys keep their defaults.
  config.orb = {};
  save_config(dir / "saved_off.yaml", config);
  std::ifstream saved(dir / "saved_off.yaml");
  const std::string text((std::istreambuf_iterator<char>(saved)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find("orb"), std::string::npos) << text;
  EXPECT_FALSE(read_orb_config(load_config(dir / "saved_off.yaml").orb).mask_compensation);
  // A global shutter (0, the default) is not written either.
  config.camera.rolling_shutter_readout_s = 0.0;
  save_config(dir / "saved_global.yaml", config);
  std::ifstream global(dir / "saved_global.yaml");
  const std::string global_text((std::istreambuf_iterator<char>(global)),
                                std::istreambuf_iterator<char>());
  EXPECT_EQ(global_text.find("rolling_shutter"), std::string::npos) << global_text;
}

TEST(Config, AllPresetsLoad) {
  const std::filesystem::path presets = source_dir() / "config";
  const SystemConfig bonn = load_config(presets / "bonn.yaml");
  EXPECT_EQ(bonn.camera.name, "bonn");
  EXPECT_DOUBLE_EQ(bonn.camera.pinhole.fx, 542.822841);
  EXPECT_DOUBLE_EQ(bonn.camera.rolling_shutter_readout_s, 0.03);
  EXPECT_DOUBLE_EQ(bonn.camera.pinhole.cy, 237.756098);
  EXPECT_DOUBLE_EQ(bonn.camera.pinhole.distortion[0], 0.039903);
  EXPECT_DOUBLE_EQ(bonn.camera.depth_factor, 5000.0);
  EXPECT_EQ(bonn.camera.depth_noise, CameraConfig::DepthNoise::kinect_v1);
  EXPECT_DOUBLE_EQ(bonn.camera.depth_noise_scale, 16.0);
  struct Expected {
    const char* file;
    const char* name;
    double fx;
    double depth_factor;  // fr2 uses ORB-SLAM2's 5208 (the TUM fr2 depth scale correction)
  };
  for (const Expected& e : {Expected{"tum_fr1.yaml", "tum_fr1", 517.306408, 5000.0},
                            Expected{"tum_fr2.yaml", "tum_fr2", 520.908620, 5208.0},
                            Expected{"tum_fr3.yaml", "tum_fr3", 535.4, 5000.0}}) {
    const SystemConfig config = load_config(presets / e.file);
    EXPECT_EQ(config.camera.name, e.name);
    EXPECT_EQ(config.camera.pinhole.width, 640) << e.file;
    EXPECT_EQ(config.camera.pinhole.height, 480) << e.file;
    EXPECT_DOUBLE_EQ(config.camera.pinhole.fx, e.fx) << e.file;
    EXPECT_DOUBLE_EQ(config.camera.depth_factor, e.depth_factor) << e.file;
  }
}

TEST(Config, ValidMinimalConfigTakesOrbDefaults) {
  const auto dir = testing::make_temp_dir("config");
  const SystemConfig config = load_config(write_file(dir, kValidCamera));
  EXPECT_EQ(config.camera.name, "test");
  EXPECT_EQ(config.camera.pinhole.fy, 501.25);
  EXPECT_EQ(config.camera.pinhole.distortion[4], 0.0);
  EXPECT_EQ(read_orb_config(config.orb).n_features, 1000);
  EXPECT_FALSE(read_orb_config(config.orb).mask_compensation);
  // Without the key, depth is weighed as ORB-SLAM2 does (virtual right coordinate).
  EXPECT_EQ(config.camera.depth_noise, CameraConfig::DepthNoise::none);
}

// Stereo: type, baseline or bf, the depth-image keys refused, monocular "not yet".
constexpr const char* kStereoCamera =
    "camera:\n"
    "  name: pair\n"
    "  type: stereo\n"
    "  width: 640\n"
    "  height: 480\n"
    "  fx: 500\n"
    "  fy: 500\n"
    "  cx: 319.5\n"
    "  cy: 239.5\n"
    "  distortion: [0, 0, 0, 0]\n"
    "  fps: 20\n"
    "  baseline: 0.12\n";

TEST(Config, StereoCameraReadsBaselineOrBfAndRoundTrips) {
  const auto dir = testing::make_temp_dir("config_stereo");
  const SystemConfig config = load_config(write_file(dir, kStereoCamera));
  EXPECT_EQ(config.camera.type, SensorType::stereo);
  EXPECT_DOUBLE_EQ(config.camera.baseline, 0.12);
  EXPECT_DOUBLE_EQ(config.camera.depth_threshold, 40 * 0.12);  // 40 baselines by default
  const SystemConfig from_bf =
      load_config(write_file(dir, replace(kStereoCamera, "  baseline: 0.12\n", "  bf: 60\n")));
  EXPECT_DOUBLE_EQ(from_bf.camera.baseline, 0.12);
  save_config(dir / "saved.yaml", config);
  const SystemConfig back = load_config(dir / "saved.yaml");
  EXPECT_EQ(back.camera.type, SensorType::stereo);
  EXPECT_DOUBLE_EQ(back.camera.baseline, 0.12);
  EXPECT_DOUBLE_EQ(back.camera.depth_threshold, config.camera.depth_threshold);
  // An rgbd config says nothing about the type and reads as before.
  EXPECT_EQ(load_config(write_file(dir, kValidCamera)).camera.type, SensorType::rgbd);
}

TEST(Config, StereoErrorsNameFileLineAndKey) {
  const auto dir = testing::make_temp_dir("config_stereo_errors");
  auto file = write_file(dir, replace(kStereoCamera, "  type: stereo\n", "  type: lidar\n"));
  EXPECT_EQ(load_error(file), file.string() +
                                  ":3: key 'camera.type': must be rgbd, stereo or monocular, got "
                                  "'lidar'");
  file = write_file(dir, replace(kStereoCamera, "  baseline: 0.12\n", ""));
  EXPECT_EQ(load_error(file), file.string() +
                                  ": a stereo camera needs exactly one of 'camera.baseline' "
                                  "(metres) and 'camera.bf' (fx * baseline), got neither");
  file =
      write_file(dir, replace(kStereoCamera, "  baseline: 0.12\n", "  baseline: 0.12\n  bf: 60\n"));
  EXPECT_EQ(load_error(file), file.string() +
                                  ": a stereo camera needs exactly one of 'camera.baseline' "
                                  "(metres) and 'camera.bf' (fx * baseline), got both");
  file = write_file(dir, replace(kStereoCamera, "  baseline: 0.12\n", "  baseline: -0.1\n"));
  EXPECT_EQ(load_error(file), file.string() + ": key 'camera.baseline' must be > 0");
  file =
      write_file(dir, replace(kStereoCamera, "  fps: 20\n", "  fps: 20\n  depth_factor: 5000\n"));
  EXPECT_EQ(load_error(file), file.string() +
                                  ":12: key 'camera.depth_factor' is for rgbd cameras only "
                                  "(camera.type is stereo)");
  file = write_file(
      dir, replace(kStereoCamera, "  baseline: 0.12\n", "  baseline: 0.12\n  basline: 1\n"));
  EXPECT_EQ(load_error(file), file.string() +
                                  ":13: unknown key 'camera.basline' (did you mean "
                                  "'camera.baseline'?)");
}

// Monocular: intrinsics and fps only; depth and baseline keys are named as another sensor's.
TEST(Config, MonocularCameraRoundTripsAndRefusesDepthAndBaselineKeys) {
  const auto dir = testing::make_temp_dir("config_monocular");
  const std::string monocular = replace(
      replace(kStereoCamera, "  type: stereo\n", "  type: monocular\n"), "  baseline: 0.12\n", "");
  const SystemConfig config = load_config(write_file(dir, monocular));
  EXPECT_EQ(config.camera.type, SensorType::monocular);
  EXPECT_EQ(to_string(config.camera.type), "monocular");
  save_config(dir / "saved.yaml", config);
  const SystemConfig back = load_config(dir / "saved.yaml");
  EXPECT_EQ(back.camera.type, SensorType::monocular);
  EXPECT_DOUBLE_EQ(back.camera.pinhole.fx, 500.0);
  auto file =
      write_file(dir, replace(monocular, "  fps: 20\n", "  fps: 20\n  depth_factor: 5000\n"));
  EXPECT_EQ(load_error(file), file.string() +
                                  ":12: key 'camera.depth_factor' is for rgbd cameras only "
                                  "(camera.type is monocular)");
  file = write_file(dir, replace(monocular, "  fps: 20\n", "  fps: 20\n  baseline: 0.1\n"));
  EXPECT_EQ(load_error(file), file.string() +
                                  ":12: key 'camera.baseline' has no meaning for a monocular "
                                  "camera (camera.type is monocular)");
}

// The geometry stage's parameters (paper III.B/C) come from the config's `geometry:` section.
TEST(Config, GeometrySectionSetsTheStageAndRoundTrips) {
  const auto dir = testing::make_temp_dir("config");
  const SystemConfig config = load_config(
      write_file(dir, std::string(kValidCamera) +
                          "geometry:\n  region:\n    max_grow_radius_m: 1.25\n  search:\n"
                          "    band_width_px: 60\n  multiview:\n    disagreement: either_sign\n"));
  GeometryParams expected;
  expected.region.max_grow_radius_m = 1.25f;
  expected.search.band_width_px = 60.0f;
  expected.multiview.disagreement = DepthDisagreement::either_sign;
  EXPECT_TRUE(read_geometry_config(config.geometry) == expected);
  EXPECT_TRUE(read_geometry_config(load_config(write_file(dir, kValidCamera)).geometry) ==
              GeometryParams{});

  // Saved as read, so the stage reads back the same parameters.
  save_config(dir / "saved.yaml", config);
  EXPECT_TRUE(read_geometry_config(load_config(dir / "saved.yaml").geometry) == expected);
  // A config without the section writes none, so it loads in builds without the section.
  SystemConfig plain = config;
  plain.geometry = {};
  save_config(dir / "plain.yaml", plain);
  std::ifstream saved(dir / "plain.yaml");
  const std::string text((std::istreambuf_iterator<char>(saved)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find("geometry"), std::string::npos) << text;
}

TEST(Config, GeometryErrorsNameFileLineAndKey) {
  const auto dir = testing::make_temp_dir("config");
  const auto strategy = write_file(
      dir, std::string(kValidCamera) + "geometry:\n  search:\n    strategy: exhaustive\n");
  EXPECT_EQ(load_error(strategy),
            strategy.string() +
                ":15: key 'geometry.search.strategy' is not a config key: pspslam run --dynamic "
                "chooses the search (full: ant_colony, exhaustive: every point)");
  const auto warped = write_file(
      dir, std::string(kValidCamera) + "geometry:\n  output_warped_previous_mask: true\n");
  EXPECT_EQ(load_error(warped), warped.string() +
                                    ":14: key 'geometry.output_warped_previous_mask' is not a "
                                    "config key: a run does not use the warped mask");
  const auto band =
      write_file(dir, std::string(kValidCamera) + "geometry:\n  search:\n    band_width_px: 0\n");
  EXPECT_EQ(load_error(band),
            band.string() + ":15: key 'geometry.search.band_width_px' must be > 0");
  const auto typo =
      write_file(dir, std::string(kValidCamera) + "geometry:\n  region:\n    max_grow_radius: 1\n");
  EXPECT_EQ(load_error(typo), typo.string() +
                                  ":15: unknown key 'geometry.region.max_grow_radius' (did you "
                                  "mean 'geometry.region.max_grow_radius_m'?)");
  const auto scalar = write_file(dir, std::string(kValidCamera) + "geometry:\n  region: 5\n");
  EXPECT_EQ(load_error(scalar),
            scalar.string() + ":14: 'geometry.region' must be a mapping of key: value");
  const auto section = write_file(dir, std::string(kValidCamera) + "geometry:\n  regions: {}\n");
  EXPECT_EQ(load_error(section), section.string() +
                                     ":14: unknown key 'geometry.regions' (did you mean "
                                     "'geometry.region'?)");
}

TEST(Config, UnknownKeyNamesFileLineAndKey) {
  const auto dir = testing::make_temp_dir("config");
  const auto file = write_file(dir, replace(kValidCamera, "  fx: 500.5\n", "  fxx: 500.5\n"));
  // The required fx is absent because it was mistyped: the typo is named, with the key meant.
  EXPECT_EQ(load_error(file),
            file.string() + ":5: unknown key 'camera.fxx' (did you mean 'camera.fx'?)");
  const auto missing = write_file(dir, replace(kValidCamera, "  fx: 500.5\n", ""));
  EXPECT_EQ(load_error(missing), missing.string() + ": missing key 'camera.fx'");
  const auto extra = write_file(dir, std::string(kValidCamera) + "  colour: blue\n");
  EXPECT_EQ(load_error(extra), extra.string() + ":13: unknown key 'camera.colour'");
  const auto top = write_file(dir, std::string(kValidCamera) + "tracking:\n  x: 1\n");
  EXPECT_EQ(load_error(top), top.string() + ":13: unknown key 'tracking'");
}

// Found by fuzz/fuzz_segmenter_metadata: a non-scalar key ("? [a, b]") made yaml-cpp throw
// its own exception (exit 3) instead of a message naming the file and line.
TEST(Config, ComplexKeyNamesFileAndLine) {
  const auto dir = testing::make_temp_dir("config");
  const auto file = write_file(dir, std::string(kValidCamera) + "  ? [a, b]\n  : 1\n");
  EXPECT_EQ(load_error(file).substr(0, file.string().size() + 1), file.string() + ":");
  EXPECT_NE(load_error(file).find(": a key must be a plain name (in 'camera')"), std::string::npos)
      << load_error(file);
}

TEST(Config, MissingKeys) {
  const auto dir = testing::make_temp_dir("config");
  const auto no_fps = write_file(dir, replace(kValidCamera, "  fps: 30\n", ""));
  EXPECT_EQ(load_error(no_fps), no_fps.string() + ": missing key 'camera.fps'");
  const auto no_camera = write_file(dir, "orb:\n  n_features: 10\n");
  EXPECT_EQ(load_error(no_camera), no_camera.string() + ": missing key 'camera'");
  EXPECT_EQ(load_error(dir / "absent.yaml"),
            (dir / "absent.yaml").string() + ": config file not found");
}

TEST(Config, InvalidValues) {
  const auto dir = testing::make_temp_dir("config");
  const auto text_fx = write_file(dir, replace(kValidCamera, "  fx: 500.5\n", "  fx: wide\n"));
  EXPECT_EQ(load_error(text_fx), text_fx.string() + ":5: key 'camera.fx' has an invalid value");
  const auto negative =
      write_file(dir, replace(kValidCamera, "  depth_factor: 5000\n", "  depth_factor: -1\n"));
  EXPECT_EQ(load_error(negative), negative.string() + ": key 'camera.depth_factor' must be > 0");
  const auto distortion =
      write_file(dir, replace(kValidCamera, "[0.1, -0.2, 0.001, 0.002]", "[0.1, -0.2]"));
  EXPECT_EQ(load_error(distortion),
            distortion.string() +
                ": key 'camera.distortion' must list 4 or 5 values (k1 k2 p1 p2 [k3]), got 2");
  const auto scale = write_file(dir, std::string(kValidCamera) + "orb:\n  scale_factor: 1.0\n");
  EXPECT_EQ(load_error(scale), scale.string() + ":14: key 'orb.scale_factor' must be > 1");
  const auto noise = write_file(dir, std::string(kValidCamera) + "  depth_noise: kinect\n");
  EXPECT_EQ(load_error(noise),
            noise.string() + ": key 'camera.depth_noise' must be none or kinect_v1, got 'kinect'");
  const auto noise_scale = write_file(dir, std::string(kValidCamera) + "  depth_noise_scale: 0\n");
  EXPECT_EQ(load_error(noise_scale),
            noise_scale.string() + ": key 'camera.depth_noise_scale' must be > 0");
  for (const std::string shift : {"[1]", "[0, 17]", "[1, 2, 3]"}) {
    const auto file = write_file(
        dir, std::string(kValidCamera) + "  depth_registration_shift_px: " + shift + "\n");
    EXPECT_EQ(load_error(file), file.string() +
                                    ": key 'camera.depth_registration_shift_px' must be two whole "
                                    "pixel offsets [dx, dy], each within +-16")
        << shift;
  }
  const auto fractional =
      write_file(dir, std::string(kValidCamera) + "  depth_registration_shift_px: [0, 1.5]\n");
  EXPECT_EQ(
      load_error(fractional),
      fractional.string() + ":13: key 'camera.depth_registration_shift_px' has an invalid value");
  // 13: the line of the appended key.
  const auto readout =
      write_file(dir, std::string(kValidCamera) + "  rolling_shutter_readout: 0.05\n");
  EXPECT_EQ(
      load_error(readout),
      readout.string() +
          ":13: key 'camera.rolling_shutter_readout' must be seconds within +-1/fps (a sensor "
          "reads its rows within one frame; negative: bottom row first), got 0.050000");
  const auto broken = write_file(dir, "camera: [1, 2\n");
  EXPECT_EQ(load_error(broken).rfind(broken.string() + ":2: invalid YAML: ", 0), 0u)
      << load_error(broken);
}

}  // namespace
}  // namespace pspslam
