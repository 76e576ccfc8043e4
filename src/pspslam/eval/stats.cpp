#include "pspslam/eval/stats.h"

#include <algorithm>
#include <cmath>

namespace pspslam {

ErrorStats compute_error_stats(std::vector<double> values) {
  ErrorStats stats;
  stats.count = values.size();
  if (values.empty()) return stats;
  const double n = static_cast<double>(values.size());
  double sum = 0.0;
  double sum_squares = 0.0;
  for (const double v : values) {
    sum += v;
    sum_squares += v * v;
  }
  stats.rmse = std::sqrt(sum_squares / n);
  stats.mean = sum / n;
  double squared_deviation = 0.0;  // two-pass, like numpy.std, for accuracy
  for (const double v : values) squared_deviation += (v - stats.mean) * (v - stats.mean);
  stats.std = std::sqrt(squared_deviation / n);
  std::sort(values.begin(), values.end());
  stats.min = values.front();
  stats.max = values.back();
  const size_t half = values.size() / 2;
  stats.median = values.size() % 2 == 1 ? values[half] : 0.5 * (values[half - 1] + values[half]);
  return stats;
}

}  // namespace pspslam
