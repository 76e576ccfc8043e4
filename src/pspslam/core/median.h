#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace pspslam {

// The upper median of `values` (the element at size/2 once sorted; 0 for none), found in linear
// time by reordering `values` in place.
inline double upper_median(std::vector<double>& values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace pspslam
