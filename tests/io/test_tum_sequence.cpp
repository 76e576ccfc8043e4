#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "pspslam/core/error.h"
#include "pspslam/io/image_files.h"
#include "pspslam/io/sequence_setup.h"
#include "pspslam/io/tum_sequence.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

using testing::write_text;

// A small TUM-layout sequence: 4 colour frames at 0.1 s, depth 5 ms later, depth value 5000*k.
std::filesystem::path make_sequence(const std::string& tag) {
  const auto dir = testing::make_temp_dir(tag);
  std::filesystem::create_directories(dir / "rgb");
  std::filesystem::create_directories(dir / "depth");
  std::string rgb_list = "# color images\n# timestamp filename\n";
  std::string depth_list = "# depth maps\n";
  for (int i = 0; i < 4; ++i) {
    char rgb_name[64], depth_name[64];
    std::snprintf(rgb_name, sizeof(rgb_name), "rgb/%.4f.png", 10.0 + 0.1 * i);
    std::snprintf(depth_name, sizeof(depth_name), "depth/%.4f.png", 10.005 + 0.1 * i);
    cv::Mat bgr(6, 8, CV_8UC3, cv::Scalar(10 * i, 20, 30));
    cv::imwrite((dir / rgb_name).string(), bgr);
    cv::Mat depth(6, 8, CV_16UC1, cv::Scalar(5000 * (i + 1)));
    depth.at<uint16_t>(0, 0) = 0;  // no reading
    cv::imwrite((dir / depth_name).string(), depth);
    rgb_list += std::string(rgb_name).substr(4, 7) + " " + rgb_name + "\n";
    depth_list += std::string(depth_name).substr(6, 7) + " " + depth_name + "\n";
  }
  write_text(dir / "rgb.txt", rgb_list);
  write_text(dir / "depth.txt", depth_list);
  return dir;
}

std::string open_error(const std::filesystem::path& dir) {
  try {
    SequenceOptions options;
    options.warnings = nullptr;
    TumSequence::open(dir, options);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

std::string load_error(const std::filesystem::path& dir, size_t index) {
  SequenceOptions options;
  options.warnings = nullptr;
  const TumSequence sequence = TumSequence::open(dir, options);
  try {
    sequence.load(index);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(TumSequence, AssociatesAndLoadsFrames) {
  const auto dir = make_sequence("seq");
  std::ostringstream warnings;
  SequenceOptions options;
  options.warnings = &warnings;
  const TumSequence sequence = TumSequence::open(dir, options);
  EXPECT_TRUE(warnings.str().empty());
  ASSERT_EQ(sequence.size(), 4u);
  EXPECT_EQ(sequence.listed_rgb(), 4u);
  EXPECT_EQ(sequence.listed_depth(), 4u);
  EXPECT_FALSE(sequence.ground_truth().has_value());
  EXPECT_FALSE(sequence.config_path().has_value());
  EXPECT_DOUBLE_EQ(sequence.timestamp(2), 10.2);
  const InputFrame frame = sequence.load(2);
  EXPECT_EQ(frame.index, 2u);
  EXPECT_DOUBLE_EQ(frame.timestamp, 10.2);
  EXPECT_DOUBLE_EQ(frame.depth_timestamp, 10.205);
  EXPECT_EQ(frame.bgr.type(), CV_8UC3);
  EXPECT_EQ(frame.gray.type(), CV_8UC1);
  EXPECT_EQ(frame.depth.type(), CV_32FC1);
  EXPECT_EQ(frame.bgr.at<cv::Vec3b>(3, 3), cv::Vec3b(20, 20, 30));
  EXPECT_FLOAT_EQ(frame.depth.at<float>(3, 3), 3.0f);  // 15000 / 5000
  EXPECT_FLOAT_EQ(frame.depth.at<float>(0, 0), 0.0f);  // no reading stays 0
}

TEST(TumSequence, DepthFactorIsApplied) {
  const auto dir = make_sequence("seq");
  SequenceOptions options;
  options.depth_factor = 1000.0;
  const InputFrame frame = TumSequence::open(dir, options).load(0);
  EXPECT_FLOAT_EQ(frame.depth.at<float>(3, 3), 5.0f);
}

// The registration shift reads depth pixel (u + dx, v + dy) for colour pixel (u, v); what is
// shifted in from beyond the border has no reading.
TEST(TumSequence, DepthRegistrationShiftMovesTheDepthImage) {
  const auto dir = testing::make_temp_dir("depth_shift");
  cv::Mat raw(6, 8, CV_16UC1);
  for (int v = 0; v < raw.rows; ++v)
    for (int u = 0; u < raw.cols; ++u) raw.at<uint16_t>(v, u) = static_cast<uint16_t>(100 * v + u);
  cv::imwrite((dir / "d.png").string(), raw);
  const cv::Mat shifted = read_depth_image(dir / "d.png", 1000.0, -2, 1);
  ASSERT_EQ(shifted.size(), raw.size());
  for (int v = 0; v < raw.rows; ++v) {
    for (int u = 0; u < raw.cols; ++u) {
      const bool inside = u - 2 >= 0 && v + 1 < raw.rows;
      const float expected = inside ? (100.0f * (v + 1) + (u - 2)) / 1000.0f : 0.0f;
      EXPECT_FLOAT_EQ(shifted.at<float>(v, u), expected) << u << ", " << v;
    }
  }
  // The sequence applies the shift of its options to every frame.
  const auto sequence_dir = make_sequence("seq_shift");
  SequenceOptions options;
  options.warnings = nullptr;
  options.depth_shift_y = 1;
  const InputFrame frame = TumSequence::open(sequence_dir, options).load(0);
  EXPECT_FLOAT_EQ(frame.depth.at<float>(0, 1), 1.0f);  // row 1 of the image
  EXPECT_FLOAT_EQ(frame.depth.at<float>(5, 1), 0.0f);  // shifted in from below the border
}

TEST(TumSequence, MissingFilesSkipFramesWithOneWarning) {
  const auto dir = make_sequence("seq");
  std::filesystem::remove(dir / "depth/10.1050.png");
  std::filesystem::remove(dir / "rgb/10.3000.png");
  std::ostringstream warnings;
  SequenceOptions options;
  options.warnings = &warnings;
  const TumSequence sequence = TumSequence::open(dir, options);
  EXPECT_EQ(warnings.str(), "warning: " + dir.string() +
                                ": 2 listed files are missing; skipped 2 frames (first: "
                                "rgb/10.3000.png)\n");
  EXPECT_EQ(sequence.warning(), warnings.str().substr(9, warnings.str().size() - 10));
  EXPECT_EQ(sequence.missing_files(), 2u);
  EXPECT_EQ(sequence.skipped_frames(), 2u);
  ASSERT_EQ(sequence.size(), 2u);
  EXPECT_DOUBLE_EQ(sequence.timestamp(0), 10.0);
  EXPECT_DOUBLE_EQ(sequence.timestamp(1), 10.2);
  EXPECT_EQ(sequence.load(1).index, 1u);
}

// Found by fuzz/fuzz_sequence_lists: a listed file name too long for the file system made
// std::filesystem::exists throw (exit 3); it is a missing file like any other.
TEST(TumSequence, UnlookupableFileNameIsAMissingFile) {
  const auto dir = testing::make_temp_dir("sequence_long_name");
  const std::string long_name(5000, 'c');
  std::ofstream(dir / "rgb.txt") << "1.0 " << long_name << "\n";
  std::ofstream(dir / "depth.txt") << "1.0 " << long_name << "\n";
  EXPECT_EQ(open_error(dir), dir.string() +
                                 ": no RGB-D frame: 1 colour and 1 depth files listed, none "
                                 "associated within 0.020000 s with both files present");
}

TEST(TumSequence, MalformedListLinesNameFileAndLine) {
  const auto dir = make_sequence("seq");
  write_text(dir / "rgb.txt", "# header\n10.0000 rgb/10.0000.png\n10.1000\n");
  EXPECT_EQ(open_error(dir),
            (dir / "rgb.txt").string() + ":3: expected 'timestamp filename', got 1 fields");
  write_text(dir / "rgb.txt", "10.0000 rgb/10.0000.png extra\n");
  EXPECT_EQ(open_error(dir),
            (dir / "rgb.txt").string() + ":1: expected 'timestamp filename', got 3 fields");
  write_text(dir / "rgb.txt", "10.0000 rgb/10.0000.png\n");
  write_text(dir / "depth.txt", "\n# c\nt10.005 depth/10.0050.png\n");
  EXPECT_EQ(open_error(dir),
            (dir / "depth.txt").string() + ":3: timestamp 't10.005' is not a number");
  write_text(dir / "depth.txt", "10.005 depth/10.0050.png\n10.005 depth/10.1050.png\n");
  EXPECT_EQ(open_error(dir), (dir / "depth.txt").string() + ":2: timestamp 10.005 repeats line 1");
}

TEST(TumSequence, MalformedGroundTruthIsAnError) {
  const auto dir = make_sequence("seq");
  write_text(dir / "groundtruth.txt", "# gt\n10.0 0 0 0 0 0 0 1\n10.1 0 0 0 0 0 0\n");
  EXPECT_EQ(open_error(dir), (dir / "groundtruth.txt").string() +
                                 ":3: expected 8 fields 'timestamp tx ty tz qx qy qz qw', got 7");
  write_text(dir / "groundtruth.txt", "10.0 0 0 0 0 0 0 1\n10.1 1 0 0 0 0 0 1\n");
  SequenceOptions options;
  const TumSequence sequence = TumSequence::open(dir, options);
  ASSERT_TRUE(sequence.ground_truth().has_value());
  EXPECT_EQ(sequence.ground_truth()->size(), 2u);
}

TEST(TumSequence, MissingDirectoryAndLists) {
  const auto dir = make_sequence("seq");
  EXPECT_EQ(open_error(dir / "nope"), (dir / "nope").string() + ": sequence directory not found");
  std::filesystem::remove(dir / "depth.txt");
  EXPECT_EQ(open_error(dir),
            dir.string() +
                ": no depth.txt (a TUM RGB-D sequence needs rgb.txt and depth.txt, or "
                "associations.txt)");
}

TEST(TumSequence, NothingAssociated) {
  const auto dir = make_sequence("seq");
  write_text(dir / "depth.txt", "20.0 depth/10.0050.png\n");
  EXPECT_EQ(open_error(dir), dir.string() +
                                 ": no RGB-D frame: 4 colour and 1 depth files listed, none "
                                 "associated within 0.020000 s with both files present");
}

TEST(TumSequence, AssociationsFileIsUsedAsGiven) {
  const auto dir = make_sequence("seq");
  // Pairs that associate.py would not make (0.105 s apart): the file is taken as given.
  write_text(dir / "associations.txt",
             "# t_rgb rgb t_depth depth\n10.0 rgb/10.0000.png 10.105 depth/10.1050.png\n"
             "10.2 rgb/10.2000.png 10.005 depth/10.0050.png\n");
  const TumSequence sequence = TumSequence::open(dir);
  EXPECT_TRUE(sequence.used_associations_file());
  ASSERT_EQ(sequence.size(), 2u);
  EXPECT_EQ(sequence.files(1).depth_file, "depth/10.0050.png");
  EXPECT_FLOAT_EQ(sequence.load(0).depth.at<float>(2, 2), 2.0f);
  write_text(dir / "associations.txt", "10.0 rgb/10.0000.png 10.105\n");
  EXPECT_EQ(open_error(dir), (dir / "associations.txt").string() +
                                 ":1: expected 't_rgb rgb_file t_depth depth_file', got 3 fields");
}

TEST(TumSequence, EightBitDepthIsAnError) {
  const auto dir = make_sequence("seq");
  cv::imwrite((dir / "depth/10.0050.png").string(), cv::Mat(6, 8, CV_8UC1, cv::Scalar(3)));
  EXPECT_EQ(load_error(dir, 0), (dir / "depth/10.0050.png").string() +
                                    ": depth image must be 16-bit single-channel (got 8-bit, 1 "
                                    "channel)");
  cv::imwrite((dir / "depth/10.1050.png").string(), cv::Mat(6, 8, CV_16UC3, cv::Scalar(3, 3, 3)));
  EXPECT_EQ(load_error(dir, 1), (dir / "depth/10.1050.png").string() +
                                    ": depth image must be 16-bit single-channel (got 16-bit, 3 "
                                    "channels)");
}

TEST(TumSequence, EmptyDepthFileIsAnError) {
  const auto dir = make_sequence("seq");
  write_text(dir / "depth/10.0050.png", "");
  EXPECT_EQ(load_error(dir, 0), (dir / "depth/10.0050.png").string() +
                                    ": cannot read depth image (missing, empty or not an image)");
  write_text(dir / "rgb/10.1000.png", "not a png");
  EXPECT_EQ(load_error(dir, 1), (dir / "rgb/10.1000.png").string() +
                                    ": cannot read colour image (missing, empty or not an image)");
}

TEST(TumSequence, ColourAndDepthOfDifferentSize) {
  const auto dir = make_sequence("seq");
  cv::imwrite((dir / "depth/10.0050.png").string(), cv::Mat(3, 4, CV_16UC1, cv::Scalar(1)));
  EXPECT_EQ(load_error(dir, 0), (dir / "rgb/10.0000.png").string() + " is 8x6 but " +
                                    (dir / "depth/10.0050.png").string() + " is 4x3");
}

TEST(SequenceSetup, UsesSequenceConfigOrAsksForOne) {
  const auto dir = make_sequence("seq");
  try {
    open_sequence_with_config(dir, std::nullopt, nullptr);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              dir.string() + ": no camera config: --config was not given and " +
                  (dir / "config.yaml").string() +
                  " does not exist (pass a preset, e.g. --config config/bonn.yaml)");
  }
  write_text(dir / "config.yaml",
             "camera:\n  width: 8\n  height: 6\n  fx: 10\n  fy: 10\n  cx: 4\n  cy: 3\n"
             "  distortion: [0, 0, 0, 0]\n  fps: 10\n  depth_factor: 2500\n  depth_threshold: 3\n");
  const SequenceSetup setup = open_sequence_with_config(dir, std::nullopt, nullptr);
  EXPECT_EQ(setup.config_file, dir / "config.yaml");
  EXPECT_EQ(setup.sequence->config_path(), dir / "config.yaml");
  EXPECT_FLOAT_EQ(setup.sequence->load(0).depth.at<float>(1, 1), 2.0f);  // 5000 / 2500
  EXPECT_EQ(describe_sequence(setup),
            "sequence:     " + dir.string() +
                "\n"
                "frames:       4 (4 colour and 4 depth files listed, associated within 0.02 s; 0 "
                "listed files missing, 0 frames skipped)\n"
                "time span:    0.300 s (10.00000 .. 10.30000)\n"
                "ground truth: no (no groundtruth.txt)\n"
                "config:       " +
                (dir / "config.yaml").string() + " (camera 'unnamed', 8x6, depth factor 2500)\n");
}

TEST(BonnCrowdDev, LoaderOnRealData) {
  PSPSLAM_SHARED_OR_SKIP(shared);
  const std::filesystem::path dir = shared / "data" / "bonn_crowd_dev";
  std::ostringstream warnings;
  SequenceOptions options;
  options.warnings = &warnings;
  const TumSequence sequence = TumSequence::open(dir, options);
  EXPECT_EQ(sequence.listed_rgb(), 400u);
  EXPECT_EQ(sequence.listed_depth(), 403u);
  // depth.txt lists two depth files that do not exist (the README's third, 1548339834.30352,
  // lies after the end of this clip). associate.py pairs no colour frame with either, so all 400
  // colour frames keep a depth image.
  EXPECT_EQ(sequence.missing_files(), 2u);
  EXPECT_EQ(sequence.skipped_frames(), 0u);
  EXPECT_EQ(warnings.str(), "warning: " + dir.string() +
                                ": 2 listed files are missing; skipped 0 frames (first: "
                                "depth/1548339819.85514.png)\n");
  ASSERT_EQ(sequence.size(), 400u);
  ASSERT_TRUE(sequence.ground_truth().has_value());
  EXPECT_EQ(sequence.ground_truth()->size(), 404u);
  EXPECT_DOUBLE_EQ(sequence.timestamp(0), 1548339819.87426);
  EXPECT_EQ(sequence.files(0).depth_file, "depth/1548339819.88851.png");
  EXPECT_NEAR(sequence.timestamp(399) - sequence.timestamp(0), 13.374, 1e-3);

  const InputFrame first = sequence.load(0);
  EXPECT_EQ(first.bgr.type(), CV_8UC3);
  EXPECT_EQ(first.bgr.cols, 640);
  EXPECT_EQ(first.bgr.rows, 480);
  EXPECT_EQ(first.depth.type(), CV_32FC1);
  EXPECT_EQ(first.depth.size(), first.bgr.size());
  // An indoor room seen by a Kinect-class sensor: most pixels read, all within 0.3-10 m.
  const cv::Mat valid = first.depth > 0.0f;
  const double valid_fraction = cv::countNonZero(valid) / static_cast<double>(first.depth.total());
  EXPECT_GT(valid_fraction, 0.5);
  double min_depth = 0.0, max_depth = 0.0;
  cv::minMaxLoc(first.depth, &min_depth, &max_depth, nullptr, nullptr, valid);
  EXPECT_GT(min_depth, 0.3);
  EXPECT_LT(max_depth, 10.0);
  const double mean_depth = cv::mean(first.depth, valid)[0];
  EXPECT_GT(mean_depth, 1.0);
  EXPECT_LT(mean_depth, 5.0);
}

}  // namespace
}  // namespace pspslam
