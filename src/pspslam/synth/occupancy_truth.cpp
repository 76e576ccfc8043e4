#include "pspslam/synth/occupancy_truth.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pspslam/core/error.h"
#include "pspslam/io/trajectory_io.h"

namespace pspslam {
namespace fs = std::filesystem;
namespace {

// Distance from `point` to a solid box (0 inside it).
double distance_to_solid(const SynthBox& box, const Eigen::Vector3d& point) {
  const Eigen::Vector3d local = (box.T_world_box.inverse() * point).cwiseAbs();
  return (local - box.half_extents).cwiseMax(0.0).norm();
}

// Distance from `point` to the faces of a box (the room: its walls, floor and ceiling).
double distance_to_faces(const SynthBox& box, const Eigen::Vector3d& point) {
  const Eigen::Vector3d local = (box.T_world_box.inverse() * point).cwiseAbs();
  const Eigen::Vector3d outside = local - box.half_extents;
  if ((outside.array() <= 0.0).all()) return -outside.maxCoeff();
  return outside.cwiseMax(0.0).norm();
}

// Every cell of the grid whose centre is within `margin` of the box's axis-aligned bounds.
template <typename Visit>
void for_cells_near(const OccupancyTruth& truth, const SynthBox& box, double margin, Visit visit) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1e9), high = -low;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d local((corner & 1 ? 1 : -1) * box.half_extents.x(),
                                (corner & 2 ? 1 : -1) * box.half_extents.y(),
                                (corner & 4 ? 1 : -1) * box.half_extents.z());
    const Eigen::Vector3d world = box.T_world_box * local;
    low = low.cwiseMin(world);
    high = high.cwiseMax(world);
  }
  const VoxelIndex first = truth.cell_of(low - Eigen::Vector3d::Constant(margin));
  const VoxelIndex last = truth.cell_of(high + Eigen::Vector3d::Constant(margin));
  for (int x = first.x; x <= last.x; ++x)
    for (int y = first.y; y <= last.y; ++y)
      for (int z = first.z; z <= last.z; ++z) visit(VoxelIndex{x, y, z});
}

void add_static_cells(const SyntheticScene& scene, OccupancyTruth& truth) {
  const std::vector<SynthBox> boxes = scene.static_boxes();
  // A cell the geometry passes through has its centre within half its diagonal of it.
  const double r = truth.resolution * std::sqrt(3.0) / 2.0;
  for_cells_near(truth, boxes.front(), 2.0 * r, [&](const VoxelIndex& cell) {
    if (distance_to_faces(boxes.front(), truth.centre_of(cell)) <= r)
      truth.static_cells.insert(cell);
  });
  for (size_t b = 1; b < boxes.size(); ++b) {
    for_cells_near(truth, boxes[b], 2.0 * r, [&](const VoxelIndex& cell) {
      if (distance_to_solid(boxes[b], truth.centre_of(cell)) <= r) truth.static_cells.insert(cell);
    });
  }
}

void add_swept_cells(const SyntheticScene& scene, OccupancyTruth& truth) {
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    const double seconds = scene.timestamp(i) - scene.timestamp(0);
    for (const SynthBox& box : scene.body_boxes_at(seconds)) {
      for_cells_near(truth, box, 0.0, [&](const VoxelIndex& cell) {
        if (distance_to_solid(box, truth.centre_of(cell)) <= 0.0) truth.swept_cells.insert(cell);
      });
    }
  }
}

// Cells holding a point of the exact depth of a static pixel (every second pixel).
void add_seen_cells(const SyntheticScene& scene, const OccupancyTruthOptions& options,
                    OccupancyTruth& truth) {
  const PinholeCamera camera = scene.system_config().camera.pinhole;
  constexpr int kStride = 2;
  std::vector<cv::Point2f> pixels;
  for (int y = 0; y < camera.height; y += kStride)
    for (int x = 0; x < camera.width; x += kStride)
      pixels.emplace_back(static_cast<float>(x), static_cast<float>(y));
  std::vector<cv::Point2f> undistorted = pixels;
  camera.undistort_points(undistorted);
  SynthFrame frame;
  for (size_t i = 0; i < scene.frame_count(); i += std::max<size_t>(options.frame_step, 1)) {
    scene.render(i, frame, options.threads);
    // The depth image is taken at the depth camera's instant.
    const double seconds = scene.timestamp(i) - scene.timestamp(0) + scene.depth_time_offset(i);
    const Pose T_world_camera = scene.camera_pose_at(seconds);
    for (size_t p = 0; p < pixels.size(); ++p) {
      const int x = static_cast<int>(pixels[p].x), y = static_cast<int>(pixels[p].y);
      if (frame.labels.at<std::uint8_t>(y, x) != kSynthLabelStatic) continue;
      const float depth = frame.depth.at<float>(y, x);
      if (depth <= 0.0f || depth > options.max_range_m) continue;
      const Eigen::Vector3d point =
          T_world_camera * camera.unproject({undistorted[p].x, undistorted[p].y}, depth);
      const VoxelIndex cell = truth.cell_of(point);
      if (truth.static_cells.contains(cell)) truth.seen_cells.insert(cell);
    }
  }
}

void write_cells(const VoxelSet& cells, double resolution, const std::string& what,
                 const fs::path& file) {
  std::vector<VoxelIndex> sorted(cells.begin(), cells.end());
  std::sort(sorted.begin(), sorted.end(), [](const VoxelIndex& a, const VoxelIndex& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
  });
  std::ofstream out(file);
  if (!out) throw Error("synth: cannot write " + file.string());
  out << "# " << what << "\n# cell (i, j, k) spans [i r, (i+1) r) on each world axis (z up)\n";
  out << "resolution " << resolution << "\n";
  for (const VoxelIndex& cell : sorted) out << cell.x << ' ' << cell.y << ' ' << cell.z << '\n';
  out.close();
  if (!out) throw Error("synth: failed writing " + file.string());
}

VoxelSet read_cells(const fs::path& file, double& resolution) {
  std::ifstream in(file);
  if (!in) throw Error("cannot read " + file.string());
  VoxelSet cells;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    if (line.rfind("resolution", 0) == 0) {
      std::string key;
      fields >> key >> resolution;
    } else {
      VoxelIndex cell;
      fields >> cell.x >> cell.y >> cell.z;
      if (fields.fail())
        throw Error(file.string() + ":" + std::to_string(number) + ": expected 'i j k'");
      cells.insert(cell);
    }
    if (fields.fail() || resolution <= 0.0)
      throw Error(file.string() + ":" + std::to_string(number) + ": bad line '" + line + "'");
  }
  return cells;
}

}  // namespace

VoxelIndex OccupancyTruth::cell_of(const Eigen::Vector3d& point) const {
  return {static_cast<int>(std::floor(point.x() / resolution)),
          static_cast<int>(std::floor(point.y() / resolution)),
          static_cast<int>(std::floor(point.z() / resolution))};
}

bool OccupancyTruth::static_near(const VoxelIndex& cell) const {
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (static_cells.contains({cell.x + x, cell.y + y, cell.z + z})) return true;
  return false;
}

Eigen::Vector3d OccupancyTruth::centre_of(const VoxelIndex& cell) const {
  return (Eigen::Vector3d(cell.x, cell.y, cell.z) + Eigen::Vector3d::Constant(0.5)) * resolution;
}

OccupancyTruth compute_occupancy_truth(const SyntheticScene& scene,
                                       const OccupancyTruthOptions& options) {
  if (!(options.resolution > 0.0))
    throw Error("synth: flag --occupancy-truth: the resolution must be > 0 metres");
  OccupancyTruth truth;
  truth.resolution = options.resolution;
  truth.max_range_m = options.max_range_m;
  add_static_cells(scene, truth);
  add_swept_cells(scene, truth);
  add_seen_cells(scene, options, truth);
  truth.camera_poses = scene.ground_truth();
  return truth;
}

void write_occupancy_truth(const OccupancyTruth& truth, const fs::path& dir) {
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) throw Error("synth: cannot create " + dir.string() + ": " + error.message());
  write_cells(truth.static_cells, truth.resolution,
              "static cells: centre within half a cell diagonal of the walls, floor, ceiling or "
              "furniture",
              dir / "static.txt");
  std::ostringstream seen;
  seen << "seen cells: static cells holding exact depth of a static pixel within "
       << truth.max_range_m << " m";
  write_cells(truth.seen_cells, truth.resolution, seen.str(), dir / "seen.txt");
  write_cells(truth.swept_cells, truth.resolution,
              "swept cells: centre inside a walking person (or carried box) at some frame",
              dir / "swept.txt");
  write_tum_trajectory(dir / "camera.txt", truth.camera_poses);
}

OccupancyTruth read_occupancy_truth(const fs::path& dir) {
  OccupancyTruth truth;
  double resolution = 0.0;
  truth.static_cells = read_cells(dir / "static.txt", resolution);
  truth.resolution = resolution;
  truth.seen_cells = read_cells(dir / "seen.txt", resolution);
  truth.swept_cells = read_cells(dir / "swept.txt", resolution);
  if (resolution != truth.resolution)
    throw Error(dir.string() + ": the cell files disagree on the resolution");
  truth.camera_poses = read_tum_trajectory(dir / "camera.txt");
  return truth;
}

}  // namespace pspslam
