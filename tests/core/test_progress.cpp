#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "pspslam/core/progress.h"

namespace pspslam {
namespace {

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// A real-time run of 150 frames that processed 90 and dropped 60 ends at "150/150", not at
// "90/150", and says how many frames were processed and dropped.
TEST(ProgressBar, RealtimeFeedCountsFramesFedProcessedAndDropped) {
  std::ostringstream out;  // not a terminal: one plain line per tenth of the frames fed
  ProgressBar bar("slam", 150, out, true, true);
  size_t processed = 0, dropped = 0;
  for (size_t fed = 1; fed <= 150; ++fed) {
    // Three of every five frames fed are processed, two are skipped.
    if (fed % 5 < 3) {
      ++processed;
    } else {
      ++dropped;
    }
    bar.update(processed, dropped);
  }
  bar.finish();
  ASSERT_EQ(processed, 90u);
  const std::vector<std::string> lines = lines_of(out.str());
  ASSERT_EQ(lines.size(), 10u) << out.str();
  EXPECT_EQ(lines.back().rfind("slam [##############################] 150/150 fed, 90 processed, "
                               "60 dropped ",
                               0),
            0u)
      << lines.back();
  EXPECT_EQ(lines.front().rfind("slam [###...........................] 15/150 fed, 9 processed, "
                                "6 dropped ",
                                0),
            0u)
      << lines.front();
}

TEST(ProgressBar, DeterministicRunsCountProcessedFramesOnly) {
  std::ostringstream out;
  ProgressBar bar("slam", 40, out);
  for (size_t done = 1; done <= 40; ++done) bar.update(done);
  bar.finish();
  const std::vector<std::string> lines = lines_of(out.str());
  ASSERT_EQ(lines.size(), 10u) << out.str();
  EXPECT_EQ(lines.back().rfind("slam [##############################] 40/40 ", 0), 0u)
      << lines.back();
  EXPECT_EQ(out.str().find("dropped"), std::string::npos) << out.str();
}

TEST(ProgressBar, QuietDrawsNothing) {
  std::ostringstream out;
  ProgressBar bar("slam", 10, out, false, true);
  for (size_t done = 1; done <= 10; ++done) bar.update(done, 1);
  bar.finish();
  EXPECT_TRUE(out.str().empty()) << out.str();
}

}  // namespace
}  // namespace pspslam
