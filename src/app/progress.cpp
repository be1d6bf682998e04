#include "app/progress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>

namespace arcsim {

namespace {

// Frames between two progress lines when the run has no end (no percentage to go by).
constexpr int kUnboundedLineEvery = 100;

}  // namespace

ProgressStyle choose_progress_style(bool quiet, bool json, bool err_is_terminal) {
  if (json) return ProgressStyle::kJson;
  if (quiet) return ProgressStyle::kQuiet;
  return err_is_terminal ? ProgressStyle::kLive : ProgressStyle::kLines;
}

std::string format_duration(double seconds) {
  char buffer[64];
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  if (seconds < 60) {
    std::snprintf(buffer, sizeof buffer, "%.1f s", seconds);
  } else if (seconds < 3600) {
    const long s = std::lround(seconds);
    std::snprintf(buffer, sizeof buffer, "%ldm%02lds", s / 60, s % 60);
  } else {
    const long m = std::lround(seconds / 60);
    std::snprintf(buffer, sizeof buffer, "%ldh%02ldm", m / 60, m % 60);
  }
  return buffer;
}

Progress::Progress(ProgressStyle style, const Console& console, double total_frames)
    : style_(style), console_(console), total_frames_(total_frames) {}

std::string Progress::status(const FrameReport& r) const {
  const bool bounded = std::isfinite(total_frames_);
  const double per_frame = frames_done_ > 0 ? wall_sum_ / frames_done_ : 0;
  char buffer[256];
  std::string total = bounded ? std::to_string(static_cast<long long>(total_frames_)) : "?";
  std::snprintf(buffer, sizeof buffer, "frame %d/%s  t = %.4g s  %lld faces  %.3g s/frame", r.frame,
                total.c_str(), r.time, r.faces, per_frame);
  std::string text = buffer;
  if (r.has_fracture) text += "  " + std::to_string(cracks_) + " cracks";
  if (r.has_time_step && r.substep_level > 0) {
    std::snprintf(buffer, sizeof buffer, "  step /%d", 1 << std::min(r.substep_level, 30));
    text += buffer;
  }
  if (r.has_time_step && r.held_steps > 0) text += "  " + std::to_string(r.held_steps) + " held";
  if (bounded) text += "  ETA " + format_duration(per_frame * std::max(0.0, total_frames_ - r.frame));
  return text;
}

void Progress::frame_done(const FrameReport& r) {
  ++frames_done_;
  wall_sum_ += r.wall.total;
  cracks_ += r.has_fracture ? r.fracture.cracks : 0;
  switch (style_) {
    case ProgressStyle::kQuiet:
      return;
    case ProgressStyle::kJson:
      console_.out << progress_json_line(r, total_frames_) << '\n' << std::flush;
      return;
    case ProgressStyle::kLive: {
      std::string text = status(r);
      const size_t width = text.size();
      if (width < live_width_) text.append(live_width_ - width, ' ');  // wipe the rest of a longer line
      live_width_ = width;
      console_.err << '\r' << text << std::flush;
      return;
    }
    case ProgressStyle::kLines: {
      const bool bounded = std::isfinite(total_frames_) && total_frames_ > 0;
      const long long bucket = bounded ? static_cast<long long>(std::floor(20.0 * r.frame / total_frames_))
                                       : r.frame / kUnboundedLineEvery;
      if (bucket == last_bucket_) return;
      last_bucket_ = bucket;
      console_.err << status(r) << '\n' << std::flush;
      return;
    }
  }
}

void Progress::end_line() {
  if (style_ == ProgressStyle::kLive && live_width_ > 0) {
    console_.err << '\n' << std::flush;
    live_width_ = 0;
  }
}

void Progress::summary(int frames, double simulated_time, const std::string& out_dir) {
  end_line();
  if (style_ == ProgressStyle::kQuiet || style_ == ProgressStyle::kJson) return;
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "done: %d frames, %.4g s simulated in %s", frames, simulated_time,
                format_duration(wall_sum_).c_str());
  console_.err << buffer << (out_dir.empty() ? " (dry run, nothing written)" : "; output in " + out_dir)
               << '\n'
               << std::flush;
}

}  // namespace arcsim
