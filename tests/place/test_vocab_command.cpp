// `pspslam vocab train` / `vocab info` end to end on a handful of generated pictures.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "pspslam/place/vocabulary.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

namespace fs = std::filesystem;

std::string cli() { return PSPSLAM_CLI_PATH; }

// Random rectangles and circles: plenty of corners for ORB.
void write_pictures(const fs::path& dir, int count) {
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> coordinate(0, 639);
  std::uniform_int_distribution<int> shade(0, 255);
  for (int i = 0; i < count; ++i) {
    cv::Mat image(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
    for (int s = 0; s < 120; ++s) {
      const cv::Point a(coordinate(rng), coordinate(rng) % 480);
      const cv::Scalar colour(shade(rng), shade(rng), shade(rng));
      if (s % 2 == 0) {
        cv::rectangle(image, a, a + cv::Point(20 + s % 40, 15 + s % 30), colour, cv::FILLED);
      } else {
        cv::circle(image, a, 5 + s % 25, colour, cv::FILLED);
      }
    }
    // Two folders, one nested: the images are found recursively.
    const fs::path folder = dir / (i % 2 == 0 ? "a" : "b/c");
    fs::create_directories(folder);
    std::string name = "p";
    name += std::to_string(i);  // GCC 12 misreports "p" + to_string(i) under -Wrestrict
    name += ".png";
    cv::imwrite((folder / name).string(), image);
  }
}

TEST(VocabCommand, TrainsFromImagesAndSyntheticFramesThenInfoLoadsIt) {
  const fs::path dir = testing::make_temp_dir("vocab_cmd");
  write_pictures(dir / "pictures", 6);
  const fs::path out = dir / "voc.pspvoc";
  std::string output;
  const int status =
      testing::run_shell(cli() + " vocab train --images " + (dir / "pictures").string() +
                             " --synthetic-frames 2 --k 6 --levels 3 --seed 4"
                             " --out " +
                             out.string(),
                         &output);
  ASSERT_EQ(status, 0) << output;
  EXPECT_NE(output.find("training images: 6 photographs, 2 synthetic frames"), std::string::npos)
      << output;
  const Vocabulary vocabulary = Vocabulary::load(out);
  EXPECT_EQ(vocabulary.branching(), 6);
  EXPECT_EQ(vocabulary.levels(), 3);
  EXPECT_GT(vocabulary.word_count(), 100u);
  EXPECT_LE(vocabulary.word_count(), 216u);
  // 6 pictures (each one view: 640 x 480 is not enlarged) + 2 frames.
  EXPECT_EQ(vocabulary.training_images(), 8u);

  ASSERT_EQ(testing::run_shell(
                cli() + " vocab info --frames 1 --repeat 1 --vocabulary " + out.string(), &output),
            0)
      << output;
  EXPECT_NE(output.find("k 6, L 3"), std::string::npos) << output;
  EXPECT_NE(output.find("us per 1000 descriptors"), std::string::npos) << output;
}

TEST(VocabCommand, ErrorsNameTheFlagOrFile) {
  const fs::path dir = testing::make_temp_dir("vocab_cmd");
  std::string output;
  EXPECT_EQ(testing::run_shell(cli() + " vocab train --images " + (dir / "none").string() +
                                   " --out " + (dir / "v").string(),
                               &output),
            2);
  EXPECT_NE(output.find("error: vocab train: --images '" + (dir / "none").string() +
                        "' is not a directory"),
            std::string::npos)
      << output;
  EXPECT_EQ(testing::run_shell(cli() +
                                   " vocab train --synthetic-frames 1 --synthetic-seed 5"
                                   " --out " +
                                   (dir / "v").string(),
                               &output),
            2);
  EXPECT_NE(output.find("error: pspslam vocab train: --synthetic-seed: must be an integer in "
                        "[1000, 1000000000], got '5'"),
            std::string::npos)
      << output;
  EXPECT_EQ(testing::run_shell(cli() + " vocab info --vocabulary " + (dir / "v").string(), &output),
            2);
  EXPECT_NE(
      output.find("error: vocabulary file '" + (dir / "v").string() + "': cannot open for reading"),
      std::string::npos)
      << output;
}

}  // namespace
}  // namespace pspslam
