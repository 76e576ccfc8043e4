#include "pspslam/place/vocabulary.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <deque>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>

#include "pspslam/core/checksum.h"
#include "pspslam/core/error.h"
#include "pspslam/feature/hamming.h"

// File format, version 1 (all integers little-endian):
//   offset  0  char[8]  magic "PSPVOCAB"
//           8  u32      format version (1)
//          12  u32      branching k
//          16  u32      levels L
//          20  u32      node count
//          24  u32      word count
//          28  u32      training images (informational)
//          32  u64      payload bytes
//          40  u64      FNV-1a 64 of the payload
//          48  payload: u8 child count per node (breadth-first order, node 0 = root),
//                       32-byte centroid per node, f32 IDF weight per word (leaves in node order)
// The tree shape is fully determined by the child counts because children are contiguous in
// breadth-first order, so no child/parent links are stored.

namespace pspslam {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the vocabulary file is little-endian and read by memcpy");

constexpr std::array<char, 8> kMagic = {'P', 'S', 'P', 'V', 'O', 'C', 'A', 'B'};
constexpr std::uint32_t kFormatVersion = 1;
constexpr std::size_t kHeaderBytes = 48;
constexpr std::size_t kDescriptorBytes = kOrbDescriptorBytes;
constexpr WordId kNoWord = std::numeric_limits<WordId>::max();
constexpr int kMaxBranching = 255;  // child counts are stored in one byte
constexpr int kMaxLevels = 10;

template <typename T>
T read_pod(const char* data) {
  T value;
  std::memcpy(&value, data, sizeof(T));
  return value;
}

template <typename T>
void append_pod(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

void check_descriptor_matrix(const cv::Mat& m, const std::string& what) {
  if (m.empty()) return;
  if (m.type() != CV_8UC1 || m.cols != kOrbDescriptorBytes) {
    throw Error("vocabulary: " + what + " must be N x 32 CV_8UC1 ORB descriptors, got " +
                std::to_string(m.rows) + " x " + std::to_string(m.cols) + " of type " +
                std::to_string(m.type()));
  }
}

// Growing tree during training (breadth-first: children appended contiguously).
struct TreeBuilder {
  std::vector<std::uint8_t> descriptors;
  std::vector<std::uint8_t> child_count;

  NodeId add_node(const std::uint8_t* descriptor) {
    const auto id = static_cast<NodeId>(child_count.size());
    descriptors.insert(descriptors.end(), descriptor, descriptor + kDescriptorBytes);
    child_count.push_back(0);
    return id;
  }
};

// k-means over a subset of binary descriptors: k-means++ seeding with Hamming distance (D^2
// sampling), Lloyd iterations with per-bit majority centroids (the binary "mean" that minimises
// the summed Hamming distance bit by bit). Scratch buffers live here so each node's clustering
// reuses them.
class BinaryKMeans {
 public:
  BinaryKMeans(const cv::Mat& data, int k, int max_iterations)
      : data_(data), k_(k), max_iterations_(max_iterations) {}

  // Clusters `members` (row indices of data_); returns the number of non-empty clusters, whose
  // centroids are centers()[c * 32] and members are members_of(c).
  int run(const std::vector<std::uint32_t>& members, std::mt19937_64& rng) {
    seed(members, rng);
    const int k = static_cast<int>(centers_.size() / kDescriptorBytes);
    assignment_.assign(members.size(), -1);
    bool converged = false;
    for (int iteration = 0; iteration < max_iterations_; ++iteration) {
      if (!assign(members, k)) {
        converged = true;
        break;
      }
      update_centers(members, k);
    }
    // Leave the clusters consistent with the centroids the tree stores: a descriptor's subtree is
    // the one whose centroid is nearest, as in the lookup.
    if (!converged) assign(members, k);
    return collect(members, k);
  }

  const std::uint8_t* center(int c) const { return &final_centers_[c * kDescriptorBytes]; }
  const std::vector<std::uint32_t>& members_of(int c) const { return clusters_[c]; }

 private:
  const std::uint8_t* row(std::uint32_t i) const { return data_.ptr<std::uint8_t>(i); }

  void seed(const std::vector<std::uint32_t>& members, std::mt19937_64& rng) {
    centers_.clear();
    std::uniform_int_distribution<std::size_t> pick(0, members.size() - 1);
    const std::uint8_t* first = row(members[pick(rng)]);
    centers_.insert(centers_.end(), first, first + kDescriptorBytes);
    min_distance_.assign(members.size(), std::numeric_limits<double>::max());
    while (static_cast<int>(centers_.size() / kDescriptorBytes) < k_) {
      const std::uint8_t* last = &centers_[centers_.size() - kDescriptorBytes];
      double total = 0.0;
      for (std::size_t i = 0; i < members.size(); ++i) {
        const double d = hamming_distance(row(members[i]), last);
        min_distance_[i] = std::min(min_distance_[i], d * d);
        total += min_distance_[i];
      }
      // Every descriptor equals a chosen centre: fewer distinct points than k.
      if (total <= 0.0) break;
      double target = std::uniform_real_distribution<double>(0.0, total)(rng);
      std::size_t chosen = members.size() - 1;
      for (std::size_t i = 0; i < members.size(); ++i) {
        target -= min_distance_[i];
        if (target <= 0.0 && min_distance_[i] > 0.0) {
          chosen = i;
          break;
        }
      }
      const std::uint8_t* next = row(members[chosen]);
      centers_.insert(centers_.end(), next, next + kDescriptorBytes);
    }
  }

  // Returns whether any assignment changed.
  bool assign(const std::vector<std::uint32_t>& members, int k) {
    bool changed = false;
    for (std::size_t i = 0; i < members.size(); ++i) {
      const std::uint8_t* d = row(members[i]);
      int best = 0;
      int best_distance = hamming_distance(d, &centers_[0]);
      for (int c = 1; c < k; ++c) {
        const int distance = hamming_distance(d, &centers_[c * kDescriptorBytes]);
        if (distance < best_distance) {
          best_distance = distance;
          best = c;
        }
      }
      if (assignment_[i] != best) {
        assignment_[i] = best;
        changed = true;
      }
    }
    return changed;
  }

  void update_centers(const std::vector<std::uint32_t>& members, int k) {
    bit_counts_.assign(static_cast<std::size_t>(k) * kDescriptorBytes * 8, 0);
    sizes_.assign(k, 0);
    for (std::size_t i = 0; i < members.size(); ++i) {
      const int c = assignment_[i];
      ++sizes_[c];
      const std::uint8_t* d = row(members[i]);
      std::uint32_t* counts = &bit_counts_[static_cast<std::size_t>(c) * kDescriptorBytes * 8];
      for (std::size_t byte = 0; byte < kDescriptorBytes; ++byte) {
        const unsigned value = d[byte];
        for (int bit = 0; bit < 8; ++bit) counts[byte * 8 + bit] += (value >> bit) & 1u;
      }
    }
    for (int c = 0; c < k; ++c) {
      if (sizes_[c] == 0) continue;  // an empty cluster keeps its centre (dropped at the end)
      const std::uint32_t* counts =
          &bit_counts_[static_cast<std::size_t>(c) * kDescriptorBytes * 8];
      std::uint8_t* center = &centers_[c * kDescriptorBytes];
      for (std::size_t byte = 0; byte < kDescriptorBytes; ++byte) {
        unsigned value = 0;
        for (int bit = 0; bit < 8; ++bit) {
          if (2 * counts[byte * 8 + bit] > sizes_[c]) value |= 1u << bit;
        }
        center[byte] = static_cast<std::uint8_t>(value);
      }
    }
  }

  int collect(const std::vector<std::uint32_t>& members, int k) {
    std::vector<int> slot(k, -1);
    final_centers_.clear();
    int used = 0;
    for (std::size_t i = 0; i < members.size(); ++i) {
      int& s = slot[assignment_[i]];
      if (s < 0) s = -2;  // mark non-empty, numbered below in centre order
    }
    for (int c = 0; c < k; ++c) {
      if (slot[c] == -2) {
        slot[c] = used++;
        final_centers_.insert(final_centers_.end(), &centers_[c * kDescriptorBytes],
                              &centers_[c * kDescriptorBytes] + kDescriptorBytes);
      }
    }
    clusters_.resize(used);
    for (auto& cluster : clusters_) cluster.clear();
    for (std::size_t i = 0; i < members.size(); ++i) {
      clusters_[slot[assignment_[i]]].push_back(members[i]);
    }
    return used;
  }

  const cv::Mat& data_;
  int k_;
  int max_iterations_;
  std::vector<std::uint8_t> centers_;
  std::vector<std::uint8_t> final_centers_;
  std::vector<double> min_distance_;
  std::vector<int> assignment_;
  std::vector<std::uint32_t> bit_counts_;
  std::vector<std::uint32_t> sizes_;
  std::vector<std::vector<std::uint32_t>> clusters_;
};

}  // namespace

void VocabularyParams::validate() const {
  if (branching < 2 || branching > kMaxBranching) {
    throw Error("vocabulary: --k (branching) must be in 2.." + std::to_string(kMaxBranching) +
                ", got " + std::to_string(branching));
  }
  if (levels < 1 || levels > kMaxLevels) {
    throw Error("vocabulary: --levels must be in 1.." + std::to_string(kMaxLevels) + ", got " +
                std::to_string(levels));
  }
  if (max_iterations < 1) {
    throw Error("vocabulary: k-means iterations must be >= 1, got " +
                std::to_string(max_iterations));
  }
}

Vocabulary Vocabulary::train(const cv::Mat& tree_descriptors, const std::vector<cv::Mat>& images,
                             const VocabularyParams& params, const VocabularyProgress& progress) {
  params.validate();
  check_descriptor_matrix(tree_descriptors, "training descriptors");
  for (const cv::Mat& image : images) check_descriptor_matrix(image, "image descriptors");
  if (tree_descriptors.rows < params.branching) {
    throw Error("vocabulary: need at least k = " + std::to_string(params.branching) +
                " training descriptors, got " + std::to_string(tree_descriptors.rows));
  }
  const cv::Mat data =
      tree_descriptors.isContinuous() ? tree_descriptors : tree_descriptors.clone();

  TreeBuilder tree;
  const std::array<std::uint8_t, kDescriptorBytes> zero{};
  tree.add_node(zero.data());

  struct Pending {
    NodeId node;
    int depth;
    std::vector<std::uint32_t> members;
  };
  std::deque<Pending> queue;
  {
    std::vector<std::uint32_t> all(static_cast<std::size_t>(data.rows));
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
    queue.push_back({0, 0, std::move(all)});
  }
  const std::size_t total = static_cast<std::size_t>(data.rows);
  std::size_t placed = 0;
  BinaryKMeans kmeans(data, params.branching, params.max_iterations);
  // Nodes are processed first-in first-out, so every node's children are appended contiguously
  // and in breadth-first order, which is what the file format relies on.
  while (!queue.empty()) {
    Pending item = std::move(queue.front());
    queue.pop_front();
    const bool can_split = item.depth < params.levels && item.members.size() > 1;
    if (!can_split) {
      placed += item.members.size();
      if (progress) progress("tree", placed, total);
      continue;
    }
    // Each node's clustering draws from its own stream: the tree does not depend on the order
    // in which other nodes consumed random numbers.
    std::mt19937_64 rng(params.seed * 0x9E3779B97F4A7C15ULL + item.node);
    if (item.members.size() <= static_cast<std::size_t>(params.branching)) {
      // Too few descriptors to cluster: each becomes its own leaf (as DBoW2 does).
      tree.child_count[item.node] = static_cast<std::uint8_t>(item.members.size());
      for (const std::uint32_t m : item.members) tree.add_node(data.ptr<std::uint8_t>(m));
      placed += item.members.size();
      if (progress) progress("tree", placed, total);
      continue;
    }
    const int clusters = kmeans.run(item.members, rng);
    if (clusters < 2) {
      // All descriptors identical: splitting further would only add a chain of single children.
      placed += item.members.size();
      if (progress) progress("tree", placed, total);
      continue;
    }
    tree.child_count[item.node] = static_cast<std::uint8_t>(clusters);
    for (int c = 0; c < clusters; ++c) {
      const NodeId child = tree.add_node(kmeans.center(c));
      queue.push_back({child, item.depth + 1, kmeans.members_of(c)});
    }
  }

  Vocabulary vocabulary;
  vocabulary.branching_ = params.branching;
  vocabulary.levels_ = params.levels;
  vocabulary.descriptors_ = std::move(tree.descriptors);
  vocabulary.child_count_ = std::move(tree.child_count);
  const std::string problem = vocabulary.link_tree();
  if (!problem.empty()) throw std::logic_error("vocabulary training built a bad tree: " + problem);

  // IDF over the training images: ln(N / n_w), n_w = images containing word w at least once.
  std::vector<std::uint32_t> images_with_word(vocabulary.word_count(), 0);
  std::vector<std::uint32_t> last_image(vocabulary.word_count(), 0);
  for (std::size_t i = 0; i < images.size(); ++i) {
    const cv::Mat& image = images[i];
    for (int r = 0; r < image.rows; ++r) {
      const WordId w = vocabulary.word(image.ptr<std::uint8_t>(r));
      if (last_image[w] != i + 1) {
        last_image[w] = static_cast<std::uint32_t>(i + 1);
        ++images_with_word[w];
      }
    }
    if (progress) progress("idf", i + 1, images.size());
  }
  vocabulary.training_images_ = static_cast<std::uint32_t>(images.size());
  vocabulary.word_weight_.assign(vocabulary.word_count(), 0.0f);
  for (std::size_t w = 0; w < images_with_word.size(); ++w) {
    if (images_with_word[w] > 0) {
      vocabulary.word_weight_[w] =
          static_cast<float>(std::log(static_cast<double>(images.size()) / images_with_word[w]));
    }
  }
  return vocabulary;
}

std::string Vocabulary::link_tree() {
  const std::size_t nodes = child_count_.size();
  if (nodes == 0) return "no nodes";
  if (descriptors_.size() != nodes * kDescriptorBytes) return "descriptor count != node count";
  first_child_.assign(nodes, 0);
  node_word_.assign(nodes, kNoWord);
  word_node_.clear();
  std::vector<std::uint8_t> depth(nodes, 0);
  std::size_t next = 1;  // id of the first child not yet given to a parent
  for (std::size_t n = 0; n < nodes; ++n) {
    if (n > 0 && n >= next) return "node " + std::to_string(n) + " has no parent";
    const int children = child_count_[n];
    if (children > branching_) {
      return "node " + std::to_string(n) + " has " + std::to_string(children) +
             " children, more than k = " + std::to_string(branching_);
    }
    if (children == 0) {
      node_word_[n] = static_cast<WordId>(word_node_.size());
      word_node_.push_back(static_cast<NodeId>(n));
      continue;
    }
    if (depth[n] >= levels_) {
      return "node " + std::to_string(n) + " at depth " + std::to_string(depth[n]) +
             " has children but L = " + std::to_string(levels_);
    }
    if (next + children > nodes) return "children of node " + std::to_string(n) + " missing";
    first_child_[n] = static_cast<NodeId>(next);
    for (int c = 0; c < children; ++c) depth[next + c] = static_cast<std::uint8_t>(depth[n] + 1);
    next += children;
  }
  if (child_count_[0] == 0) return "the root has no children";
  return {};
}

WordId Vocabulary::word(const std::uint8_t* descriptor) const {
  return word(descriptor, 0, nullptr);
}

NodeId Vocabulary::nearest_child(const std::uint8_t* descriptor, NodeId parent) const {
  const NodeId first = first_child_[parent];
  const NodeId end = first + child_count_[parent];
  NodeId best = first;
  int best_distance = hamming_distance(descriptor, node_descriptor(first));
  for (NodeId child = first + 1; child < end; ++child) {
    const int distance = hamming_distance(descriptor, node_descriptor(child));
    if (distance < best_distance) {
      best_distance = distance;
      best = child;
    }
  }
  return best;
}

WordId Vocabulary::word(const std::uint8_t* descriptor, int node_level, NodeId* node) const {
  NodeId current = 0;
  NodeId at_level = 0;
  int depth = 0;
  while (child_count_[current] != 0) {
    current = nearest_child(descriptor, current);
    if (++depth == node_level) at_level = current;
  }
  if (depth < node_level) at_level = current;  // the word sits above the requested level
  if (node != nullptr) *node = at_level;
  return node_word_[current];
}

namespace {

// Sorts by word, merges repeated words and divides by the L1 norm (TF-IDF: each occurrence adds
// the word's IDF; the normalisation turns counts into term frequencies).
void normalise_bow(BowVector& bow) {
  std::sort(bow.entries.begin(), bow.entries.end(),
            [](const BowEntry& a, const BowEntry& b) { return a.word < b.word; });
  std::size_t out = 0;
  double total = 0.0;
  for (std::size_t i = 0; i < bow.entries.size(); ++i) {
    total += bow.entries[i].weight;
    if (out > 0 && bow.entries[out - 1].word == bow.entries[i].word) {
      bow.entries[out - 1].weight += bow.entries[i].weight;
    } else {
      bow.entries[out++] = bow.entries[i];
    }
  }
  bow.entries.resize(out);
  if (total > 0.0) {
    const auto inverse = static_cast<float>(1.0 / total);
    for (BowEntry& e : bow.entries) e.weight *= inverse;
  }
}

}  // namespace

void Vocabulary::transform(const cv::Mat& descriptors, BowVector& bow) const {
  check_descriptor_matrix(descriptors, "descriptors");
  bow.entries.clear();
  for (int r = 0; r < descriptors.rows; ++r) {
    const WordId w = word(descriptors.ptr<std::uint8_t>(r));
    // Words no training image had carry no information (weight 0) and are left out.
    if (word_weight_[w] > 0.0f) bow.entries.push_back({w, word_weight_[w]});
  }
  normalise_bow(bow);
}

void Vocabulary::transform(const cv::Mat& descriptors, BowVector& bow, FeatureVector& features,
                           int node_level) const {
  check_descriptor_matrix(descriptors, "descriptors");
  if (node_level < 1 || node_level > levels_) {
    throw Error("vocabulary: direct index level must be in 1.." + std::to_string(levels_) +
                ", got " + std::to_string(node_level));
  }
  bow.entries.clear();
  features.clear();
  // (node, feature) pairs packed in one integer sort into node order with ascending features.
  // One scratch allocation per image, none per descriptor.
  std::vector<std::uint64_t> keys;
  keys.reserve(static_cast<std::size_t>(descriptors.rows));
  for (int r = 0; r < descriptors.rows; ++r) {
    NodeId node = 0;
    const WordId w = word(descriptors.ptr<std::uint8_t>(r), node_level, &node);
    if (word_weight_[w] <= 0.0f) continue;
    bow.entries.push_back({w, word_weight_[w]});
    keys.push_back((static_cast<std::uint64_t>(node) << 32) | static_cast<std::uint32_t>(r));
  }
  normalise_bow(bow);
  std::sort(keys.begin(), keys.end());
  features.features_.reserve(keys.size());
  for (const std::uint64_t key : keys) {
    const auto node = static_cast<NodeId>(key >> 32);
    if (features.nodes_.empty() || features.nodes_.back() != node) {
      features.nodes_.push_back(node);
      features.offsets_.push_back(static_cast<std::uint32_t>(features.features_.size()));
    }
    features.features_.push_back(static_cast<int>(key & 0xffffffffu));
  }
  if (!features.nodes_.empty()) {
    features.offsets_.push_back(static_cast<std::uint32_t>(features.features_.size()));
  }
}

void Vocabulary::save(const std::filesystem::path& file) const {
  std::string payload;
  payload.reserve(child_count_.size() * (1 + kDescriptorBytes) + word_weight_.size() * 4);
  payload.append(reinterpret_cast<const char*>(child_count_.data()), child_count_.size());
  payload.append(reinterpret_cast<const char*>(descriptors_.data()), descriptors_.size());
  for (const float w : word_weight_) append_pod(payload, w);

  std::string header(kMagic.begin(), kMagic.end());
  append_pod(header, kFormatVersion);
  append_pod(header, static_cast<std::uint32_t>(branching_));
  append_pod(header, static_cast<std::uint32_t>(levels_));
  append_pod(header, static_cast<std::uint32_t>(node_count()));
  append_pod(header, static_cast<std::uint32_t>(word_count()));
  append_pod(header, training_images_);
  append_pod(header, static_cast<std::uint64_t>(payload.size()));
  append_pod(header, fnv1a64(payload.data(), payload.size()));

  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw Error("vocabulary file '" + file.string() + "': cannot open for writing");
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(payload.data(), static_cast<std::streamsize>(payload.size()));
  out.close();
  if (!out) throw Error("vocabulary file '" + file.string() + "': write failed");
}

Vocabulary Vocabulary::load(const std::filesystem::path& file) {
  const std::string prefix = "vocabulary file '" + file.string() + "': ";
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(prefix + "cannot open for reading");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());

  if (bytes.size() >= kMagic.size() && !std::equal(kMagic.begin(), kMagic.end(), bytes.begin())) {
    throw Error(prefix + "not a pspslam vocabulary (bad magic, expected \"PSPVOCAB\")");
  }
  if (bytes.size() < kHeaderBytes) {
    throw Error(prefix + "truncated (the header needs " + std::to_string(kHeaderBytes) +
                " bytes, the file has " + std::to_string(bytes.size()) + ")");
  }
  const char* h = bytes.data();
  const auto version = read_pod<std::uint32_t>(h + 8);
  if (version != kFormatVersion) {
    throw Error(prefix + "unsupported format version " + std::to_string(version) +
                " (this build reads version " + std::to_string(kFormatVersion) + ")");
  }
  const auto branching = read_pod<std::uint32_t>(h + 12);
  const auto levels = read_pod<std::uint32_t>(h + 16);
  const auto nodes = read_pod<std::uint32_t>(h + 20);
  const auto words = read_pod<std::uint32_t>(h + 24);
  const auto training_images = read_pod<std::uint32_t>(h + 28);
  const auto payload_bytes = read_pod<std::uint64_t>(h + 32);
  const auto stored_checksum = read_pod<std::uint64_t>(h + 40);
  if (branching < 2 || branching > kMaxBranching || levels < 1 || levels > kMaxLevels ||
      nodes < 2 || words < 1 || words >= nodes) {
    throw Error(prefix + "invalid header (k = " + std::to_string(branching) +
                ", L = " + std::to_string(levels) + ", nodes = " + std::to_string(nodes) +
                ", words = " + std::to_string(words) + ")");
  }
  const std::uint64_t expected_payload =
      static_cast<std::uint64_t>(nodes) * (1 + kDescriptorBytes) +
      static_cast<std::uint64_t>(words) * sizeof(float);
  if (payload_bytes != expected_payload) {
    throw Error(prefix + "invalid header (payload size " + std::to_string(payload_bytes) +
                " does not match " + std::to_string(nodes) + " nodes and " + std::to_string(words) +
                " words: expected " + std::to_string(expected_payload) + ")");
  }
  const std::uint64_t expected_size = kHeaderBytes + payload_bytes;
  if (bytes.size() < expected_size) {
    throw Error(prefix + "truncated (expected " + std::to_string(expected_size) +
                " bytes, the file has " + std::to_string(bytes.size()) + ")");
  }
  if (bytes.size() > expected_size) {
    throw Error(prefix + "unexpected " + std::to_string(bytes.size() - expected_size) +
                " trailing bytes after the payload (expected " + std::to_string(expected_size) +
                " bytes)");
  }
  const char* payload = h + kHeaderBytes;
  const std::uint64_t checksum = fnv1a64(payload, payload_bytes);
  if (checksum != stored_checksum) {
    throw Error(prefix + "checksum mismatch (stored " + hex64(stored_checksum) + ", computed " +
                hex64(checksum) + "): the file is corrupt");
  }

  Vocabulary vocabulary;
  vocabulary.branching_ = static_cast<int>(branching);
  vocabulary.levels_ = static_cast<int>(levels);
  vocabulary.training_images_ = training_images;
  vocabulary.child_count_.assign(payload, payload + nodes);
  vocabulary.descriptors_.assign(payload + nodes, payload + nodes + nodes * kDescriptorBytes);
  const std::string problem = vocabulary.link_tree();
  if (!problem.empty()) throw Error(prefix + "inconsistent tree (" + problem + ")");
  if (vocabulary.word_node_.size() != words) {
    throw Error(prefix + "inconsistent tree (" + std::to_string(vocabulary.word_node_.size()) +
                " leaves, header says " + std::to_string(words) + " words)");
  }
  vocabulary.word_weight_.resize(words);
  std::memcpy(vocabulary.word_weight_.data(), payload + nodes * (1 + kDescriptorBytes),
              words * sizeof(float));
  return vocabulary;
}

}  // namespace pspslam
