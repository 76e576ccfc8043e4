#include "pspslam/core/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace pspslam {

ProgressBar::ProgressBar(std::string label, size_t total, std::ostream& out, bool enabled,
                         bool realtime_feed)
    : label_(std::move(label)),
      total_(total),
      out_(out),
      interactive_((&out == &std::cerr && isatty(STDERR_FILENO)) ||
                   (&out == &std::cout && isatty(STDOUT_FILENO))),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_),
      enabled_(enabled),
      realtime_feed_(realtime_feed) {}

void ProgressBar::update(size_t processed, size_t dropped) {
  if (!enabled_) return;
  processed_ = processed;
  dropped_ = dropped;
  const size_t done = processed + dropped;
  const auto now = std::chrono::steady_clock::now();
  if (interactive_) {
    if (now - last_draw_ < std::chrono::milliseconds(100) && done < total_) return;
    last_draw_ = now;
    draw(false);
  } else if (total_ > 0) {
    const size_t decile = done * 10 / total_;
    if (decile > last_decile_) {
      last_decile_ = decile;
      draw(true);
    }
  }
}

void ProgressBar::finish() {
  if (finished_ || !enabled_) return;
  finished_ = true;
  if (interactive_) {
    // A deterministic run that stops early (Ctrl-C) still ends its bar full, as it always did;
    // a real-time line keeps its true counts.
    if (!realtime_feed_) processed_ = std::max(processed_, total_);
    draw(false);
    out_ << "\n";
  }
  out_.flush();
}

void ProgressBar::draw(bool final_line) {
  const size_t done = std::min(total_, processed_ + dropped_);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  // Frames handled per second: for a real-time feed the processed ones, the others are skipped.
  const double rate = elapsed > 0 ? static_cast<double>(processed_) / elapsed : 0.0;
  // Time left follows the feed (it runs at the sequence's rate whatever the system keeps up with).
  const double feed_rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
  const double eta =
      feed_rate > 0 && total_ >= done ? static_cast<double>(total_ - done) / feed_rate : 0.0;
  constexpr int kWidth = 30;
  const int filled = total_ ? static_cast<int>(kWidth * done / total_) : kWidth;
  std::ostringstream line;
  line << label_ << " [" << std::string(filled, '#') << std::string(kWidth - filled, '.') << "] "
       << done << "/" << total_;
  if (realtime_feed_) line << " fed, " << processed_ << " processed, " << dropped_ << " dropped";
  line << " " << std::fixed << std::setprecision(1) << rate << " fps ETA " << std::setprecision(0)
       << eta << "s";
  if (final_line) {
    out_ << line.str() << "\n";
  } else {
    out_ << "\r" << line.str() << "   ";
  }
  out_.flush();
}

}  // namespace pspslam
