#include "progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <ostream>

namespace cohort::app {
namespace {

constexpr int kBarWidth = 24;
constexpr auto kLogInterval = std::chrono::seconds(5);

}  // namespace

ProgressBar::ProgressBar(int total, std::ostream& out, bool interactive)
    : total_(std::max(total, 1)), out_(out), interactive_(interactive) {}

std::string ProgressBar::line() const {
  const int filled = std::min(done_, total_) * kBarWidth / total_;  // a replay of unknown length passes its total
  std::string bar = "[" + std::string(static_cast<size_t>(filled), '#') +
                    std::string(static_cast<size_t>(kBarWidth - filled), '.') + "]";
  const double per_frame = done_ > 0 ? total_ms_ / done_ : 0.0;
  const double eta_s = per_frame * (total_ - done_) / 1000.0;
  char text[128];
  std::snprintf(text, sizeof text, " %d/%d frames  %.1f ms/frame  ETA %.1f s", done_, total_, per_frame, eta_s);
  return bar + text;
}

void ProgressBar::frame_done(double frame_ms) {
  ++done_;
  total_ms_ += frame_ms;
  const auto now = std::chrono::steady_clock::now();
  if (interactive_) {
    out_ << "\r" << line() << std::flush;
  } else if (done_ == total_ || now - last_print_ >= kLogInterval) {
    out_ << line() << "\n" << std::flush;
    last_print_ = now;
  }
}

void ProgressBar::finish() {
  if (interactive_) out_ << "\n" << std::flush;
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) != 0; }

}  // namespace cohort::app
