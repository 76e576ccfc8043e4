#include <gtest/gtest.h>

#include <cmath>

#include "pspslam/eval/stats.h"

namespace pspslam {
namespace {

TEST(ErrorStats, NumpySemantics) {
  const ErrorStats even = compute_error_stats({4.0, 1.0, 3.0, 2.0});
  EXPECT_EQ(even.count, 4u);
  EXPECT_DOUBLE_EQ(even.mean, 2.5);
  EXPECT_DOUBLE_EQ(even.median, 2.5);           // mean of the two middle values
  EXPECT_DOUBLE_EQ(even.std, std::sqrt(1.25));  // population std (numpy default ddof=0)
  EXPECT_DOUBLE_EQ(even.rmse, std::sqrt(30.0 / 4.0));
  EXPECT_DOUBLE_EQ(even.min, 1.0);
  EXPECT_DOUBLE_EQ(even.max, 4.0);
  const ErrorStats odd = compute_error_stats({5.0, 1.0, 3.0});
  EXPECT_DOUBLE_EQ(odd.median, 3.0);
  const ErrorStats empty = compute_error_stats({});
  EXPECT_EQ(empty.count, 0u);
  EXPECT_EQ(empty.rmse, 0.0);
}

}  // namespace
}  // namespace pspslam
