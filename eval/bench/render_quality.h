#pragma once
// The image-quality studies of `rovo bench render --quality` (tables on stdout).

#include <tbb/task_arena.h>

#include "datasets/rig.h"
#include "render/tracer.h"
#include "scenes/scene.h"

namespace rovo {

// Anti-aliasing: renders camera 0 of frame 0 turned by quarter-pixel yaw steps (a slow pan) with each
// sampling setting and prints the mean absolute difference to a 32-spp reference and the shimmer:
// mean |(I_k - I_k-1) - (R_k - R_k-1)|, the frame-to-frame change not explained by the reference's.
void RunQualityStudy(const Scene& scene, const Rig& rig, Tracer& tracer, tbb::task_arena& arena);

// Point and spot lights (scenes with lights only): renders camera 0 of frame 0 with each light
// choice (ShadeSettings::max_shadowed_lights, min_shadowed_share, sample_lights) and prints the mean
// absolute difference to a reference, the share of values off by more than 8 codes and the CPU time.
void RunLightQualityStudy(const Scene& scene, const Rig& rig, Tracer& tracer, tbb::task_arena& arena);

// Motion blur: renders camera 0 of trajectory frame 1 with a global shutter of `shutter_ms` (the rig
// from the continuous-time ground truth of frames 0-2) with fixed sample counts and with adaptive
// sampling (render/tracer.h, AdaptiveSampling) at several thresholds, and prints the mean absolute
// difference to a 64-spp reference, the share of values off by more than 8 codes, the mean samples per
// pixel and the CPU time.
void RunBlurQualityStudy(const Scene& scene, const Rig& rig, Tracer& tracer, tbb::task_arena& arena, double shutter_ms);

}  // namespace rovo
