#include <chrono>
#include <iostream>
#include <string>
#include <vector>

#include "commands.h"
#include "pspslam/core/arg_parser.h"
#include "pspslam/core/error.h"
#include "pspslam/core/progress.h"
#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"

namespace pspslam::cli {
namespace {

bool parse_on_off(const ArgParser& parser, const std::string& flag) {
  const std::string value = parser.get(flag);
  if (value == "on") return true;
  if (value == "off") return false;
  throw Error("synth: flag --" + flag + " expects 'on' or 'off', got '" + value + "'");
}

}  // namespace

int synth_command(const std::vector<std::string>& args) {
  ArgParser parser("pspslam synth",
                   "Render a synthetic dynamic RGB-D sequence in TUM layout: rgb/, depth/ "
                   "(16-bit, 5000 per metre), mask/ (0 static, 15 person, 100 carried object), "
                   "groundtruth.txt and config.yaml, ready for 'pspslam run --sequence DIR'.");
  parser.add_option("out", "output directory (created when missing)", "", true);
  parser.add_option("frames", "number of frames at 30 Hz", "300");
  parser.add_option("bodies", "people walking around the room (0 = static twin)", "3");
  parser.add_option("seed", "random seed: same seed, same bytes", "1");
  parser.add_option("trajectory", "camera motion: handheld | loop", "handheld");
  parser.add_option("loop-turns",
                    "turns of the loop trajectory (1.08 revisits the start briefly; 1.5 gives "
                    "half a turn of revisit, enough for covisibility-consistent loop detection)",
                    "1.08");
  parser.add_option("depth-noise", "on | off: Kinect-like noise and holes (off = exact depth)",
                    "on");
  parser.add_option("carried-objects", "people carrying a box (label 100)", "1");
  parser.add_option("threads", "worker threads (0 = all cores)", "0");
  if (!parser.parse(args)) return 0;

  SynthOptions options;
  const int frames = parser.get_int("frames");
  if (frames < 1) throw Error("synth: flag --frames must be >= 1, got " + parser.get("frames"));
  options.frames = static_cast<size_t>(frames);
  options.bodies = parser.get_int("bodies");
  const int seed = parser.get_int("seed");
  if (seed < 0) throw Error("synth: flag --seed must be >= 0, got " + parser.get("seed"));
  options.seed = static_cast<uint64_t>(seed);
  options.trajectory = parse_synth_trajectory(parser.get("trajectory"));
  options.depth_noise = parse_on_off(parser, "depth-noise");
  try {
    options.loop_turns = std::stod(parser.get("loop-turns"));
  } catch (const std::exception&) {
    throw Error("synth: flag --loop-turns expects a number, got '" + parser.get("loop-turns") +
                "'");
  }
  options.carried_objects = parser.get_int("carried-objects");
  options.threads = parser.get_int("threads");
  options.validate();

  const std::string out = parser.get("out");
  const auto start = std::chrono::steady_clock::now();
  const SyntheticScene scene(options);
  ProgressBar progress("synth", options.frames, std::cerr);
  write_sequence(scene, out, [&](size_t done) { progress.update(done); });
  progress.finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "wrote " << options.frames << " frames (" << options.bodies << " bodies, "
            << to_string(options.trajectory) << ", seed " << options.seed << ") to " << out
            << " in " << seconds << " s\n";
  return 0;
}

}  // namespace pspslam::cli
