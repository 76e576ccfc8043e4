#include "pspslam/tracking/local_map.h"

#include <algorithm>
#include <unordered_map>

#include "pspslam/map/frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map_point.h"

namespace pspslam {

void LocalMap::add_keyframe(const std::shared_ptr<KeyFrame>& keyframe, std::uint64_t frame_id) {
  if (!keyframe || keyframe->is_bad() || keyframe->track_reference_frame == frame_id) return;
  keyframe->track_reference_frame = frame_id;
  keyframes_.push_back(keyframe);
}

std::shared_ptr<KeyFrame> LocalMap::update(const Frame& frame) {
  const std::uint64_t frame_id = frame.id();
  // Votes: how many of the frame's matches each keyframe observes.
  std::unordered_map<std::uint64_t, std::pair<std::shared_ptr<KeyFrame>, int>> votes;
  for (int i = 0; i < frame.size(); ++i) {
    const auto& point = frame.map_points[i];
    if (!point || frame.outlier[i] || point->is_bad()) continue;
    point->for_each_observation([&](std::uint64_t kf_id, const MapPoint::Observation& obs) {
      auto& vote = votes[kf_id];
      if (!vote.first) vote.first = obs.keyframe.lock();
      ++vote.second;
    });
  }
  keyframes_.clear();
  std::shared_ptr<KeyFrame> reference;
  int best = 0;
  counts_.clear();
  for (auto& [id, vote] : votes) {
    if (!vote.first || vote.first->is_bad()) continue;
    counts_.emplace_back(vote.first, vote.second);
  }
  // Deterministic order: most shared points first, ties by keyframe id.
  std::sort(counts_.begin(), counts_.end(), [](const auto& a, const auto& b) {
    return a.second != b.second ? a.second > b.second : a.first->id() < b.first->id();
  });
  for (const auto& [kf, count] : counts_) {
    if (count > best) {
      best = count;
      reference = kf;
    }
    add_keyframe(kf, frame_id);
  }
  // Neighbours of the voting keyframes, while under the size limit.
  const size_t voters = keyframes_.size();
  for (size_t k = 0; k < voters && keyframes_.size() < max_keyframes_; ++k) {
    const std::shared_ptr<KeyFrame> kf = keyframes_[k];
    for (const auto& neighbour : kf->best_covisibles(10)) {
      if (neighbour->track_reference_frame != frame_id) {
        add_keyframe(neighbour, frame_id);
        break;
      }
    }
    for (const auto& child : kf->children()) {
      if (child->track_reference_frame != frame_id) {
        add_keyframe(child, frame_id);
        break;
      }
    }
    add_keyframe(kf->parent(), frame_id);
  }

  points_.clear();
  for (const auto& kf : keyframes_) {
    for (const auto& point : kf->map_points()) {
      if (!point || point->track_reference_frame == frame_id) continue;
      point->track_reference_frame = frame_id;
      points_.push_back(point);
    }
  }
  return reference;
}

}  // namespace pspslam
