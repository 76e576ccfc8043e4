#include "pspslam/map/keyframe.h"

#include <algorithm>
#include <limits>
#include <string>

#include "pspslam/core/error.h"
#include "pspslam/map/frame.h"
#include "pspslam/map/map_point.h"
#include "pspslam/place/vocabulary.h"

namespace pspslam {
namespace {

// ORB-SLAM2's covisibility edge threshold: keyframes sharing fewer points are not neighbours.
constexpr int kMinCovisibilityWeight = 15;

// Virtual right coordinate of each keypoint (as Frame computes it), NaN without depth.
std::vector<float> right_coordinates(std::uint64_t frame_id,
                                     const std::vector<cv::KeyPoint>& keypoints,
                                     const cv::Mat& descriptors, const std::vector<float>& depth,
                                     const CameraModel& camera) {
  if (depth.size() != keypoints.size() || descriptors.rows != static_cast<int>(keypoints.size())) {
    throw Error("keyframe of frame " + std::to_string(frame_id) + ": " +
                std::to_string(keypoints.size()) + " keypoints but " +
                std::to_string(depth.size()) + " depths and " + std::to_string(descriptors.rows) +
                " descriptors");
  }
  std::vector<float> right_u(keypoints.size(), std::numeric_limits<float>::quiet_NaN());
  for (size_t i = 0; i < right_u.size(); ++i) {
    if (depth[i] > 0.0f) right_u[i] = keypoints[i].pt.x - static_cast<float>(camera.bf / depth[i]);
  }
  return right_u;
}

}  // namespace

KeyFrame::KeyFrame(std::uint64_t id, const Frame& frame)
    : id_(id),
      frame_id_(frame.id()),
      timestamp_(frame.timestamp()),
      keypoints_(frame.keypoints()),
      descriptors_(frame.descriptors()),
      depth_(frame.depths()),
      right_u_(frame.right_us()),
      camera_(frame.camera_ptr()),
      pyramid_(frame.pyramid_ptr()),
      grid_(frame.grid()),
      T_camera_world_(frame.T_camera_world()),
      T_world_camera_(frame.T_camera_world().inverse()) {
  map_points_.resize(keypoints_.size());
  for (size_t i = 0; i < keypoints_.size(); ++i) {
    if (frame.map_points[i] && !frame.outlier[i]) map_points_[i] = frame.map_points[i];
  }
}

void KeyFrame::compute_bow(const Vocabulary& vocabulary, int direct_index_level) {
  std::lock_guard lock(bow_mutex_);
  if (bow_ready_.load(std::memory_order_relaxed)) return;
  vocabulary.transform(descriptors_, bow_, features_, direct_index_level);
  bow_ready_.store(true, std::memory_order_release);
}

KeyFrame::KeyFrame(std::uint64_t id, KeyFrameData data, std::shared_ptr<const CameraModel> camera,
                   std::shared_ptr<const ScalePyramid> pyramid)
    : id_(id),
      frame_id_(data.frame_id),
      timestamp_(data.timestamp),
      keypoints_(std::move(data.keypoints)),
      descriptors_(std::move(data.descriptors)),
      depth_(std::move(data.depth)),
      right_u_(right_coordinates(data.frame_id, keypoints_, descriptors_, depth_, *camera)),
      camera_(std::move(camera)),
      pyramid_(std::move(pyramid)),
      grid_(keypoints_, camera_->min_x, camera_->max_x, camera_->min_y, camera_->max_y),
      T_camera_world_(data.T_camera_world),
      T_world_camera_(data.T_camera_world.inverse()) {
  map_points_.resize(keypoints_.size());
}

Pose KeyFrame::T_camera_world() const {
  std::lock_guard lock(pose_mutex_);
  return T_camera_world_;
}

Pose KeyFrame::T_world_camera() const {
  std::lock_guard lock(pose_mutex_);
  return T_world_camera_;
}

Eigen::Vector3d KeyFrame::camera_center() const {
  std::lock_guard lock(pose_mutex_);
  return T_world_camera_.translation();
}

void KeyFrame::set_pose(const Pose& T_camera_world) {
  std::lock_guard lock(pose_mutex_);
  T_camera_world_ = T_camera_world;
  T_world_camera_ = T_camera_world.inverse();
}

Eigen::Vector3d KeyFrame::unproject_world(int i) const {
  const cv::Point2f& p = keypoints_[i].pt;
  return T_world_camera() * camera_->pinhole.unproject({p.x, p.y}, depth_[i]);
}

void KeyFrame::add_map_point(int index, const std::shared_ptr<MapPoint>& point) {
  std::lock_guard lock(features_mutex_);
  map_points_[index] = point;
}

void KeyFrame::erase_map_point(int index) {
  std::lock_guard lock(features_mutex_);
  map_points_[index].reset();
}

void KeyFrame::erase_map_point(const MapPoint& point) {
  const int index = point.keypoint_index_in(id_);
  if (index >= 0) erase_map_point(index);
}

void KeyFrame::replace_map_point(int index, const std::shared_ptr<MapPoint>& point) {
  add_map_point(index, point);
}

std::shared_ptr<MapPoint> KeyFrame::map_point(int index) const {
  std::lock_guard lock(features_mutex_);
  auto point = map_points_[index].lock();
  return point && !point->is_bad() ? point : nullptr;
}

std::vector<std::shared_ptr<MapPoint>> KeyFrame::map_points() const {
  std::lock_guard lock(features_mutex_);
  std::vector<std::shared_ptr<MapPoint>> points(map_points_.size());
  for (size_t i = 0; i < map_points_.size(); ++i) {
    auto point = map_points_[i].lock();
    if (point && !point->is_bad()) points[i] = std::move(point);
  }
  return points;
}

int KeyFrame::tracked_map_points(int min_observations) const {
  int count = 0;
  for (const auto& point : map_points()) {
    if (point && point->num_observations() >= min_observations) ++count;
  }
  return count;
}

void KeyFrame::update_connections() {
  // Count shared map points per other keyframe.
  std::map<std::uint64_t, Connection> counts;
  for (const auto& point : map_points()) {
    if (!point) continue;
    point->for_each_observation([&](std::uint64_t kf_id, const MapPoint::Observation& obs) {
      if (kf_id == id_) return;
      Connection& c = counts[kf_id];
      if (c.weight == 0) c.keyframe = obs.keyframe;
      ++c.weight;
    });
  }
  if (counts.empty()) return;

  std::map<std::uint64_t, Connection> kept;
  std::uint64_t best_id = counts.begin()->first;
  int best_weight = 0;
  for (const auto& [kf_id, c] : counts) {
    auto other = c.keyframe.lock();
    if (!other || other->is_bad()) continue;
    if (c.weight > best_weight) {
      best_weight = c.weight;
      best_id = kf_id;
    }
    if (c.weight >= kMinCovisibilityWeight) {
      kept[kf_id] = c;
      other->add_connection(shared_from_this(), c.weight);
    }
  }
  if (best_weight == 0) return;
  // Keep at least the best neighbour so no keyframe is isolated in the graph.
  if (kept.empty()) {
    kept[best_id] = counts[best_id];
    if (auto best = counts[best_id].keyframe.lock()) {
      best->add_connection(shared_from_this(), best_weight);
    }
  }

  std::shared_ptr<KeyFrame> new_parent;
  {
    std::lock_guard lock(connections_mutex_);
    connections_ = std::move(kept);
    update_ordered_connections_locked();
    if (first_connection_ && id_ != 0 && !ordered_connections_.empty()) {
      new_parent = ordered_connections_.front().second.lock();
      if (new_parent) {
        parent_ = new_parent;
        first_connection_ = false;
      }
    }
  }
  if (new_parent) new_parent->add_child(shared_from_this());
}

void KeyFrame::add_connection(const std::shared_ptr<KeyFrame>& other, int weight) {
  std::lock_guard lock(connections_mutex_);
  Connection& c = connections_[other->id()];
  if (c.weight == weight && !c.keyframe.expired()) return;
  c.keyframe = other;
  c.weight = weight;
  update_ordered_connections_locked();
}

void KeyFrame::erase_connection(std::uint64_t other_id) {
  std::lock_guard lock(connections_mutex_);
  if (connections_.erase(other_id) > 0) update_ordered_connections_locked();
}

int KeyFrame::weight(std::uint64_t other_id) const {
  std::lock_guard lock(connections_mutex_);
  auto it = connections_.find(other_id);
  return it == connections_.end() ? 0 : it->second.weight;
}

void KeyFrame::update_ordered_connections_locked() {
  ordered_connections_.clear();
  ordered_connections_.reserve(connections_.size());
  for (const auto& [id, c] : connections_) ordered_connections_.emplace_back(c.weight, c.keyframe);
  // Stable order for equal weights (by id, as inserted) keeps runs deterministic.
  std::stable_sort(ordered_connections_.begin(), ordered_connections_.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
}

std::vector<std::shared_ptr<KeyFrame>> KeyFrame::covisibles() const {
  return best_covisibles(SIZE_MAX);
}

std::vector<std::shared_ptr<KeyFrame>> KeyFrame::best_covisibles(size_t n) const {
  std::lock_guard lock(connections_mutex_);
  std::vector<std::shared_ptr<KeyFrame>> out;
  for (const auto& [weight, weak] : ordered_connections_) {
    if (out.size() >= n) break;
    auto kf = weak.lock();
    if (kf && !kf->is_bad()) out.push_back(std::move(kf));
  }
  return out;
}

std::vector<std::shared_ptr<KeyFrame>> KeyFrame::covisibles_with_min_weight(int min_weight) const {
  std::lock_guard lock(connections_mutex_);
  std::vector<std::shared_ptr<KeyFrame>> out;
  for (const auto& [weight, weak] : ordered_connections_) {
    if (weight < min_weight) break;
    auto kf = weak.lock();
    if (kf && !kf->is_bad()) out.push_back(std::move(kf));
  }
  return out;
}

std::shared_ptr<KeyFrame> KeyFrame::parent() const {
  std::lock_guard lock(connections_mutex_);
  return parent_.lock();
}

std::vector<std::shared_ptr<KeyFrame>> KeyFrame::children() const {
  std::lock_guard lock(connections_mutex_);
  std::vector<std::shared_ptr<KeyFrame>> out;
  for (const auto& [id, weak] : children_) {
    if (auto kf = weak.lock()) out.push_back(std::move(kf));
  }
  return out;
}

void KeyFrame::change_parent(const std::shared_ptr<KeyFrame>& parent) {
  {
    std::lock_guard lock(connections_mutex_);
    parent_ = parent;
    first_connection_ = false;
  }
  parent->add_child(shared_from_this());
}

void KeyFrame::add_child(const std::shared_ptr<KeyFrame>& child) {
  std::lock_guard lock(connections_mutex_);
  children_[child->id()] = child;
}

void KeyFrame::erase_child(std::uint64_t child_id) {
  std::lock_guard lock(connections_mutex_);
  children_.erase(child_id);
}

void KeyFrame::set_bad() {
  if (is_anchor()) return;
  const auto self = shared_from_this();
  for (const auto& other : covisibles()) other->erase_connection(id_);
  for (const auto& point : map_points()) {
    if (point) point->erase_observation(id_);
  }
  std::vector<std::shared_ptr<KeyFrame>> orphans = children();
  std::shared_ptr<KeyFrame> parent;
  {
    std::lock_guard lock(connections_mutex_);
    connections_.clear();
    ordered_connections_.clear();
    children_.clear();
    parent = parent_.lock();
    bad_ = true;
  }
  {
    std::lock_guard lock(features_mutex_);
    for (auto& point : map_points_) point.reset();
  }
  // Re-attach each orphan to the candidate parent (the removed keyframe's parent, or an
  // already re-attached sibling) it shares most points with, as ORB-SLAM2 does.
  std::vector<std::shared_ptr<KeyFrame>> candidates;
  if (parent) candidates.push_back(parent);
  while (!orphans.empty()) {
    int best_weight = -1;
    size_t best_child = 0;
    std::shared_ptr<KeyFrame> best_parent;
    for (size_t c = 0; c < orphans.size(); ++c) {
      for (const auto& candidate : candidates) {
        const int w = orphans[c]->weight(candidate->id());
        if (w > best_weight) {
          best_weight = w;
          best_child = c;
          best_parent = candidate;
        }
      }
    }
    if (!best_parent) break;
    orphans[best_child]->change_parent(best_parent);
    candidates.push_back(orphans[best_child]);
    orphans.erase(orphans.begin() + static_cast<std::ptrdiff_t>(best_child));
  }
  if (parent) {
    for (const auto& orphan : orphans) orphan->change_parent(parent);
    parent->erase_child(id_);
  }
}

bool KeyFrame::is_bad() const { return bad_; }

}  // namespace pspslam
