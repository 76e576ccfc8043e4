#include "pspslam/io/association.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

namespace pspslam {

std::vector<TimestampMatch> associate_timestamps(std::span<const Timestamp> first,
                                                 std::span<const Timestamp> second,
                                                 double max_difference, double offset) {
  std::vector<size_t> second_sorted(second.size());
  std::iota(second_sorted.begin(), second_sorted.end(), size_t{0});
  std::sort(second_sorted.begin(), second_sorted.end(),
            [&](size_t l, size_t r) { return second[l] < second[r]; });

  struct Candidate {
    double difference;
    size_t first;
    size_t second;
  };
  std::vector<Candidate> candidates;
  // The window search is only a pre-filter (widened by a small margin against rounding);
  // the acceptance test below is associate.py's exact expression.
  const double margin = 1e-9 * (1.0 + std::abs(max_difference));
  for (size_t a = 0; a < first.size(); ++a) {
    const double low = first[a] - offset - max_difference - margin;
    auto it = std::lower_bound(second_sorted.begin(), second_sorted.end(), low,
                               [&](size_t index, double value) { return second[index] < value; });
    for (; it != second_sorted.end(); ++it) {
      const double b = second[*it];
      if (b - margin > first[a] - offset + max_difference) break;
      const double difference = std::abs(first[a] - (b + offset));
      if (difference < max_difference) candidates.push_back({difference, a, *it});
    }
  }
  // Python sorts (difference, a, b) tuples: ties broken by the timestamps themselves.
  std::sort(candidates.begin(), candidates.end(), [&](const Candidate& l, const Candidate& r) {
    return std::make_tuple(l.difference, first[l.first], second[l.second]) <
           std::make_tuple(r.difference, first[r.first], second[r.second]);
  });

  std::vector<bool> first_used(first.size(), false);
  std::vector<bool> second_used(second.size(), false);
  std::vector<TimestampMatch> matches;
  for (const Candidate& c : candidates) {
    if (first_used[c.first] || second_used[c.second]) continue;
    first_used[c.first] = true;
    second_used[c.second] = true;
    matches.push_back({c.first, c.second});
  }
  std::sort(matches.begin(), matches.end(), [&](const TimestampMatch& l, const TimestampMatch& r) {
    return std::make_tuple(first[l.first], second[l.second]) <
           std::make_tuple(first[r.first], second[r.second]);
  });
  return matches;
}

}  // namespace pspslam
