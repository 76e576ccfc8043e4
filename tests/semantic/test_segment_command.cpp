#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "pspslam/core/shared_paths.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

TEST(SegmentCommand, WritesOverlaysMasksAndTiming) {
  const auto dir = testing::make_temp_dir("semantic");
  const auto images = dir / "images";
  std::filesystem::create_directories(images);
  const auto golden = source_dir() / "models" / "pspnet" / "golden" / "input.png";
  std::filesystem::copy_file(golden, images / "a.png");
  std::filesystem::copy_file(golden, images / "b.png");
  std::string output;
  const int status =
      testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " segment --images " + images.string() +
                             " --out " + (dir / "out").string() + " --limit 1 --dilation 3",
                         &output);
  ASSERT_EQ(status, 0) << output;
  EXPECT_NE(output.find("median"), std::string::npos) << output;
  for (const char* name : {"a_overlay.png", "a_labels.png", "a_mask.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / name)) << name;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "b_mask.png"));  // --limit 1
  const cv::Mat labels = cv::imread((dir / "out" / "a_labels.png").string(), cv::IMREAD_UNCHANGED);
  const cv::Mat expected =
      cv::imread((source_dir() / "models" / "pspnet" / "golden" / "labels.png").string(),
                 cv::IMREAD_UNCHANGED);
  ASSERT_EQ(labels.size(), expected.size());
  EXPECT_LE(cv::countNonZero(labels != expected), static_cast<int>(labels.total() / 1000));
}

TEST(SegmentCommand, ReportsBadFlagsWithTheirName) {
  const auto dir = testing::make_temp_dir("semantic");
  std::string output;
  int status = testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " segment --images " +
                                      (dir / "nope").string() + " --out " + dir.string(),
                                  &output);
  EXPECT_EQ(status, 2);
  EXPECT_NE(
      output.find("error: segment: --images '" + (dir / "nope").string() + "' is not a directory"),
      std::string::npos)
      << output;
  status = testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " segment --images " + dir.string() +
                                  " --out " + dir.string() + " --step 0",
                              &output);
  EXPECT_EQ(status, 2);
  EXPECT_NE(output.find("error: pspslam segment: --step: must be an integer in [1, 1000000], got "
                        "'0' (see 'pspslam segment --help')"),
            std::string::npos)
      << output;
}

}  // namespace
}  // namespace pspslam
