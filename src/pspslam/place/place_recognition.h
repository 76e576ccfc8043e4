#pragma once

#include <filesystem>
#include <memory>

#include "pspslam/place/keyframe_database.h"
#include "pspslam/place/vocabulary.h"

namespace pspslam {

// The vocabulary shipped with the project (models/vocabulary/, see its README for how to
// rebuild it), resolved against the source directory like the other default models.
std::filesystem::path default_vocabulary_path();

// What relocalisation and loop closing share: the vocabulary (immutable) and the keyframe
// database over it. Owned by System (shared_ptr), lent to local mapping (which indexes each
// keyframe it processes and removes culled ones), tracking (relocalisation queries) and loop
// closing. Thread-safe: the vocabulary is const, the database locks internally.
class PlaceRecognition {
 public:
  // Level of the direct index (FeatureVector) that guided matching groups descriptors by:
  // nodes at depth 2 of a k=10 tree (<= 100 nodes), as ORB-SLAM2's "levelsup 4" of its 6-level
  // tree. Deeper nodes split true matches apart, shallower ones compare too many pairs.
  static constexpr int kDirectIndexLevel = 2;

  explicit PlaceRecognition(std::shared_ptr<const Vocabulary> vocabulary);
  // Loads the vocabulary; throws pspslam::Error naming the file when missing or corrupt.
  static std::shared_ptr<PlaceRecognition> load(const std::filesystem::path& vocabulary_file);

  const Vocabulary& vocabulary() const { return *vocabulary_; }
  KeyFrameDatabase& database() { return database_; }
  const KeyFrameDatabase& database() const { return database_; }
  int direct_index_level() const { return direct_index_level_; }

 private:
  std::shared_ptr<const Vocabulary> vocabulary_;
  int direct_index_level_;
  KeyFrameDatabase database_;
};

}  // namespace pspslam
