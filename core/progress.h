// Progress line with elapsed time and ETA for long runs, written to stderr on
// rank 0 only. Quiet when stderr is not a terminal unless forced (CI logs stay small).
#pragma once
#include <chrono>
#include <string>

namespace morphfem {

class Progress {
 public:
  // `total` is the amount of work in any unit (simulated seconds, load factor, runs).
  Progress(std::string label, double total, bool enabled = true);
  // Report that `done` of `total` is complete; `info` is appended (e.g. "step 12").
  void update(double done, const std::string& info = "");
  void finish(const std::string& info = "");
  // Work already done before this process started (a resumed run): the ETA then
  // extrapolates the rate since the start of this process only.
  void set_resumed_from(double done) { resumed_from_ = done; }

 private:
  std::string label_;
  double total_;
  double resumed_from_ = 0.0;
  bool enabled_;
  bool tty_;
  std::chrono::steady_clock::time_point start_, last_;
};

std::string format_seconds(double s);

}  // namespace morphfem
