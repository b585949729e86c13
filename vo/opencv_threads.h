#pragma once
// ScopedOpenCvThreads: OpenCV serial (cv::setNumThreads(1), process-wide) while any holder lives, the
// caller's setting restored when the last one goes. Every vo step that calls OpenCV's parallel
// functions (the front-end, the start-up calibration, the lateral colour correction) holds one: a set-and-restore per
// call races with another VO run in the same process. The views already run in parallel under TBB
// (docs/design-notes.md).

#include <mutex>
#include <opencv2/core.hpp>

namespace rovo {

class ScopedOpenCvThreads {
 public:
  ScopedOpenCvThreads() {
    const std::lock_guard<std::mutex> lock(Mutex());
    if (Count()++ == 0) {
      Saved() = cv::getNumThreads();
      if (Saved() != 1) cv::setNumThreads(1);
    }
  }
  ~ScopedOpenCvThreads() {
    const std::lock_guard<std::mutex> lock(Mutex());
    if (--Count() == 0 && Saved() != 1) cv::setNumThreads(Saved());
  }
  ScopedOpenCvThreads(const ScopedOpenCvThreads&) = delete;
  ScopedOpenCvThreads& operator=(const ScopedOpenCvThreads&) = delete;

 private:
  static std::mutex& Mutex() {
    static std::mutex mutex;
    return mutex;
  }
  static int& Count() {
    static int count = 0;
    return count;
  }
  static int& Saved() {
    static int saved = 0;
    return saved;
  }
};

}  // namespace rovo
