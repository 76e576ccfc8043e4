#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pspslam/place/bow_vector.h"

namespace pspslam {

struct VocabularyParams {
  int branching = 10;  // k: children per node
  int levels = 5;      // L: depth of the tree below the root; at most k^L words
  // Lloyd iterations per node; k-means stops earlier once no assignment changes.
  int max_iterations = 10;
  std::uint64_t seed = 1;  // k-means++ seeding: same seed and input, same vocabulary

  // Throws pspslam::Error naming the flag (--k, --levels) for unusable values.
  void validate() const;
};

// Progress of training: `stage` is "tree" (done/total = descriptors placed in leaves) or "idf"
// (done/total = images).
using VocabularyProgress =
    std::function<void(const std::string& stage, std::size_t done, std::size_t total)>;

// Visual vocabulary over 256-bit ORB descriptors (DBoW2-style): a tree built by hierarchical
// k-means (k-means++ seeding with Hamming distance, per-bit majority centroids), whose leaves are
// the words, weighted by IDF over the training images.
//
// Immutable after training/loading: all const methods are safe to call from many threads.
class Vocabulary {
 public:
  // Trains on `tree_descriptors` (N x 32 CV_8UC1, e.g. a random subsample of all descriptors)
  // and computes IDF over `images` (one descriptor matrix per training image): idf(w) =
  // ln(images / images containing w); words no image contains get weight 0.
  // Throws pspslam::Error for invalid params, no descriptors or a wrong matrix type.
  static Vocabulary train(const cv::Mat& tree_descriptors, const std::vector<cv::Mat>& images,
                          const VocabularyParams& params,
                          const VocabularyProgress& progress = nullptr);

  // Binary file (format in vocabulary.cpp). load() throws pspslam::Error naming the file and
  // what is wrong: missing, bad magic, wrong version, truncated, checksum mismatch, inconsistent.
  void save(const std::filesystem::path& file) const;
  static Vocabulary load(const std::filesystem::path& file);

  // The word a descriptor (32 bytes) falls into: descends the tree choosing the child with the
  // smallest Hamming distance (first child on ties). No allocation.
  WordId word(const std::uint8_t* descriptor) const;
  // Same, and also the node the descent passed at depth `node_level` (1 = child of the root; a
  // leaf above that depth is its own node). For the direct index.
  WordId word(const std::uint8_t* descriptor, int node_level, NodeId* node) const;

  // BoW vector (TF-IDF, L1-normalised) of a descriptor matrix (rows x 32, CV_8UC1). `bow` is
  // overwritten and keeps its capacity.
  void transform(const cv::Mat& descriptors, BowVector& bow) const;
  // Same plus the direct index at depth `node_level` (1..levels(); ORB-SLAM2's "levelsup 4" of
  // a 6-level tree corresponds to node_level 2).
  void transform(const cv::Mat& descriptors, BowVector& bow, FeatureVector& features,
                 int node_level) const;

  int branching() const { return branching_; }
  int levels() const { return levels_; }
  std::size_t node_count() const { return child_count_.size(); }
  std::size_t word_count() const { return word_node_.size(); }
  float word_weight(WordId word) const { return word_weight_[word]; }
  NodeId word_node(WordId word) const { return word_node_[word]; }
  // 32-byte centroid of a node (the root's is all zero and never compared).
  const std::uint8_t* node_descriptor(NodeId node) const { return &descriptors_[node * 32u]; }
  // Children of a node: first_child(n) .. first_child(n) + child_count(n) - 1 (contiguous in
  // breadth-first order); a node without children is a word.
  NodeId first_child(NodeId node) const { return first_child_[node]; }
  int child_count(NodeId node) const { return child_count_[node]; }
  std::uint32_t training_images() const { return training_images_; }

 private:
  // The child of `parent` whose centroid is nearest (Hamming) to the descriptor.
  NodeId nearest_child(const std::uint8_t* descriptor, NodeId parent) const;
  Vocabulary() = default;
  // Derives first_child_, leaf word ids and depths from child_count_ (breadth-first order).
  // Returns an empty string when consistent, else what is wrong.
  std::string link_tree();

  int branching_ = 0;
  int levels_ = 0;
  std::uint32_t training_images_ = 0;
  std::vector<std::uint8_t> descriptors_;  // node_count x 32
  std::vector<std::uint8_t> child_count_;  // per node
  std::vector<NodeId> first_child_;        // per node (0 for leaves)
  std::vector<WordId> node_word_;          // per node: word id of a leaf, kNoWord otherwise
  std::vector<NodeId> word_node_;          // per word
  std::vector<float> word_weight_;         // per word: IDF
};

}  // namespace pspslam
