#include "pspslam/place/bow_matching.h"

#include <algorithm>
#include <limits>

#include "pspslam/feature/hamming.h"

namespace pspslam {

void match_by_bow(const FeatureVector& query_features, const cv::Mat& query_descriptors,
                  std::span<const std::uint8_t> query_usable, const FeatureVector& train_features,
                  const cv::Mat& train_descriptors, std::span<const std::uint8_t> train_usable,
                  const BowMatchOptions& options, std::vector<BowMatch>& matches) {
  matches.clear();
  const auto usable = [](std::span<const std::uint8_t> flags, int i) {
    return flags.empty() || flags[static_cast<std::size_t>(i)] != 0;
  };
  // Both node lists are ascending: walk them like a merge.
  const std::vector<NodeId>& query_nodes = query_features.nodes();
  const std::vector<NodeId>& train_nodes = train_features.nodes();
  std::size_t qi = 0;
  std::size_t ti = 0;
  while (qi < query_nodes.size() && ti < train_nodes.size()) {
    if (query_nodes[qi] < train_nodes[ti]) {
      ++qi;
      continue;
    }
    if (train_nodes[ti] < query_nodes[qi]) {
      ++ti;
      continue;
    }
    const std::span<const int> train_in_node = train_features.features(ti);
    for (const int q : query_features.features(qi)) {
      if (!usable(query_usable, q)) continue;
      const std::uint8_t* query_descriptor = query_descriptors.ptr<std::uint8_t>(q);
      int best = std::numeric_limits<int>::max();
      int second = std::numeric_limits<int>::max();
      int best_train = -1;
      for (const int t : train_in_node) {
        if (!usable(train_usable, t)) continue;
        const int d = hamming_distance(query_descriptor, train_descriptors.ptr<std::uint8_t>(t));
        if (d < best) {
          second = best;
          best = d;
          best_train = t;
        } else if (d < second) {
          second = d;
        }
      }
      if (best_train < 0 || best > options.max_distance) continue;
      if (second != std::numeric_limits<int>::max() &&
          static_cast<double>(best) >= options.ratio * static_cast<double>(second)) {
        continue;
      }
      matches.push_back({q, best_train, best});
    }
    ++qi;
    ++ti;
  }
  // One match per train descriptor: keep the closest.
  std::sort(matches.begin(), matches.end(), [](const BowMatch& a, const BowMatch& b) {
    if (a.train != b.train) return a.train < b.train;
    if (a.distance != b.distance) return a.distance < b.distance;
    return a.query < b.query;
  });
  const auto last =
      std::unique(matches.begin(), matches.end(),
                  [](const BowMatch& a, const BowMatch& b) { return a.train == b.train; });
  matches.erase(last, matches.end());
  std::sort(matches.begin(), matches.end(),
            [](const BowMatch& a, const BowMatch& b) { return a.query < b.query; });
}

}  // namespace pspslam
