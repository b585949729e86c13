#pragma once
// ScopedOpenCvThreads: OpenCV serial (cv::setNumThreads(1), process-wide) while any holder lives, the
// caller's setting restored when the last one goes. Every vo step that calls OpenCV's parallel
// functions (the front-end, the start-up calibration) holds one: with several VO runs in one process
// (`rovo suite --jobs 2`) a set-and-restore per call changed OpenCV's thread pool while another
// run's KLT or remap was inside it, which crashed. Serial OpenCV also costs nothing there: the views
// already run in parallel under TBB, and OpenCV's nested loops only added task overhead (measured: 4 x
// 5 remaps on 2 threads took ~20 % more wall and CPU time than with OpenCV serial inside each view).

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
