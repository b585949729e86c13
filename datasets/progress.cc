#include "datasets/progress.h"

#include <unistd.h>

#include <cstdio>

namespace rovo {

Progress::Progress(std::string label, int64_t total, std::string unit, bool quiet)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      quiet_(quiet),
      tty_(::isatty(2) != 0),
      start_(std::chrono::steady_clock::now()),
      last_print_(start_) {}

Progress::~Progress() { Finish(); }

void Progress::Add(int64_t n) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ += n;
  Print(false);
}

void Progress::SetDone(int64_t done) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ = done;
  Print(false);
}

void Progress::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  Print(true);
}

void Progress::Print(bool final_line) {
  if (quiet_) return;
  const auto now = std::chrono::steady_clock::now();
  const double since_last = std::chrono::duration<double>(now - last_print_).count();
  // Terminal: redraw at most 10 times/s. Logs: a line every 5 s.
  if (!final_line && since_last < (tty_ ? 0.1 : 5.0)) return;
  last_print_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed > 0 ? done_ / elapsed : 0.0;
  const double eta = rate > 0 ? (total_ - done_) / rate : 0.0;
  const double frac = total_ > 0 ? static_cast<double>(done_) / total_ : 1.0;
  char line[256];
  if (tty_) {
    const int width = 28;
    const int filled = static_cast<int>(frac * width + 0.5);
    std::string bar(static_cast<size_t>(filled), '#');
    bar.resize(width, '.');
    std::snprintf(line, sizeof(line), "\r%s [%s] %lld/%lld %s  %.2f %s/s  ETA %.0fs   ", label_.c_str(), bar.c_str(),
                  static_cast<long long>(done_), static_cast<long long>(total_), unit_.c_str(), rate, unit_.c_str(),
                  eta);
    std::fputs(line, stderr);
    if (final_line) std::fputs("\n", stderr);
  } else {
    std::snprintf(line, sizeof(line), "%s: %lld/%lld %s (%.0f%%), %.2f %s/s, %s %.0fs\n", label_.c_str(),
                  static_cast<long long>(done_), static_cast<long long>(total_), unit_.c_str(), 100.0 * frac, rate,
                  unit_.c_str(), final_line ? "elapsed" : "ETA", final_line ? elapsed : eta);
    std::fputs(line, stderr);
  }
  std::fflush(stderr);
}

}  // namespace rovo
