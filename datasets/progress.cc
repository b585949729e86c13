#include "datasets/progress.h"

#include <atomic>

namespace rovo {
namespace {

std::atomic<ProgressSink*> g_sink{nullptr};

}  // namespace

void SetProgressSink(ProgressSink* sink) { g_sink.store(sink); }

Progress::Progress(std::string label, int64_t total, std::string unit, bool quiet)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      sink_(quiet ? nullptr : g_sink.load()),
      start_(std::chrono::steady_clock::now()),
      last_report_(start_) {}

Progress::~Progress() { Finish(); }

void Progress::Add(int64_t n) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ += n;
  Report(false);
}

void Progress::SetDone(int64_t done) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ = done;
  Report(false);
}

void Progress::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  Report(true);
}

void Progress::Report(bool final) {
  if (sink_ == nullptr) return;
  const auto now = std::chrono::steady_clock::now();
  if (!final && std::chrono::duration<double>(now - last_report_).count() < sink_->MinIntervalSeconds()) return;
  last_report_ = now;
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  sink_->Report(ProgressUpdate{label_, unit_, done_, total_, elapsed_s, final});
}

}  // namespace rovo
