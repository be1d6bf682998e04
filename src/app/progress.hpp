// Progress of a simulate run: a live line rewritten with \r on a terminal, a short line every ~5% of the run
// otherwise, one JSON object per frame on stdout with `--progress json`, or nothing with --quiet.
#pragma once

#include <string>

#include "app/console.hpp"
#include "app/frame_report.hpp"

namespace arcsim {

enum class ProgressStyle { kLive, kLines, kJson, kQuiet };

// --progress json wins over --quiet (a caller that asked for JSON wants it); otherwise quiet, then the terminal
// decides.
ProgressStyle choose_progress_style(bool quiet, bool json, bool err_is_terminal);

class Progress {
 public:
  Progress(ProgressStyle style, const Console& console, double total_frames);

  void frame_done(const FrameReport& report);
  // Ends a live line, so that a following message starts on a line of its own.
  void end_line();
  // The closing line on stderr ("done: ..."), except in the JSON and quiet styles.
  void summary(int frames, double simulated_time, const std::string& out_dir);

 private:
  std::string status(const FrameReport& report) const;

  ProgressStyle style_;
  const Console& console_;
  double total_frames_;
  int frames_done_ = 0;
  double wall_sum_ = 0;       // s, over the frames reported so far
  long long cracks_ = 0;      // cracks opened over the frames reported so far
  size_t live_width_ = 0;     // characters of the live line on screen
  long long last_bucket_ = -1;  // last 5% bucket printed in the lines style
};

// "12.3 s", "4m05s" or "2h03m": a duration for people.
std::string format_duration(double seconds);

}  // namespace arcsim
