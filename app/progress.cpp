#include "app/progress.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace pvrr::app {

double Progress::steadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::FILE* Progress::terminal() { return isatty(2) ? stderr : nullptr; }

int Progress::alive_ = 0;

Progress::Progress(std::string label, double total, std::FILE* out, Clock clock)
    : label_(std::move(label)),
      total_(total > 0 ? total : 1),
      out_(alive_ > 0 ? nullptr : out),
      clock_(std::move(clock)),
      start_(clock_()) {
  ++alive_;
}

Progress::~Progress() {
  finish();
  --alive_;
}

std::optional<double> Progress::secondsLeft(double done) const {
  if (!(done > 0)) return std::nullopt;
  return elapsed() * std::max(0.0, total_ - done) / done;
}

std::string Progress::duration(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char buf[48];
  if (s < 60) std::snprintf(buf, sizeof buf, "%ld s", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%ld min %02ld s", s / 60, s % 60);
  else std::snprintf(buf, sizeof buf, "%ld h %02ld min", s / 3600, (s % 3600) / 60);
  return buf;
}

std::string Progress::line(double done) const {
  constexpr int kBar = 20;
  const double share = std::clamp(done / total_, 0.0, 1.0);
  const int filled = int(kBar * share);
  std::string s = label_ + ": [" + std::string(size_t(filled), '#') + std::string(size_t(kBar - filled), ' ') + "] ";
  char buf[96];
  // Whole units as a count ("5/12"), a fraction (total 1) as a percentage only.
  if (total_ > 1 && total_ == std::floor(total_)) {
    std::snprintf(buf, sizeof buf, "%.0f/%.0f  ", std::floor(done), total_);
    s += buf;
  }
  std::snprintf(buf, sizeof buf, "%3d%%  ", int(100 * share));
  s += buf + duration(elapsed());
  const auto left = secondsLeft(done);
  s += left ? ", about " + duration(*left) + " left" : ", estimating";
  return s;
}

void Progress::update(double done) {
  if (!out_ || finished_) return;
  const double now = clock_();
  const bool last = done >= total_;
  if (now - start_ < kShowAfterSeconds || (!last && now - last_draw_ < kRedrawSeconds)) return;
  last_draw_ = now;
  // Padded so that a shorter line covers the longer one before it.
  std::fprintf(out_, "\r%-79s", line(done).c_str());
  std::fflush(out_);
  shown_ = true;
}

void Progress::clear() {
  if (!out_ || !shown_ || finished_) return;
  std::fprintf(out_, "\r%79s\r", "");
  std::fflush(out_);
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  if (!out_ || !shown_) return;
  std::fprintf(out_, "\r%-79s\n", (label_ + ": done in " + duration(elapsed())).c_str());
  std::fflush(out_);
}

}  // namespace pvrr::app
