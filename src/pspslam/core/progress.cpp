#include "pspslam/core/progress.h"

#include <unistd.h>

#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace pspslam {

ProgressBar::ProgressBar(std::string label, size_t total, std::ostream& out, bool enabled)
    : label_(std::move(label)),
      total_(total),
      out_(out),
      interactive_((&out == &std::cerr && isatty(STDERR_FILENO)) ||
                   (&out == &std::cout && isatty(STDOUT_FILENO))),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_),
      enabled_(enabled) {}

void ProgressBar::update(size_t done) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (interactive_) {
    if (now - last_draw_ < std::chrono::milliseconds(100) && done < total_) return;
    last_draw_ = now;
    draw(done, false);
  } else if (total_ > 0) {
    const size_t decile = done * 10 / total_;
    if (decile > last_decile_) {
      last_decile_ = decile;
      draw(done, true);
    }
  }
}

void ProgressBar::finish() {
  if (finished_ || !enabled_) return;
  finished_ = true;
  if (interactive_) {
    draw(total_, false);
    out_ << "\n";
  }
  out_.flush();
}

void ProgressBar::draw(size_t done, bool final_line) {
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
  const double eta = rate > 0 && total_ >= done ? static_cast<double>(total_ - done) / rate : 0.0;
  constexpr int kWidth = 30;
  const int filled = total_ ? static_cast<int>(kWidth * done / total_) : kWidth;
  std::ostringstream line;
  line << label_ << " [" << std::string(filled, '#') << std::string(kWidth - filled, '.') << "] "
       << done << "/" << total_ << " " << std::fixed << std::setprecision(1) << rate << " fps ETA "
       << std::setprecision(0) << eta << "s";
  if (final_line) {
    out_ << line.str() << "\n";
  } else {
    out_ << "\r" << line.str() << "   ";
  }
  out_.flush();
}

}  // namespace pspslam
