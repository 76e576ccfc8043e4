#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace pspslam {

// Index of a leaf of the vocabulary tree (a visual word), 0 .. Vocabulary::word_count()-1.
using WordId = std::uint32_t;
// Index of any node of the vocabulary tree (breadth-first order, 0 = root).
using NodeId = std::uint32_t;

struct BowEntry {
  WordId word = 0;
  float weight = 0.0f;
};

// Bag-of-words vector of one image: TF-IDF weights of the words it contains, sorted by word id
// with one entry per word, L1-normalised (weights sum to 1) when built by Vocabulary::transform.
// A sorted vector instead of a map: scoring is a linear merge and a reused vector does not
// allocate.
struct BowVector {
  std::vector<BowEntry> entries;

  bool empty() const { return entries.empty(); }
  std::size_t size() const { return entries.size(); }
  void clear() { entries.clear(); }
};

// Direct index of one image: for every tree node at a chosen level that one of its descriptors
// descends through, the indices of those descriptors (ascending). Guided matching compares only
// descriptors that share a node. Stored flat (CSR) so building one does not allocate per node.
class FeatureVector {
 public:
  std::size_t node_count() const { return nodes_.size(); }
  bool empty() const { return nodes_.empty(); }
  // Node ids, ascending.
  const std::vector<NodeId>& nodes() const { return nodes_; }
  // Descriptor (keypoint) indices of the i-th node of nodes(), ascending.
  std::span<const int> features(std::size_t i) const {
    return {features_.data() + offsets_[i], features_.data() + offsets_[i + 1]};
  }
  void clear() {
    nodes_.clear();
    offsets_.clear();
    features_.clear();
  }

 private:
  friend class Vocabulary;
  std::vector<NodeId> nodes_;
  std::vector<std::uint32_t> offsets_;  // nodes_.size() + 1 entries when not empty
  std::vector<int> features_;
};

// DBoW's L1 score s(v, w) = 1 - 1/2 * || v/|v| - w/|w| ||_1, in [0, 1]: 1 for identical word
// histograms, 0 for images without a common word. For non-negative weights it equals the sum
// over common words of min(v_i/|v|, w_i/|w|), which needs only the common words.
double bow_score(const BowVector& a, const BowVector& b);

}  // namespace pspslam
