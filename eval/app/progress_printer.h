#pragma once
// How `rovo` shows the libraries' progress (datasets/progress.h) on stderr: a redrawn bar with rate and
// ETA on a terminal (at most 10 redraws/s), plain periodic lines otherwise (logs, CI: one every 5 s).

#include "datasets/progress.h"

namespace rovo {

class ProgressPrinter : public ProgressSink {
 public:
  ProgressPrinter();
  double MinIntervalSeconds() const override;
  void Report(const ProgressUpdate& update) override;

 private:
  bool tty_;
};

}  // namespace rovo
