#include "pspslam/io/point_cloud_ply.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "pspslam/core/error.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

// A file in a folder of its own, removed when the test passes (support/test_support.h).
std::filesystem::path temp_file(const std::string& name) {
  return testing::make_temp_dir("ply_" + name) / name;
}

std::string error_of(const std::filesystem::path& file) {
  try {
    read_point_cloud_ply(file);
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

TEST(PointCloudPly, RoundTripKeepsPositionsAndColours) {
  std::vector<ColoredPoint> points(3);
  points[0].position = {1.5f, -2.25f, 3.0f};
  points[1].position = {0.0f, 1e-3f, -7.75f};
  points[1].red = 10, points[1].green = 20, points[1].blue = 30;
  points[2].position = {123.0f, 0.5f, 0.25f};
  points[2].red = 0, points[2].green = 255, points[2].blue = 128;
  const auto file = temp_file("round_trip.ply");
  const std::vector<std::string> comments = {"pspslam static map", "frames 42"};
  write_point_cloud_ply(file, points, comments);
  // 15 bytes per vertex after the text header.
  std::ifstream in(file, std::ios::binary);
  std::string header((std::istreambuf_iterator<char>(in)), {});
  const auto end = header.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  EXPECT_EQ(header.size() - (end + 11), 3u * 15u);
  EXPECT_NE(header.find("element vertex 3\n"), std::string::npos);
  EXPECT_NE(header.find("comment frames 42\n"), std::string::npos);

  const std::vector<ColoredPoint> back = read_point_cloud_ply(file);
  ASSERT_EQ(back.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(back[i].position, points[i].position) << i;
    EXPECT_EQ(back[i].red, points[i].red);
    EXPECT_EQ(back[i].green, points[i].green);
    EXPECT_EQ(back[i].blue, points[i].blue);
  }
}

TEST(PointCloudPly, EmptyCloudIsValid) {
  const auto file = temp_file("empty.ply");
  write_point_cloud_ply(file, {});
  EXPECT_TRUE(read_point_cloud_ply(file).empty());
}

TEST(PointCloudPly, TruncatedFileNamesTheMissingVertices) {
  std::vector<ColoredPoint> points(4);
  const auto file = temp_file("truncated.ply");
  write_point_cloud_ply(file, points);
  std::filesystem::resize_file(file, std::filesystem::file_size(file) - 20);
  const std::string message = error_of(file);
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
  EXPECT_NE(message.find("truncated: header says 4 vertices, file has 2"), std::string::npos)
      << message;
}

// Found by fuzz/fuzz_point_cloud_ply: a vertex count far beyond the file asked for an
// impossible allocation (std::length_error, exit 3) instead of a clear error.
TEST(PointCloudPly, ImpossibleVertexCountIsAnError) {
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex COUNT\nproperty float x\n"
      "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nend_header\n";
  const auto huge = temp_file("huge.ply");
  std::ofstream(huge) << std::string(header).replace(header.find("COUNT"), 5,
                                                     "18446744073709551615");
  EXPECT_NE(error_of(huge).find("truncated: header says 18446744073709551615 vertices, file has 0"),
            std::string::npos)
      << error_of(huge);
  const auto negative = temp_file("negative.ply");
  std::ofstream(negative) << std::string(header).replace(header.find("COUNT"), 5, "-1");
  EXPECT_NE(error_of(negative).find("bad vertex count in 'element vertex -1'"), std::string::npos)
      << error_of(negative);
}

TEST(PointCloudPly, OtherFormatsAreRejectedWithTheReason) {
  const auto ascii = temp_file("ascii.ply");
  std::ofstream(ascii) << "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n";
  EXPECT_NE(error_of(ascii).find("expected 'format binary_little_endian 1.0', got 'format ascii"),
            std::string::npos);
  const auto text = temp_file("not_ply.ply");
  std::ofstream(text) << "hello\n";
  EXPECT_NE(error_of(text).find("not a PLY file"), std::string::npos);
  EXPECT_NE(error_of(temp_file("missing.ply")).find("cannot open point cloud"), std::string::npos);
}

}  // namespace
}  // namespace pspslam
