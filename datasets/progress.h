#pragma once
// Progress reporting for long work: a redrawn bar with rate and ETA on a terminal, plain periodic
// lines otherwise (logs, CI). Thread-safe; writes to stderr.

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace rovo {

class Progress {
 public:
  // total: number of units; unit: e.g. "frames". quiet: print nothing.
  Progress(std::string label, int64_t total, std::string unit = "frames", bool quiet = false);
  ~Progress();
  void Add(int64_t n = 1);     // n more units done
  void SetDone(int64_t done);  // absolute count
  void Finish();               // final line (idempotent)

 private:
  void Print(bool final_line);
  std::string label_, unit_;
  int64_t total_, done_ = 0;
  bool quiet_, tty_, finished_ = false;
  std::chrono::steady_clock::time_point start_, last_print_;
  std::mutex mutex_;
};

}  // namespace rovo
