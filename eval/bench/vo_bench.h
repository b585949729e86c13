#pragma once
// VO speed benchmark (`rovo bench vo`): the pipeline's time per frame by stage, with a machine reference.

#include "vo/pipeline.h"

namespace rovo {

// Median wall time (ms) of one full-size hybrid warp per core on `cores` cores at once (details in vo_bench.cc).
double MachineReferenceWarpMs(int cores);

// Runs the pipeline with `options` (out_dir default: <dataset>_bench_vo_run) between two machine references
// and prints the table of mean ms per frame by stage.
void RunVoBenchmark(VoOptions options);

// `rovo bench vo --against-mode M --rounds N`: the options' extrinsics mode and mode M run in turn, N
// rounds, the first of a round alternating (run folders <out_dir>_<mode>), and a table of each round's
// whole frame (mean ms per frame, over the frames from io.timed_from on) in both modes with their ratio,
// printed as each round ends, then the median ratio and its range: a paired comparison, as the machine's
// speed drifts between runs. Throws std::invalid_argument for rounds < 1 or M equal to the options' mode.
void RunVoModeComparison(VoOptions options, ExtrinsicsMode against, int rounds);

}  // namespace rovo
