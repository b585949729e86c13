#pragma once
// Progress of long work (frames rendered, frames tracked, runs done). The libraries report it; how it is
// shown is the application's choice: `rovo` installs a terminal printer (eval/app/progress_printer.h).
// With no sink installed nothing is shown. Thread-safe.

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace rovo {

// One report of a Progress to the sink.
struct ProgressUpdate {
  const std::string& label;
  const std::string& unit;  // e.g. "frames"
  int64_t done = 0;
  int64_t total = 0;
  double elapsed_s = 0.0;
  bool final = false;  // the last report of this Progress
};

class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  // Least time between two non-final reports of one Progress (the sink's redraw rate).
  virtual double MinIntervalSeconds() const = 0;
  virtual void Report(const ProgressUpdate& update) = 0;
};

// Installs the process's sink (not owned; nullptr: nothing is shown). Set it before work starts.
void SetProgressSink(ProgressSink* sink);

class Progress {
 public:
  // total: number of units; unit: e.g. "frames". quiet: report nothing.
  Progress(std::string label, int64_t total, std::string unit = "frames", bool quiet = false);
  ~Progress();
  void Add(int64_t n = 1);     // n more units done
  void SetDone(int64_t done);  // absolute count
  void Finish();               // final report (idempotent)

 private:
  void Report(bool final);
  std::string label_, unit_;
  int64_t total_, done_ = 0;
  bool finished_ = false;
  ProgressSink* sink_;  // nullptr: quiet or no sink installed
  std::chrono::steady_clock::time_point start_, last_report_;
  std::mutex mutex_;
};

}  // namespace rovo
