#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace pspslam {

// A coloured 3-D point (world frame, metres) for map export.
struct ColoredPoint {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  std::uint8_t red = 255, green = 255, blue = 255;
};

// Writes a binary little-endian PLY (vertex: float x, y, z; uchar red, green, blue) that
// MeshLab, CloudCompare and Open3D read. `comment` lines go into the header (no newlines).
// Errors (pspslam::Error): "<file>: cannot write point cloud".
void write_point_cloud_ply(const std::filesystem::path& file, std::span<const ColoredPoint> points,
                           std::span<const std::string> comments = {});

// Reads back exactly the layout write_point_cloud_ply writes (tests, tools). Errors name the
// file and what is wrong: not a PLY, another layout, or fewer vertices than the header says.
std::vector<ColoredPoint> read_point_cloud_ply(const std::filesystem::path& file);

}  // namespace pspslam
