#include "core/progress.h"

#include <mpi.h>
#include <unistd.h>

#include <cstdio>

namespace morphfem {

std::string format_seconds(double s) {
  char buf[32];
  if (s < 0 || s != s) return "--";
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%.1fs", s);
  else if (s < 3600)
    std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
  else
    std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, (int(s) % 3600) / 60);
  return buf;
}

Progress::Progress(std::string label, double total, bool enabled)
    : label_(std::move(label)), total_(total), enabled_(enabled) {
  int rank = 0, init = 0;
  MPI_Initialized(&init);
  if (init) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  enabled_ = enabled_ && rank == 0;
  tty_ = isatty(STDERR_FILENO);
  start_ = last_ = std::chrono::steady_clock::now();
}

void Progress::update(double done, const std::string& info) {
  if (!enabled_) return;
  auto now = std::chrono::steady_clock::now();
  double since_last = std::chrono::duration<double>(now - last_).count();
  // On a terminal redraw at most 10x per second; in a log, one line every 10 s
  // (and nothing at all for runs shorter than that).
  const double elapsed_total = std::chrono::duration<double>(now - start_).count();
  if (!tty_ && elapsed_total < 10.0) return;
  if (since_last < (tty_ ? 0.1 : 10.0) && done < total_) return;
  last_ = now;
  double elapsed = std::chrono::duration<double>(now - start_).count();
  double frac = total_ > 0 ? done / total_ : 1.0;
  const double rate_done = done - resumed_from_;  // work done by this process
  double eta = total_ <= 0 ? 0.0 : rate_done > 1e-9 * total_ ? elapsed * (total_ - done) / rate_done : -1.0;
  const int width = 30;
  int filled = static_cast<int>(frac * width + 0.5);
  std::string bar(std::max(0, std::min(width, filled)), '#');
  bar.resize(width, '.');
  std::fprintf(stderr, "%s%s [%s] %5.1f%% elapsed %s ETA %s %s%s", tty_ ? "\r" : "", label_.c_str(), bar.c_str(),
               100.0 * frac, format_seconds(elapsed).c_str(), format_seconds(eta).c_str(), info.c_str(),
               tty_ ? "\033[K" : "\n");
  std::fflush(stderr);
}

void Progress::finish(const std::string& info) {
  if (!enabled_) return;
  last_ = {};
  update(total_, info);
  if (tty_) std::fprintf(stderr, "\n");
}

}  // namespace morphfem
