#pragma once
// VO speed benchmark (`rovo bench vo`): the pipeline's time per frame by stage, with a machine reference.

#include "vo/pipeline.h"

namespace rovo {

// Median wall time (ms) of one full-size hybrid warp per core on `cores` cores at once (details in vo_bench.cc).
double MachineReferenceWarpMs(int cores);

// Runs the pipeline with `options` (out_dir default: <dataset>_bench_vo_run) between two machine references
// and prints the table of mean ms per frame by stage.
void RunVoBenchmark(VoOptions options);

}  // namespace rovo
