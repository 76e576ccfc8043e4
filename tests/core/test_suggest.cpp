#include <gtest/gtest.h>

#include "pspslam/core/suggest.h"

namespace pspslam {
namespace {

TEST(Suggest, EditDistanceCountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(edit_distance("width", "width"), 0u);
  EXPECT_EQ(edit_distance("widht", "width"), 2u);  // a swap is two substitutions
  EXPECT_EQ(edit_distance("fxx", "fx"), 1u);
  EXPECT_EQ(edit_distance("", "abc"), 3u);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
}

TEST(Suggest, NearestIsATypoNotAnyName) {
  const std::vector<std::string> keys = {"width", "height", "fx", "fy", "depth_factor"};
  EXPECT_EQ(nearest("widht", keys), "width");
  EXPECT_EQ(nearest("depth_facter", keys), "depth_factor");
  EXPECT_EQ(nearest("fxx", keys), "fx");
  EXPECT_EQ(nearest("x", keys), std::nullopt);       // 1 edit from fx, but half the name
  EXPECT_EQ(nearest("colour", keys), std::nullopt);  // nothing close
  EXPECT_EQ(nearest("width", keys), std::nullopt);   // not a typo: the key itself
  EXPECT_EQ(nearest("--plots", {"--plot", "--gt"}), "--plot");
}

}  // namespace
}  // namespace pspslam
