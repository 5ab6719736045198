// Progress of a long command on the terminal: a line on stderr, rewritten in place, with the share done and an
// estimate of the time left ("sweep: [#######       ] 5/12  42%  8 s, about 11 s left"). Quiet when stderr
// is not a terminal (logs, pipes, tests) and for work that ends within the first second. A Progress made
// while another is alive (the reference render inside a sweep) stays quiet: the outer one owns the line.
#pragma once
#include <cstdio>
#include <functional>
#include <optional>
#include <string>

namespace pvrr::app {

class Progress {
 public:
  // Seconds on a monotonic clock; tests pass a fake one.
  using Clock = std::function<double()>;
  static double steadySeconds();
  // stderr when it is a terminal, else nullptr (quiet).
  static std::FILE* terminal();

  // `label` names the work ("sweep"), `total` > 0 its units (frames, stages; 1 for a fraction). `out`
  // nullptr: nothing is printed, the arithmetic still works.
  Progress(std::string label, double total, std::FILE* out = terminal(), Clock clock = steadySeconds);
  ~Progress();  // finish()
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // `done` units of `total` are done. Prints when a second has passed since the start and at most every
  // kRedrawSeconds, and always the last unit.
  void update(double done);
  // Ends the line (when one was shown) with the elapsed time.
  void finish();
  // Erases the line (until the next update) before the command prints its own lines to a terminal.
  void clear();

  // The estimate: the time so far, scaled by what is left over what is done (a steady rate); none before
  // the first unit is done.
  std::optional<double> secondsLeft(double done) const;
  double elapsed() const { return clock_() - start_; }
  // The line update() prints for `done`, without the leading '\r'.
  std::string line(double done) const;
  // "42 s", "3 min 05 s", "1 h 02 min".
  static std::string duration(double seconds);

  static constexpr double kShowAfterSeconds = 1.0, kRedrawSeconds = 0.25;

 private:
  std::string label_;
  double total_;
  std::FILE* out_;
  Clock clock_;
  double start_, last_draw_ = -1e300;
  bool shown_ = false, finished_ = false;
  static int alive_;  // Progress objects alive now (commands run on one thread)
};

}  // namespace pvrr::app
