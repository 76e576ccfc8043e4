#include <gtest/gtest.h>

#include "support/test_support.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"

namespace pspslam {
namespace {

std::string read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string run(const std::string& arguments) {
  std::string output;
  const int status =
      testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " run --quiet " + arguments, &output);
  EXPECT_EQ(status, 0) << output;
  return output;
}

// `--load-map M --localization` on a sequence with people. The geometry stage tests
// points against views rebuilt from the map's keyframes, nothing in the run changes the map (the
// map saved after the run is the loaded file, byte for byte), and the header says loop closing is
// off.
TEST(LocalizationMode, GeometryTestsPointsAndTheLoadedMapStaysBitForBit) {
  const std::filesystem::path dir = testing::make_temp_dir("localization_mode");
  SynthOptions synth;
  synth.frames = 120;
  synth.bodies = 3;
  synth.seed = 1;
  synth.threads = 0;
  write_sequence(synth, dir / "sequence");
  const std::string sequence = " --sequence " + (dir / "sequence").string();
  const std::filesystem::path map = dir / "map.pspmap";
  run(sequence + " --dynamic geometry --out " + (dir / "slam").string() + " --save-map " +
      map.string());
  ASSERT_TRUE(std::filesystem::exists(map));

  // A map keeps its keyframe and point ids through loading, so the localisation run on the SLAM
  // map must save it back byte for byte; so must a second localisation run on that file.
  const auto localise = [&](const std::filesystem::path& in, const std::string& name) {
    return run(sequence + " --dynamic geometry --load-map " + in.string() +
               " --localization --out " + (dir / name).string() + " --save-map " +
               (dir / (name + ".pspmap")).string());
  };
  localise(map, "first");
  const std::string header = localise(dir / "first.pspmap", "second");
  EXPECT_NE(header.find("(localisation only)"), std::string::npos) << header;
  EXPECT_NE(header.find("loop closing: off"), std::string::npos) << header;
  EXPECT_EQ(header.find("loop closing: on"), std::string::npos) << header;

  for (const char* name : {"first", "second"}) {
    const nlohmann::json stats = nlohmann::json::parse(read_bytes(dir / name / "stats.json"));
    EXPECT_EQ(stats["lost_frames"].get<int>(), 0) << name << stats.dump(1);
    // Every frame after the first has a prior and map views: thousands of tests, people found.
    EXPECT_GT(stats["dynamic"]["tested_points"].get<int>(), 3000) << name << stats.dump(1);
    EXPECT_GT(stats["dynamic"]["dynamic_points"].get<int>(), 100) << name << stats.dump(1);
    EXPECT_EQ(stats["dynamic"]["culled_map_points"].get<int>(), 0) << name << stats.dump(1);
  }
  const std::string original = read_bytes(map);
  ASSERT_GT(original.size(), 1000u);
  for (const char* name : {"first.pspmap", "second.pspmap"}) {
    const std::string saved = read_bytes(dir / name);
    EXPECT_EQ(saved.size(), original.size()) << name;
    EXPECT_TRUE(saved == original) << "the localisation run changed the map: " << name;
  }
}

}  // namespace
}  // namespace pspslam
