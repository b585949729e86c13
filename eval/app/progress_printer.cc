#include "eval/app/progress_printer.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace rovo {

ProgressPrinter::ProgressPrinter() : tty_(::isatty(2) != 0) {}

double ProgressPrinter::MinIntervalSeconds() const { return tty_ ? 0.1 : 5.0; }

void ProgressPrinter::Report(const ProgressUpdate& u) {
  const double rate = u.elapsed_s > 0 ? u.done / u.elapsed_s : 0.0;
  const double eta = rate > 0 ? (u.total - u.done) / rate : 0.0;
  const double frac = u.total > 0 ? static_cast<double>(u.done) / u.total : 1.0;
  char line[256];
  if (tty_) {
    const int width = 28;
    const int filled = static_cast<int>(std::lround(frac * width));
    std::string bar(static_cast<size_t>(filled), '#');
    bar.resize(width, '.');
    std::snprintf(line, sizeof(line), "\r%s [%s] %lld/%lld %s  %.2f %s/s  ETA %.0fs   ", u.label.c_str(), bar.c_str(),
                  static_cast<long long>(u.done), static_cast<long long>(u.total), u.unit.c_str(), rate, u.unit.c_str(),
                  eta);
    std::fputs(line, stderr);
    if (u.final) std::fputs("\n", stderr);
  } else {
    std::snprintf(line, sizeof(line), "%s: %lld/%lld %s (%.0f%%), %.2f %s/s, %s %.0fs\n", u.label.c_str(),
                  static_cast<long long>(u.done), static_cast<long long>(u.total), u.unit.c_str(), 100.0 * frac, rate,
                  u.unit.c_str(), u.final ? "elapsed" : "ETA", u.final ? u.elapsed_s : eta);
    std::fputs(line, stderr);
  }
  std::fflush(stderr);
}

}  // namespace rovo
