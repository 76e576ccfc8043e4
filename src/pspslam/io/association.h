#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "pspslam/core/types.h"

namespace pspslam {

// One associated pair: indices into the `first` and `second` timestamp lists.
struct TimestampMatch {
  size_t first = 0;
  size_t second = 0;
};

// Default of the TUM tools (associate.py, evaluate_ate.py): 20 ms.
inline constexpr double kDefaultMaxTimeDifference = 0.02;

// Associates two timestamp lists exactly as TUM's associate.py does:
//  - candidates are all pairs with |a - (b + offset)| < max_difference,
//  - taken greedily by increasing difference (ties by a, then b), each element used at most once,
//  - the result is sorted by the first list's timestamp.
// Inputs need not be sorted; timestamps within one list must be distinct.
// Runs in O((n + m) log(n + m) + k log k) for k candidates instead of associate.py's O(n m).
std::vector<TimestampMatch> associate_timestamps(std::span<const Timestamp> first,
                                                 std::span<const Timestamp> second,
                                                 double max_difference = kDefaultMaxTimeDifference,
                                                 double offset = 0.0);

}  // namespace pspslam
