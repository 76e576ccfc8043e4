#pragma once

#include <chrono>
#include <cstddef>
#include <iosfwd>
#include <string>

namespace pspslam {

// One-line progress report for long runs: "label [#####.....] 120/400 31.2 fps ETA 9s".
// Redraws at most every 100 ms on a terminal; when the stream is not a terminal (CI logs)
// it prints a plain line every 10% so logs stay short.
class ProgressBar {
 public:
  // `enabled` false (--quiet) draws nothing.
  ProgressBar(std::string label, size_t total, std::ostream& out, bool enabled = true);
  void update(size_t done);
  void finish();

 private:
  void draw(size_t done, bool final_line);

  std::string label_;
  size_t total_;
  std::ostream& out_;
  bool interactive_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  size_t last_decile_ = 0;
  bool enabled_;
  bool finished_ = false;
};

}  // namespace pspslam
