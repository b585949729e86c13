#pragma once
// Wall and process CPU time in milliseconds, for the stage timings of the pipeline.

#include <chrono>
#include <ctime>

namespace rovo {

// Milliseconds of steady-clock time since `start`.
inline double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Process CPU time (all threads), milliseconds.
inline double CpuMs() { return 1000.0 * static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

}  // namespace rovo
