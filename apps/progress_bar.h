// A progress line on stderr for long headless renders: frames done, milliseconds per frame, ETA.
// On a terminal it redraws one line; otherwise (logs, CI) it prints a line at most every few seconds.
#pragma once

#include <chrono>
#include <iosfwd>
#include <string>

namespace cohort::app {

class ProgressBar {
 public:
  ProgressBar(int total, std::ostream& out, bool interactive);
  // After each frame: its wall time in milliseconds.
  void frame_done(double frame_ms);
  void finish();
  // The text of the line now, e.g. "[#####.....] 5/10 frames  12.5 ms/frame  ETA 0.1 s".
  std::string line() const;

 private:
  int total_;
  int done_ = 0;
  double total_ms_ = 0.0;
  std::ostream& out_;
  bool interactive_;
  std::chrono::steady_clock::time_point last_print_{};
};

// Whether stderr is a terminal (the bar redraws in place only there).
bool stderr_is_terminal();

}  // namespace cohort::app
