#include "pspslam/occupancy/occupancy_grid.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <random>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

constexpr double kMaxFloorTilt = 0.866;  // cos 30 degrees
constexpr int kRansacIterations = 400;
constexpr size_t kMinFloorSupport = 50;

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// Least-squares plane through `points`: normal towards `up`, height along it.
FloorPlane fit_plane(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  Eigen::Vector3d normal = solver.eigenvectors().col(0);
  if (normal.dot(up) < 0.0) normal = -normal;
  return {normal, normal.dot(mean), true, points.size()};
}

// RANSAC over the candidate voxels; empty plane (support 0) when none is level enough.
FloorPlane ransac_floor(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up,
                        double tolerance) {
  FloorPlane best;
  if (points.size() < kMinFloorSupport) return best;
  std::mt19937 random(7);
  std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
  for (int i = 0; i < kRansacIterations; ++i) {
    const Eigen::Vector3d &a = points[pick(random)], &b = points[pick(random)],
                          &c = points[pick(random)];
    Eigen::Vector3d normal = (b - a).cross(c - a);
    if (normal.norm() < 1e-9) continue;
    normal.normalize();
    if (normal.dot(up) < 0.0) normal = -normal;
    if (normal.dot(up) < kMaxFloorTilt) continue;
    const double height = normal.dot(a);
    size_t support = 0;
    for (const Eigen::Vector3d& p : points) support += std::abs(normal.dot(p) - height) < tolerance;
    if (support > best.support) best = {normal, height, true, support};
  }
  return best;
}

}  // namespace

FloorPlane find_floor(const OccupancyMap& map, const std::vector<Eigen::Vector3d>& camera_centres,
                      const GridOptions& options) {
  FloorPlane floor;
  if (options.floor_height_m) {
    floor.height = *options.floor_height_m;
    return floor;
  }
  std::vector<double> camera_heights;
  for (const Eigen::Vector3d& c : camera_centres) camera_heights.push_back(floor.up.dot(c));
  const double camera_height = median(camera_heights);
  std::vector<Eigen::Vector3d> below;
  std::vector<double> heights;
  map.for_each_voxel([&](const Eigen::Vector3d& centre, bool occupied) {
    if (!occupied) return;
    heights.push_back(floor.up.dot(centre));
    if (heights.back() < camera_height - 0.3) below.push_back(centre);
  });
  // Voxel centres of a level floor lie in one layer; a tilted plane through the floor and the
  // foot of a wall crosses layers, so a tolerance under a voxel prefers the level one.
  const double tolerance = map.resolution() / 2.0;
  FloorPlane found = ransac_floor(below, floor.up, tolerance);
  if (found.support >= kMinFloorSupport) {
    std::vector<Eigen::Vector3d> inliers;
    for (const Eigen::Vector3d& p : below)
      if (std::abs(found.up.dot(p) - found.height) < tolerance) inliers.push_back(p);
    return fit_plane(inliers, floor.up);
  }
  if (!heights.empty()) {
    std::nth_element(heights.begin(), heights.begin() + heights.size() / 100, heights.end());
    floor.height = heights[heights.size() / 100];
  }
  return floor;
}

size_t OccupancyGrid::count(std::int8_t state) const {
  return static_cast<size_t>(std::count(cells.begin(), cells.end(), state));
}

bool OccupancyGrid::cell_of(const Eigen::Vector3d& world_point, int& column, int& row) const {
  const Eigen::Vector3d g = T_world_grid.inverse() * world_point;
  column = static_cast<int>(std::floor((g.x() - origin.x()) / resolution));
  row = static_cast<int>(std::floor((g.y() - origin.y()) / resolution));
  return column >= 0 && row >= 0 && column < width && row < height;
}

OccupancyGrid make_grid(const OccupancyMap& map, const FloorPlane& floor,
                        const GridOptions& options) {
  OccupancyGrid grid;
  grid.resolution = map.resolution();
  grid.floor = floor;
  const Eigen::Vector3d z = floor.up.normalized();
  Eigen::Vector3d x = Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitX().dot(z) * z;
  if (x.norm() < 1e-3) x = Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ().dot(z) * z;
  x.normalize();
  grid.T_world_grid.linear() << x, z.cross(x), z;
  grid.T_world_grid.translation() = z * floor.height;
  const Pose T_grid_world = grid.T_world_grid.inverse();
  std::map<std::pair<int, int>, std::int8_t> states;
  const double r = grid.resolution;
  map.for_each_voxel([&](const Eigen::Vector3d& centre, bool occupied) {
    const Eigen::Vector3d g = T_grid_world * centre;
    if (g.z() < options.min_height_m || g.z() > options.max_height_m) return;
    const std::pair<int, int> cell{static_cast<int>(std::floor(g.x() / r)),
                                   static_cast<int>(std::floor(g.y() / r))};
    std::int8_t& state = states.try_emplace(cell, kGridFree).first->second;
    if (occupied) state = kGridOccupied;
  });
  if (states.empty()) return grid;
  int min_x = INT32_MAX, min_y = INT32_MAX, max_x = INT32_MIN, max_y = INT32_MIN;
  for (const auto& [cell, state] : states) {
    min_x = std::min(min_x, cell.first), max_x = std::max(max_x, cell.first);
    min_y = std::min(min_y, cell.second), max_y = std::max(max_y, cell.second);
  }
  grid.width = max_x - min_x + 1;
  grid.height = max_y - min_y + 1;
  grid.origin = Eigen::Vector2d(min_x, min_y) * r;
  grid.cells.assign(static_cast<size_t>(grid.width) * grid.height, kGridUnknown);
  for (const auto& [cell, state] : states)
    grid.cells[static_cast<size_t>(cell.second - min_y) * grid.width + (cell.first - min_x)] =
        state;
  return grid;
}

void write_map_server(const OccupancyGrid& grid, const std::filesystem::path& yaml) {
  std::filesystem::path pgm = yaml;
  pgm.replace_extension(".pgm");
  {
    std::ofstream out(pgm, std::ios::binary);
    out << "P5\n# pspslam occupancy grid\n" << grid.width << ' ' << grid.height << "\n255\n";
    std::vector<unsigned char> row(static_cast<size_t>(grid.width));
    for (int r = grid.height - 1; r >= 0; --r) {  // the image's top row is the highest y
      for (int c = 0; c < grid.width; ++c) {
        const std::int8_t state = grid.at(c, r);
        row[static_cast<size_t>(c)] = state == kGridOccupied ? 0 : state == kGridFree ? 254 : 205;
      }
      out.write(reinterpret_cast<const char*>(row.data()),
                static_cast<std::streamsize>(row.size()));
    }
    if (!out.flush()) throw Error("cannot write the occupancy grid image " + pgm.string());
  }
  std::ofstream out(yaml);
  out.precision(9);
  out << "image: " << pgm.filename().string() << "\nmode: trinary\nresolution: " << grid.resolution
      << "\norigin: [" << grid.origin.x() << ", " << grid.origin.y() << ", 0.0]\n"
      << "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  if (!out.flush()) throw Error("cannot write the occupancy grid " + yaml.string());
}

}  // namespace pspslam
