#pragma once

#include <chrono>
#include <cstddef>
#include <iosfwd>
#include <string>

namespace pspslam {

// One-line progress report for long runs: "label [#####.....] 120/400 31.2 fps ETA 9s".
// Redraws at most every 100 ms on a terminal; when the stream is not a terminal (CI logs)
// it prints a plain line every 10% so logs stay short.
//
// A real-time feed (`pspslam run --realtime`) skips the frames whose time passed while the
// system was busy, so counting processed frames would stop short of the total ("90/150" at the
// end). With `realtime_feed` the bar follows the frames *fed* (processed + dropped) and the line
// names all three: "label [#####] 150/150 fed, 90 processed, 60 dropped 19.0 fps ETA 0s"
// (fps = processed frames per second).
class ProgressBar {
 public:
  // `enabled` false (--quiet) draws nothing.
  ProgressBar(std::string label, size_t total, std::ostream& out, bool enabled = true,
              bool realtime_feed = false);
  void update(size_t processed, size_t dropped = 0);
  void finish();

 private:
  void draw(bool final_line);

  std::string label_;
  size_t total_;
  std::ostream& out_;
  bool interactive_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  size_t last_decile_ = 0;
  bool enabled_;
  bool realtime_feed_;
  size_t processed_ = 0;
  size_t dropped_ = 0;
  bool finished_ = false;
};

}  // namespace pspslam
