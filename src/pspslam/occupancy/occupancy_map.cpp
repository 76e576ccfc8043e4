#include "pspslam/occupancy/occupancy_map.h"

#include <octomap/OcTree.h>

#include <cmath>
#include <fstream>
#include <unordered_map>
#include <unordered_set>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

octomap::point3d to_octomap(const Eigen::Vector3d& p) {
  return {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
}

Eigen::Vector3d to_eigen(const octomap::point3d& p) { return {p.x(), p.y(), p.z()}; }

constexpr double kSeenThroughMarginVoxels = 3.0;

}  // namespace

KeyframeScan make_keyframe_scan(std::uint64_t keyframe_id, const PinholeCamera& camera,
                                const cv::Mat& depth, const cv::Mat& dynamic_mask,
                                const OccupancyOptions& options) {
  KeyframeScan scan;
  scan.keyframe_id = keyframe_id;
  std::vector<cv::Point2f> pixels;
  std::vector<float> depths;
  const bool masked = options.use_masks && !dynamic_mask.empty();
  for (int y = 0; y < depth.rows; y += options.pixel_stride) {
    for (int x = 0; x < depth.cols; x += options.pixel_stride) {
      const float z = depth.at<float>(y, x);
      if (!(z > 0.0f) || !std::isfinite(z)) continue;
      if (masked && dynamic_mask.at<std::uint8_t>(y, x)) continue;
      pixels.emplace_back(static_cast<float>(x), static_cast<float>(y));
      depths.push_back(z);
    }
  }
  camera.undistort_points(pixels);
  scan.points.reserve(pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i)
    scan.points.push_back(camera.unproject({pixels[i].x, pixels[i].y}, depths[i]).cast<float>());
  return scan;
}

struct OccupancyMap::Impl {
  explicit Impl(const OccupancyOptions& opts) : options(opts), tree(opts.resolution_m) {}

  // The voxels one scan marks free (the rays before their ends, cut at the maximum range) and
  // occupied (the ends within range); a voxel both hit and passed is occupied.
  void compute_update(const KeyframeScan& scan, const Pose& T_world_camera,
                      octomap::KeySet& free_cells, octomap::KeySet& occupied_cells) const {
    octomap::Pointcloud cloud;
    cloud.reserve(scan.points.size());
    for (const Eigen::Vector3f& point : scan.points)
      cloud.push_back(to_octomap(T_world_camera * point.cast<double>()));
    octomap::OcTree& mutable_tree = const_cast<octomap::OcTree&>(tree);  // ray buffers only
    mutable_tree.computeUpdate(cloud, to_octomap(T_world_camera.translation()), free_cells,
                               occupied_cells, options.max_range_m);
  }

  OccupancyOptions options;
  octomap::OcTree tree;
  size_t scans = 0;
  // The insertion index of the scan that first hit each voxel (for seen_through).
  std::unordered_map<octomap::OcTreeKey, std::uint32_t, octomap::OcTreeKey::KeyHash> first_hit;
};

OccupancyMap::OccupancyMap(const OccupancyOptions& options)
    : impl_(std::make_unique<Impl>(options)) {}
OccupancyMap::~OccupancyMap() = default;
OccupancyMap::OccupancyMap(OccupancyMap&&) noexcept = default;
OccupancyMap& OccupancyMap::operator=(OccupancyMap&&) noexcept = default;

void OccupancyMap::insert(const KeyframeScan& scan, const Pose& T_world_camera) {
  octomap::KeySet free_cells, occupied_cells;
  impl_->compute_update(scan, T_world_camera, free_cells, occupied_cells);
  if (impl_->options.clearing) {
    for (const octomap::OcTreeKey& key : free_cells) impl_->tree.updateNode(key, false, true);
  }
  const auto index = static_cast<std::uint32_t>(impl_->scans);
  for (const octomap::OcTreeKey& key : occupied_cells) {
    impl_->tree.updateNode(key, true, true);
    impl_->first_hit.try_emplace(key, index);
  }
  impl_->tree.updateInnerOccupancy();
  ++impl_->scans;
}

void OccupancyMap::clear() {
  impl_->tree.clear();
  impl_->first_hit.clear();
  impl_->scans = 0;
}

double OccupancyMap::resolution() const { return impl_->tree.getResolution(); }

size_t OccupancyMap::memory_bytes() const {
  return impl_->tree.memoryUsage() +
         impl_->first_hit.size() * (sizeof(octomap::OcTreeKey) + sizeof(std::uint32_t) + 16);
}

size_t OccupancyMap::inserted_scans() const { return impl_->scans; }

void OccupancyMap::for_each_voxel(
    const std::function<void(const Eigen::Vector3d&, bool)>& visit) const {
  const octomap::OcTree& tree = impl_->tree;
  const double r = tree.getResolution();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const bool occupied = tree.isNodeOccupied(*it);
    const double size = it.getSize();
    const Eigen::Vector3d centre = to_eigen(it.getCoordinate());
    if (size <= r * 1.5) {
      visit(centre, occupied);
      continue;
    }
    const int n = static_cast<int>(std::lround(size / r));
    const Eigen::Vector3d first = centre - Eigen::Vector3d::Constant(size / 2.0 - r / 2.0);
    for (int x = 0; x < n; ++x)
      for (int y = 0; y < n; ++y)
        for (int z = 0; z < n; ++z) visit(first + Eigen::Vector3d(x, y, z) * r, occupied);
  }
}

std::optional<bool> OccupancyMap::occupied_at(const Eigen::Vector3d& point) const {
  const octomap::OcTreeNode* node = impl_->tree.search(to_octomap(point));
  if (node == nullptr) return std::nullopt;
  return impl_->tree.isNodeOccupied(node);
}

bool OccupancyMap::occupied_near(const Eigen::Vector3d& point) const {
  const double r = impl_->tree.getResolution();
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (occupied_at(point + Eigen::Vector3d(x, y, z) * r).value_or(false)) return true;
  return false;
}

std::vector<Eigen::Vector3d> OccupancyMap::seen_through(
    const std::vector<std::pair<const KeyframeScan*, Pose>>& scans) const {
  const octomap::OcTree& tree = impl_->tree;
  // A ray sees through a voxel when it ends well behind it: rays are cut this far before their
  // reading, so that depth noise at a surface is not taken for a view through it.
  const float margin = static_cast<float>(kSeenThroughMarginVoxels * tree.getResolution());
  std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash> found;
  for (size_t k = 0; k < scans.size(); ++k) {
    KeyframeScan cut;
    for (const Eigen::Vector3f& point : scans[k].first->points) {
      const float range = point.norm();
      if (range > margin) cut.points.push_back(point * ((range - margin) / range));
    }
    octomap::KeySet free_cells, occupied_cells;
    impl_->compute_update(cut, scans[k].second, free_cells, occupied_cells);
    for (const octomap::OcTreeKey& key : free_cells) {
      const auto hit = impl_->first_hit.find(key);
      if (hit == impl_->first_hit.end() || hit->second >= k) continue;
      const octomap::OcTreeNode* node = tree.search(key);
      if (node != nullptr && tree.isNodeOccupied(node)) found.insert(key);
    }
  }
  std::vector<Eigen::Vector3d> centres;
  for (const octomap::OcTreeKey& key : found) centres.push_back(to_eigen(tree.keyToCoord(key)));
  return centres;
}

void OccupancyMap::write_binary(const std::filesystem::path& file) const {
  std::ofstream out(file, std::ios::binary);
  if (!out || !impl_->tree.writeBinaryConst(out) || !out.flush())
    throw Error("cannot write the occupancy map " + file.string());
}

}  // namespace pspslam
