#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <shared_mutex>
#include <unordered_map>
#include <vector>

#include "pspslam/place/bow_vector.h"

namespace pspslam {

// Same id as KeyFrame::id(); the database does not know map/ classes.
using KeyFrameId = std::uint64_t;

// The keyframes covisible with a keyframe, best first (ORB-SLAM2: GetBestCovisibilityKeyFrames).
// The query uses at most QueryOptions::group_size of them. Called without the database lock
// held, so it may lock the map.
using CovisibilityFn = std::function<std::vector<KeyFrameId>(KeyFrameId)>;

struct PlaceQueryOptions {
  // Keyframes never returned and not counted (loop closing: the query keyframe and its
  // covisible neighbours; relocalisation: none).
  std::vector<KeyFrameId> excluded;
  // Candidates scoring below this are dropped (loop closing: the lowest score between the
  // query keyframe and its covisible neighbours; relocalisation: 0).
  double min_score = 0.0;
  // Keyframes need at least min_common_ratio * (most words any keyframe shares) common words.
  double min_common_ratio = 0.8;
  // Neighbours (from the covisibility callback) whose scores add up to a candidate's group.
  int group_size = 10;
  // Groups scoring at least retain_ratio * best group score are returned.
  double retain_ratio = 0.75;
};

struct PlaceCandidate {
  KeyFrameId id = 0;         // best-scoring keyframe of its covisibility group
  double score = 0.0;        // bow_score(query, id)
  double group_score = 0.0;  // accumulated score of the group
  std::uint32_t common_words = 0;
};

// Inverse index (word -> keyframes containing it) over the keyframes' BoW vectors, with
// ORB-SLAM2's candidate selection for relocalisation and loop closing. Thread-safe: queries
// share a lock, add/erase take it exclusively.
class KeyFrameDatabase {
 public:
  // word_count: Vocabulary::word_count() of the vocabulary that made the BoW vectors.
  explicit KeyFrameDatabase(std::size_t word_count);

  // Adds (or replaces) a keyframe. Throws pspslam::Error for a word id >= word_count.
  void add(KeyFrameId id, const BowVector& bow);
  // Returns false when the id was not in the database.
  bool erase(KeyFrameId id);
  void clear();
  std::size_t size() const;
  bool contains(KeyFrameId id) const;

  // Candidates for a query BoW vector, best group first (ORB-SLAM2 DetectLoopCandidates /
  // DetectRelocalizationCandidates):
  //  1. keyframes sharing words with the query (not excluded) and their common-word counts;
  //  2. keep those with >= min_common_ratio * max common words, score them, drop < min_score;
  //  3. for each kept keyframe, its group = itself + its first group_size covisible neighbours;
  //     the group score sums the scores of members kept in step 2, the group's representative
  //     is its best-scoring member;
  //  4. return the representatives of groups scoring >= retain_ratio * best group, each once.
  // `covisible` may be empty: then every group is the keyframe alone.
  std::vector<PlaceCandidate> query(const BowVector& bow, const CovisibilityFn& covisible,
                                    const PlaceQueryOptions& options = {}) const;

  // Every keyframe with its score, best first, without the common-word filter or grouping
  // (diagnostics and tests).
  std::vector<PlaceCandidate> score_all(const BowVector& bow) const;

 private:
  struct Scored {
    KeyFrameId id;
    std::uint32_t common_words;
    double score;
  };
  // Steps 1-2 under the shared lock.
  std::vector<Scored> score_candidates(const BowVector& bow,
                                       const PlaceQueryOptions& options) const;

  mutable std::shared_mutex mutex_;
  std::size_t word_count_;
  std::vector<std::vector<KeyFrameId>> inverse_index_;  // per word
  std::unordered_map<KeyFrameId, BowVector> keyframes_;
};

}  // namespace pspslam
