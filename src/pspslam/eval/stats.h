#pragma once

#include <cstddef>
#include <vector>

namespace pspslam {

// Summary of a list of errors, as the TUM scripts print it (numpy semantics: median averages
// the two middle values of an even count; std is the population standard deviation).
struct ErrorStats {
  size_t count = 0;
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;
  double min = 0.0;
  double max = 0.0;
};

// All fields 0 for an empty list.
ErrorStats compute_error_stats(std::vector<double> values);

}  // namespace pspslam
