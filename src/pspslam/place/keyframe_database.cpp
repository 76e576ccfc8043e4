#include "pspslam/place/keyframe_database.h"

#include <algorithm>
#include <string>
#include <unordered_set>

#include "pspslam/core/error.h"

namespace pspslam {

KeyFrameDatabase::KeyFrameDatabase(std::size_t word_count)
    : word_count_(word_count), inverse_index_(word_count) {}

void KeyFrameDatabase::add(KeyFrameId id, const BowVector& bow) {
  for (const BowEntry& e : bow.entries) {
    if (e.word >= word_count_) {
      throw Error("keyframe database: keyframe " + std::to_string(id) + " has word " +
                  std::to_string(e.word) + " but the vocabulary has " +
                  std::to_string(word_count_) + " words (BoW vector from another vocabulary?)");
    }
  }
  std::unique_lock lock(mutex_);
  auto existing = keyframes_.find(id);
  if (existing != keyframes_.end()) {
    for (const BowEntry& e : existing->second.entries) {
      std::erase(inverse_index_[e.word], id);
    }
    existing->second = bow;
  } else {
    keyframes_.emplace(id, bow);
  }
  for (const BowEntry& e : bow.entries) inverse_index_[e.word].push_back(id);
}

bool KeyFrameDatabase::erase(KeyFrameId id) {
  std::unique_lock lock(mutex_);
  auto it = keyframes_.find(id);
  if (it == keyframes_.end()) return false;
  for (const BowEntry& e : it->second.entries) std::erase(inverse_index_[e.word], id);
  keyframes_.erase(it);
  return true;
}

void KeyFrameDatabase::clear() {
  std::unique_lock lock(mutex_);
  for (auto& list : inverse_index_) list.clear();
  keyframes_.clear();
}

std::size_t KeyFrameDatabase::size() const {
  std::shared_lock lock(mutex_);
  return keyframes_.size();
}

bool KeyFrameDatabase::contains(KeyFrameId id) const {
  std::shared_lock lock(mutex_);
  return keyframes_.contains(id);
}

std::vector<KeyFrameDatabase::Scored> KeyFrameDatabase::score_candidates(
    const BowVector& bow, const PlaceQueryOptions& options) const {
  const std::unordered_set<KeyFrameId> excluded(options.excluded.begin(), options.excluded.end());
  std::shared_lock lock(mutex_);
  std::unordered_map<KeyFrameId, std::uint32_t> common;
  for (const BowEntry& e : bow.entries) {
    if (e.word >= word_count_) continue;  // cannot share a word the database has no list for
    for (const KeyFrameId id : inverse_index_[e.word]) {
      if (!excluded.contains(id)) ++common[id];
    }
  }
  std::uint32_t max_common = 0;
  for (const auto& [id, n] : common) max_common = std::max(max_common, n);
  const double min_common = options.min_common_ratio * max_common;

  std::vector<Scored> scored;
  for (const auto& [id, n] : common) {
    if (n < min_common) continue;
    const double score = bow_score(bow, keyframes_.at(id));
    if (score >= options.min_score) scored.push_back({id, n, score});
  }
  return scored;
}

std::vector<PlaceCandidate> KeyFrameDatabase::query(const BowVector& bow,
                                                    const CovisibilityFn& covisible,
                                                    const PlaceQueryOptions& options) const {
  const std::vector<Scored> scored = score_candidates(bow, options);
  if (scored.empty()) return {};
  std::unordered_map<KeyFrameId, const Scored*> by_id;
  for (const Scored& s : scored) by_id.emplace(s.id, &s);

  // Group scores (step 3) are computed without the lock: the callback may take map locks.
  std::vector<PlaceCandidate> groups;
  groups.reserve(scored.size());
  double best_group = 0.0;
  for (const Scored& s : scored) {
    PlaceCandidate group{s.id, s.score, s.score, s.common_words};
    if (covisible) {
      std::vector<KeyFrameId> neighbours = covisible(s.id);
      if (neighbours.size() > static_cast<std::size_t>(std::max(options.group_size, 0))) {
        neighbours.resize(static_cast<std::size_t>(std::max(options.group_size, 0)));
      }
      for (const KeyFrameId n : neighbours) {
        auto it = by_id.find(n);
        if (it == by_id.end() || n == s.id) continue;
        group.group_score += it->second->score;
        if (it->second->score > group.score) {
          group.id = n;
          group.score = it->second->score;
          group.common_words = it->second->common_words;
        }
      }
    }
    best_group = std::max(best_group, group.group_score);
    groups.push_back(group);
  }

  const double retain = options.retain_ratio * best_group;
  std::sort(groups.begin(), groups.end(), [](const PlaceCandidate& a, const PlaceCandidate& b) {
    if (a.group_score != b.group_score) return a.group_score > b.group_score;
    if (a.score != b.score) return a.score > b.score;
    return a.id < b.id;
  });
  std::vector<PlaceCandidate> result;
  std::unordered_set<KeyFrameId> returned;
  for (const PlaceCandidate& g : groups) {
    if (g.group_score < retain) break;
    if (returned.insert(g.id).second) result.push_back(g);
  }
  return result;
}

std::vector<PlaceCandidate> KeyFrameDatabase::score_all(const BowVector& bow) const {
  std::shared_lock lock(mutex_);
  std::vector<PlaceCandidate> result;
  result.reserve(keyframes_.size());
  for (const auto& [id, kf_bow] : keyframes_) {
    const double score = bow_score(bow, kf_bow);
    result.push_back({id, score, score, 0});
  }
  std::sort(result.begin(), result.end(), [](const PlaceCandidate& a, const PlaceCandidate& b) {
    if (a.score != b.score) return a.score > b.score;
    return a.id < b.id;
  });
  return result;
}

}  // namespace pspslam
