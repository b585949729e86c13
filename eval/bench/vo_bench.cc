// `rovo bench vo`: time per frame by stage, and the machine reference that makes two runs comparable.
#include "eval/bench/vo_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "datasets/rig.h"
#include "vo/hybrid_projection.h"

namespace rovo {

// Machine reference printed with the bench table: full-size hybrid warps by cv::remap itself (rovo4,
// camera 0, its fixed-point maps, a fixed random image; the front-end's own warp is faster,
// vo/bilinear_remap.h, and would move the unit), one per core on `cores` cores at once (shared caches and memory
// bandwidth included), median wall time of 31 rounds after 9 warm-up rounds (single rounds vary by 2x on this machine,
// the median by about 10 % between seconds). Measured before and after the run: the machine's speed drifts by a third
// or more between hours (the one-core warp took 6.8 ms one evening, 10.5 ms another), so runs are comparable only when
// their references agree.
double MachineReferenceWarpMs(int cores) {
  const Rig rig = MakeRigPreset("rovo4");
  const std::vector<HybridLayout> layouts = ComputeHybridLayouts(rig);
  const HybridProjection projection(rig.cameras[0].camera, rig.cameras[0].cam_from_rig, layouts[0]);
  cv::Mat image(rig.cameras[0].camera.height, rig.cameras[0].camera.width, CV_8UC1);
  cv::RNG(7).fill(image, cv::RNG::UNIFORM, 0, 255);
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  std::vector<cv::Mat> warped(cores);
  std::vector<double> ms;
  for (int k = 0; k < 40; ++k) {
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> workers;
    workers.reserve(static_cast<size_t>(cores));
    for (int c = 0; c < cores; ++c)
      workers.emplace_back([&, c] {
        cv::remap(image, warped[c], projection.map_fixed(), projection.map_frac(), cv::INTER_LINEAR,
                  cv::BORDER_CONSTANT, cv::Scalar::all(0));
      });
    for (std::thread& w : workers) w.join();
    const double round_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (k >= 9) ms.push_back(round_ms);  // the first rounds of a process run slow (warm-up)
  }
  cv::setNumThreads(threads);
  std::nth_element(ms.begin(), ms.begin() + ms.size() / 2, ms.end());
  return ms[ms.size() / 2];
}

void RunVoBenchmark(VoOptions options) {
  if (options.io.out_dir.empty()) options.io.out_dir = options.io.dataset_dir + "_bench_vo_run";
  const int cores =
      options.io.threads > 0 ? options.io.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const double reference_before_ms = MachineReferenceWarpMs(cores);
  const VoSummary s = RunVo(options);
  const double reference_after_ms = MachineReferenceWarpMs(cores);
  const VoStageTimes& t = s.stage_ms;
  std::printf("rovo bench vo: %s, mode %s, %d frames, threads %d\n", options.io.dataset_dir.c_str(),
              ExtrinsicsModeName(options.start.mode).c_str(), s.frames, options.io.threads);
  if (options.io.timed_from > 0) {
    std::printf("stage times: the frames from index %d of the range on (%d of %d frames)\n", options.io.timed_from,
                std::max(0, s.frames - options.io.timed_from), s.frames);
  }
  // CPU = process CPU time of all threads (FrontendFrame::cpu_ms_*); measured for the front-end only. It
  // includes the image decoder and, with async BA, the BA and the previous frame's back-end running
  // meanwhile: use --preload --sync-ba for the front-end's own CPU time. "load images (wait)" is the
  // front-end's wait for its frame's images.
  // Ratios against the mean of the two references: what stays comparable between machines and hours.
  const double reference_ms = 0.5 * (reference_before_ms + reference_after_ms);
  std::printf(
      "| stage                     | ms/frame | machine refs | CPU ms/frame |\n"
      "|---------------------------|---------:|-------------:|-------------:|\n");
  const double frontend_wall = t.warp + t.detect + t.track + t.match;
  const double frontend_cpu = t.cpu_warp + t.cpu_detect + t.cpu_track + t.cpu_match;
  const struct {
    const char* name;
    double wall, cpu;  // cpu < 0: not measured
  } rows[] = {{"load images (wait)", t.load, -1},
              {"front-end: warp", t.warp, t.cpu_warp},
              {"front-end: detect", t.detect, t.cpu_detect},
              {"front-end: track", t.track, t.cpu_track},
              {"front-end: match", t.match, t.cpu_match},
              {"front-end: total", frontend_wall, frontend_cpu},
              {"back-end: RANSAC", t.ransac, -1},
              {"back-end: refine", t.refine, -1},
              {"back-end: triangulate", t.triangulate, -1},
              {"back-end: local BA solve", t.ba, -1},
              {"back-end: wait for BA", t.ba_wait, -1},
              {"back-end: in-line total", t.backend_total, -1},
              {"whole frame", t.total, -1}};
  for (const auto& row : rows) {
    if (row.cpu >= 0) {
      std::printf("| %-25s | %8.2f | %12.2f | %12.2f |\n", row.name, row.wall, row.wall / reference_ms, row.cpu);
    } else {
      std::printf("| %-25s | %8.2f | %12.2f |            - |\n", row.name, row.wall, row.wall / reference_ms);
    }
  }
  if (s.startup_ms > 0.0) {
    std::printf("start-up calibration (OnlineExt, before the first frame): %.0f ms = %.1f machine refs, %.0f CPU ms\n",
                s.startup_ms, s.startup_ms / reference_ms, s.startup_cpu_ms);
  }
  std::printf("RANSAC: %.2f us per hypothesis\n", t.ransac_us_per_hypothesis);
  std::printf("local BA: %s\n",
              options.backend.async_ba
                  ? "solved on its own thread beside the next frame's front-end (in-line total = wait "
                    "for it + the rest); the next frame's front-end runs beside the back-end, so the "
                    "whole frame is less than the two totals' sum"
                  : "solved in line (--sync-ba), front-end and back-end in turn");
  std::printf("whole pipeline: %.2f frames/s (target 10 Hz), %.2f machine refs per frame%s\n",
              t.total > 0 ? 1000.0 / t.total : 0.0, t.total / reference_ms,
              options.io.preload ? ", images decoded beforehand" : ", images decoded on a second thread");
  std::printf(
      "machine reference: one full-size hybrid warp by cv::remap per core on %d core%s at once: %.2f ms before "
      "the run, %.2f ms after\n",
      cores, cores == 1 ? "" : "s", reference_before_ms, reference_after_ms);
  const double reference_low_ms = std::min(reference_before_ms, reference_after_ms);
  if (std::abs(reference_after_ms - reference_before_ms) > 0.2 * reference_low_ms) {
    std::printf(
        "warning: the machine's speed changed by more than 20 %% during the run; repeat it before "
        "comparing\n");
  }
}

namespace {

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace

// One run of the comparison in `mode` (run folder <out_dir>_<mode>, progress off): its whole frame's mean
// ms; images it could not read are reported on stderr.
double TimeModeRun(VoOptions options, ExtrinsicsMode mode, const std::string& out_dir) {
  options.start.mode = mode;
  options.io.out_dir = out_dir + "_" + ExtrinsicsModeName(mode);
  options.io.quiet = true;
  const VoSummary s = RunVo(options);
  if (s.missing_images > 0) {
    std::fprintf(stderr, "bench vo: %s run: %d images missing or unreadable (in %d frames)\n",
                 ExtrinsicsModeName(mode).c_str(), s.missing_images, s.frames_with_missing_images);
  }
  return s.stage_ms.total;
}

void RunVoModeComparison(VoOptions options, ExtrinsicsMode against, int rounds) {
  if (rounds < 1) throw std::invalid_argument("bench vo: --rounds must be >= 1");
  const ExtrinsicsMode mode = options.start.mode;
  const std::string name = ExtrinsicsModeName(mode), other = ExtrinsicsModeName(against);
  if (against == mode) throw std::invalid_argument("bench vo: --against-mode " + other + " is the run's own mode");
  if (options.io.out_dir.empty()) options.io.out_dir = options.io.dataset_dir + "_bench_vo_run";
  const int cores =
      options.io.threads > 0 ? options.io.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  std::printf("rovo bench vo: %s, %s against %s, %d round%s (odd rounds %s first, even rounds %s first), threads %d",
              options.io.dataset_dir.c_str(), name.c_str(), other.c_str(), rounds, rounds == 1 ? "" : "s", name.c_str(),
              other.c_str(), cores);
  if (options.io.timed_from > 0) std::printf(", the frames from index %d of the range on", options.io.timed_from);
  std::printf("\n| round | %s ms/frame | %s ms/frame | %s / %s | machine ref ms |\n|---|---:|---:|---:|---:|\n",
              name.c_str(), other.c_str(), name.c_str(), other.c_str());
  std::fflush(stdout);
  std::vector<double> ms_mode, ms_other, ratios;
  for (int r = 0; r < rounds; ++r) {
    const double reference_ms = MachineReferenceWarpMs(cores);
    // Alternating order: neither mode always runs first, next to the reference or the process's warm-up.
    const bool mode_first = r % 2 == 0;
    for (const ExtrinsicsMode m : mode_first ? std::vector{mode, against} : std::vector{against, mode}) {
      std::fprintf(stderr, "bench vo: round %d/%d, %s\n", r + 1, rounds, ExtrinsicsModeName(m).c_str());
      (m == mode ? ms_mode : ms_other).push_back(TimeModeRun(options, m, options.io.out_dir));
    }
    ratios.push_back(ms_mode.back() / ms_other.back());
    std::printf("| %d | %.2f | %.2f | %.3f | %.2f |\n", r + 1, ms_mode.back(), ms_other.back(), ratios.back(),
                reference_ms);
    std::fflush(stdout);
  }
  std::printf("%s / %s: median %.3f (%.3f-%.3f over %d rounds); median ms per frame %.2f against %.2f\n", name.c_str(),
              other.c_str(), Median(ratios), *std::min_element(ratios.begin(), ratios.end()),
              *std::max_element(ratios.begin(), ratios.end()), rounds, Median(ms_mode), Median(ms_other));
}

}  // namespace rovo
