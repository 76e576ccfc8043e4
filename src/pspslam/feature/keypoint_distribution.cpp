#include "pspslam/feature/keypoint_distribution.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace pspslam {
namespace {

// Nodes narrower than this are not split further: keypoints sit on integer pixel positions, so a
// smaller node can hold at most one and splitting it would only spin.
constexpr float kMinNodeSize = 1.0f;

}  // namespace

bool QuadtreeDistributor::can_split(const Node& node) const {
  return node.count() > 1 &&
         (node.max_x - node.min_x > kMinNodeSize || node.max_y - node.min_y > kMinNodeSize);
}

int QuadtreeDistributor::split(const Node& node, std::span<const cv::KeyPoint> candidates,
                               Node* children) {
  const float mid_x = 0.5f * (node.min_x + node.max_x);
  const float mid_y = 0.5f * (node.min_y + node.max_y);
  const auto first = candidate_order_.begin() + node.begin;
  const auto last = candidate_order_.begin() + node.end;
  const auto left_of = [&](int index) { return candidates[index].pt.x < mid_x; };
  const auto above = [&](int index) { return candidates[index].pt.y < mid_y; };
  const auto mid_column = std::partition(first, last, left_of);
  const auto left_mid_row = std::partition(first, mid_column, above);
  const auto right_mid_row = std::partition(mid_column, last, above);

  const auto offset = [this](auto iterator) {
    return static_cast<int>(iterator - candidate_order_.begin());
  };
  const Node quadrants[4] = {
      {node.min_x, node.min_y, mid_x, mid_y, node.begin, offset(left_mid_row)},
      {node.min_x, mid_y, mid_x, node.max_y, offset(left_mid_row), offset(mid_column)},
      {mid_x, node.min_y, node.max_x, mid_y, offset(mid_column), offset(right_mid_row)},
      {mid_x, mid_y, node.max_x, node.max_y, offset(right_mid_row), node.end},
  };
  int n_children = 0;
  for (const Node& quadrant : quadrants) {
    if (quadrant.count() > 0) children[n_children++] = quadrant;
  }
  return n_children;
}

void QuadtreeDistributor::distribute(std::span<const cv::KeyPoint> candidates,
                                     const cv::Rect2f& area, int target,
                                     std::vector<cv::KeyPoint>& selected) {
  selected.clear();
  if (target <= 0 || candidates.empty()) return;
  const int n_candidates = static_cast<int>(candidates.size());
  if (n_candidates <= target) {
    selected.assign(candidates.begin(), candidates.end());
    return;
  }

  candidate_order_.resize(n_candidates);
  std::iota(candidate_order_.begin(), candidate_order_.end(), 0);

  // Root nodes are roughly square (a 640x480 level gets one root, a very wide image several) so
  // that the quadrants stay roughly square too.
  const int n_roots = std::max(1, static_cast<int>(std::lround(area.width / area.height)));
  const float root_width = area.width / static_cast<float>(n_roots);
  nodes_.clear();
  auto root_begin = candidate_order_.begin();
  for (int root = 0; root < n_roots; ++root) {
    const float min_x = area.x + root_width * static_cast<float>(root);
    const float max_x = root == n_roots - 1 ? area.x + area.width : min_x + root_width;
    const auto root_end = root == n_roots - 1
                              ? candidate_order_.end()
                              : std::partition(root_begin, candidate_order_.end(), [&](int index) {
                                  return candidates[index].pt.x < max_x;
                                });
    const Node root_node{min_x,
                         area.y,
                         max_x,
                         area.y + area.height,
                         static_cast<int>(root_begin - candidate_order_.begin()),
                         static_cast<int>(root_end - candidate_order_.begin())};
    if (root_node.count() > 0) nodes_.push_back(root_node);
    root_begin = root_end;
  }

  Node children[4];
  while (static_cast<int>(nodes_.size()) < target) {
    split_order_.clear();
    for (int i = 0; i < static_cast<int>(nodes_.size()); ++i) {
      if (can_split(nodes_[i])) split_order_.push_back(i);
    }
    if (split_order_.empty()) break;

    const int n_nodes = static_cast<int>(nodes_.size());
    const int n_splittable = static_cast<int>(split_order_.size());
    if (n_nodes + 3 * n_splittable < target) {
      // Far from the target: split every node (one full quadtree level).
      next_nodes_.clear();
      for (const Node& node : nodes_) {
        if (!can_split(node)) {
          next_nodes_.push_back(node);
          continue;
        }
        const int n_children = split(node, candidates, children);
        next_nodes_.insert(next_nodes_.end(), children, children + n_children);
      }
      nodes_.swap(next_nodes_);
      continue;
    }

    // Close to the target: split the most crowded nodes first and stop as soon as it is reached,
    // so that the spread is refined where the keypoints are dense.
    std::stable_sort(split_order_.begin(), split_order_.end(),
                     [this](int a, int b) { return nodes_[a].count() > nodes_[b].count(); });
    for (const int node_index : split_order_) {
      const int n_children = split(nodes_[node_index], candidates, children);
      nodes_[node_index] = children[0];
      nodes_.insert(nodes_.end(), children + 1, children + n_children);
      if (static_cast<int>(nodes_.size()) >= target) break;
    }
  }

  // One keypoint per node: the strongest (lowest candidate index on ties, for determinism).
  for (const Node& node : nodes_) {
    int best = candidate_order_[node.begin];
    for (int i = node.begin + 1; i < node.end; ++i) {
      const int index = candidate_order_[i];
      const float response = candidates[index].response;
      if (response > candidates[best].response ||
          (response == candidates[best].response && index < best)) {
        best = index;
      }
    }
    selected.push_back(candidates[best]);
  }
  // The last split may overshoot by up to 3 nodes: drop the weakest to hit the target exactly.
  if (static_cast<int>(selected.size()) > target) {
    std::nth_element(
        selected.begin(), selected.begin() + target, selected.end(),
        [](const cv::KeyPoint& a, const cv::KeyPoint& b) { return a.response > b.response; });
    selected.resize(target);
  }
}

void share_feature_budget(std::span<const int> shares, std::span<const int> available,
                          std::span<int> budgets) {
  const std::size_t n = shares.size();
  int spare = 0;
  for (std::size_t l = 0; l < n; ++l) {
    budgets[l] = std::min(shares[l], std::max(0, available[l]));
    spare += shares[l] - budgets[l];
  }
  while (spare > 0) {
    // Weights: the original shares (at least 1, so a level with a zero share can still absorb),
    // of the levels that can take more.
    long long weight = 0;
    for (std::size_t l = 0; l < n; ++l) {
      if (available[l] > budgets[l]) weight += std::max(1, shares[l]);
    }
    if (weight == 0) break;
    int given = 0;
    for (std::size_t l = 0; l < n; ++l) {
      const int room = available[l] - budgets[l];
      if (room <= 0) continue;
      const auto proportional =
          static_cast<int>(static_cast<long long>(spare) * std::max(1, shares[l]) / weight);
      const int add = std::min(room, proportional);
      budgets[l] += add;
      given += add;
    }
    if (given == 0) {
      // Every proportional part rounded to 0: hand out the remainder one by one, finest level
      // first (it has the most candidates).
      for (std::size_t l = 0; l < n && given < spare; ++l) {
        if (available[l] > budgets[l]) {
          ++budgets[l];
          ++given;
        }
      }
    }
    spare -= given;
  }
}

}  // namespace pspslam
