#include "pspslam/io/point_cloud_ply.h"

#include <array>
#include <bit>
#include <cstring>
#include <fstream>
#include <sstream>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

static_assert(std::endian::native == std::endian::little,
              "PLY export writes the host's float layout as binary_little_endian");

constexpr std::size_t kVertexBytes = 3 * sizeof(float) + 3;

constexpr std::array<const char*, 6> kVertexProperties = {
    "property float x",   "property float y",     "property float z",
    "property uchar red", "property uchar green", "property uchar blue"};

}  // namespace

void write_point_cloud_ply(const std::filesystem::path& file, std::span<const ColoredPoint> points,
                           std::span<const std::string> comments) {
  std::ofstream out(file, std::ios::binary);
  if (!out) throw Error(file.string() + ": cannot write point cloud");
  out << "ply\nformat binary_little_endian 1.0\n";
  for (const std::string& comment : comments) out << "comment " << comment << '\n';
  out << "element vertex " << points.size() << '\n';
  for (const char* property : kVertexProperties) out << property << '\n';
  out << "end_header\n";
  std::array<char, kVertexBytes> record{};
  for (const ColoredPoint& point : points) {
    std::memcpy(record.data(), point.position.data(), 3 * sizeof(float));
    record[12] = static_cast<char>(point.red);
    record[13] = static_cast<char>(point.green);
    record[14] = static_cast<char>(point.blue);
    out.write(record.data(), record.size());
  }
  out.flush();
  if (!out) throw Error(file.string() + ": cannot write point cloud (disk full?)");
}

std::vector<ColoredPoint> read_point_cloud_ply(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file.string() + ": cannot open point cloud");
  const auto fail = [&](const std::string& what) -> Error {
    return Error(file.string() + ": " + what);
  };
  std::string line;
  if (!std::getline(in, line) || line != "ply") throw fail("not a PLY file (no 'ply' line)");
  if (!std::getline(in, line) || line != "format binary_little_endian 1.0")
    throw fail("expected 'format binary_little_endian 1.0', got '" + line + "'");
  std::size_t count = 0;
  bool have_count = false;
  std::size_t property = 0;
  while (std::getline(in, line) && line != "end_header") {
    if (line.rfind("comment", 0) == 0) continue;
    if (line.rfind("element vertex ", 0) == 0) {
      std::istringstream fields(line.substr(15));
      std::string rest;
      if (line.find('-') != std::string::npos || !(fields >> count) || (fields >> rest))
        throw fail("bad vertex count in '" + line + "'");
      have_count = true;
      continue;
    }
    if (property >= kVertexProperties.size() || line != kVertexProperties[property])
      throw fail("unexpected header line '" + line + "' (only x y z red green blue is read)");
    ++property;
  }
  if (line != "end_header") throw fail("header has no end_header line");
  if (!have_count || property != kVertexProperties.size())
    throw fail("header lacks the vertex element or its properties");
  // The count comes from the file: check it against the bytes that follow before allocating
  // (found by fuzz/fuzz_point_cloud_ply: a huge count asked for an impossible vector).
  const auto data_start = in.tellg();
  in.seekg(0, std::ios::end);
  const auto data_bytes = static_cast<std::size_t>(in.tellg() - data_start);
  in.seekg(data_start);
  if (count > data_bytes / kVertexBytes) {
    throw fail("truncated: header says " + std::to_string(count) + " vertices, file has " +
               std::to_string(data_bytes / kVertexBytes));
  }
  std::vector<ColoredPoint> points(count);
  std::array<char, kVertexBytes> record{};
  for (std::size_t i = 0; i < count; ++i) {
    if (!in.read(record.data(), record.size()))
      throw fail("truncated: header says " + std::to_string(count) + " vertices, file has " +
                 std::to_string(i));
    std::memcpy(points[i].position.data(), record.data(), 3 * sizeof(float));
    points[i].red = static_cast<std::uint8_t>(record[12]);
    points[i].green = static_cast<std::uint8_t>(record[13]);
    points[i].blue = static_cast<std::uint8_t>(record[14]);
  }
  return points;
}

}  // namespace pspslam
