#include "render/tracer.h"

#include <pmmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "render/tracer_internal.h"

namespace rovo {
namespace tracer_internal {

namespace {

// Depth and object id of the pixel-centre hits.
void WriteDepthAndMask(const RenderJob& job, const TileRect& t, int n, const TileBuffers& tb) {
  const Tracer::Impl& d = job.d;
  for (int r = 0; r < n; ++r) {
    const RTCRayHit& rh = tb.rayhit[r];
    const size_t pi = t.Pixel(job, tb.pixel[r]);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    if (job.settings.want_depth) job.image->depth[pi] = rh.ray.tfar;
    if (job.settings.want_mask) {
      const unsigned inst = rh.hit.instID[0];
      const int obj = inst != RTC_INVALID_GEOMETRY_ID && d.top_instance_object[inst] >= 0
                          ? d.top_instance_object[inst]
                          : d.static_geom_object[rh.hit.geomID];
      job.image->mask[pi] = d.scene.objects[obj].id;
    }
  }
}

// Shadow rays towards one point light in a tile's packets: at least this many go as an 8-wide packet.
constexpr int kMinPacket = 4;

// Casts rays[group[0, n)] (n <= 8) as one 8-wide packet; occluded rays get tfar = -inf.
void Occlude8(const Tracer::Impl& d, RTCIntersectContext* context, const int* group, int n, TileBuffers& tb) {
  alignas(32) RTCRay8 packet;
  alignas(32) int valid[8];
  for (int l = 0; l < 8; ++l) {
    const RTCRay& r = tb.shadow[group[std::min(l, n - 1)]];
    valid[l] = l < n ? -1 : 0;
    packet.org_x[l] = r.org_x;
    packet.org_y[l] = r.org_y;
    packet.org_z[l] = r.org_z;
    packet.dir_x[l] = r.dir_x;
    packet.dir_y[l] = r.dir_y;
    packet.dir_z[l] = r.dir_z;
    packet.tnear[l] = r.tnear;
    packet.tfar[l] = r.tfar;
    packet.time[l] = r.time;
    packet.mask[l] = r.mask;
    packet.id[l] = 0;
    packet.flags[l] = 0;
  }
  rtcOccluded8(valid, d.trace_scene, context, &packet);
  for (int l = 0; l < n; ++l) tb.shadow[group[l]].tfar = packet.tfar[l];
}

// The tile's shadow rays; occluded rays get tfar = -inf. Rays towards the same light start close
// together and end at one point: runs of kMinPacket to 8 of them go to Embree as 8-wide packets
// (rtcOccluded8). The sun's rays (spread over its disc) and the rest go through rtcOccluded1Mp.
void OccludeShadowRays(const RenderJob& job, RTCIntersectContext* context, int num_shadow, TileBuffers& tb) {
  if (job.d.lights.empty()) {
    rtcOccluded1M(job.d.trace_scene, context, tb.shadow, static_cast<unsigned>(num_shadow), sizeof(RTCRay));
    return;
  }
  // Open groups of rays towards one light; a full group goes out at once. Rays to the sun, to a light
  // beyond the first kMaxGroups, and groups left smaller than kMinPacket are cast one by one.
  constexpr int kMaxGroups = 16;
  uint32_t group_target[kMaxGroups];
  int group_size[kMaxGroups], group[kMaxGroups][8];
  int num_groups = 0, single[kMaxShadowRays], num_single = 0;
  for (int k = 0; k < num_shadow; ++k) {
    const uint32_t target = tb.shadow_target[k];
    int g = 0;
    while (g < num_groups && group_target[g] != target) ++g;
    if (target == 0 || g == kMaxGroups) {
      single[num_single++] = k;
      continue;
    }
    if (g == num_groups) {
      group_target[num_groups] = target;
      group_size[num_groups++] = 0;
    }
    group[g][group_size[g]++] = k;
    if (group_size[g] == 8) {
      Occlude8(job.d, context, group[g], 8, tb);
      group_size[g] = 0;
    }
  }
  for (int g = 0; g < num_groups; ++g) {
    if (group_size[g] >= kMinPacket)
      Occlude8(job.d, context, group[g], group_size[g], tb);
    else
      for (int k = 0; k < group_size[g]; ++k) single[num_single++] = group[g][k];
  }
  if (num_single == 0) return;
  // Contiguous, as rtcOccluded1M's streams are faster than rtcOccluded1Mp's pointers.
  for (int k = 0; k < num_single; ++k) tb.shadow_scratch[k] = tb.shadow[single[k]];
  rtcOccluded1M(job.d.trace_scene, context, tb.shadow_scratch, static_cast<unsigned>(num_single), sizeof(RTCRay));
  for (int k = 0; k < num_single; ++k) tb.shadow[single[k]].tfar = tb.shadow_scratch[k].tfar;
}

// Adaptive sampling (AdaptiveSampling): every pixel of the tile active.
void StartAdaptiveTile(TileBuffers& tb) {
  for (int i = 0; i < kTilePixels; ++i) tb.active[i] = 1;
}

// The sums and counts that end the first half of the current stage.
void MarkHalf(TileBuffers& tb) {
  for (int i = 0; i < kTilePixels; ++i) {
    tb.sum_half[i] = tb.sum[i];
    tb.count_half[i] = tb.count[i];
  }
}

// sqrt(clamp(output_scale * Y, 0, 1)) of the mean of `count` samples summing to `sum`.
inline float EncodedMean(const RenderJob& job, __m128 sum, int count) {
  alignas(16) float c[4];
  _mm_store_ps(c, sum);
  const float y = job.output_scale * (0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]) / static_cast<float>(count);
  return std::sqrt(std::clamp(y, 0.0f, 1.0f));
}

// At the end of a stage: a pixel stays active when the means of its stage's two halves differ by more
// than the threshold, or those of a 4-neighbour in the tile do (two samples can agree by chance beside
// an edge that their neighbour's samples straddle). Marks the next stage's first half (this stage's
// samples). False when no pixel of the tile is left.
bool CloseAdaptiveStage(const RenderJob& job, TileBuffers& tb) {
  uint8_t differ[kTilePixels];
  for (int i = 0; i < kTilePixels; ++i) {
    const int n0 = tb.count_half[i], n1 = tb.count[i] - tb.count_half[i];
    differ[i] = tb.active[i] && n0 > 0 && n1 > 0 &&
                std::abs(EncodedMean(job, tb.sum_half[i], n0) -
                         EncodedMean(job, _mm_sub_ps(tb.sum[i], tb.sum_half[i]), n1)) > job.adaptive_threshold;
  }
  bool any = false;
  for (int i = 0; i < kTilePixels; ++i) {
    if (!tb.active[i]) continue;
    const int x = i % kTile, y = i / kTile;
    const bool keep = differ[i] || (x > 0 && differ[i - 1]) || (x + 1 < kTile && differ[i + 1]) ||
                      (y > 0 && differ[i - kTile]) || (y + 1 < kTile && differ[i + kTile]);
    tb.active[i] = keep;
    any = any || keep;
  }
  MarkHalf(tb);
  return any;
}

// The two intersection contexts of a tile: coherent camera rays; shadow rays through the incoherent
// path (Embree 3.13's coherent stream path never returned for the rays towards a wide sun disc: a
// 30-degree overcast sun hung the render).
struct TileContexts {
  TileContexts() {
    rtcInitIntersectContext(&camera);
    camera.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcInitIntersectContext(&shadow);
    shadow.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  }
  RTCIntersectContext camera, shadow;
};

// Sample s of the tile (-1: the extra pixel-centre pass for depth and masks): the camera rays, the
// three shading passes and the shadow rays. Returns the number of camera rays.
int TracePass(const RenderJob& job, const TileRect& t, int s, bool centre_pass, TileContexts& contexts,
              TileBuffers& tb) {
  const Tracer::Impl& d = job.d;
  const bool raw = job.raw;
  const bool is_centre = s < 0 || job.spp == 1;
  const int n = MakeSampleRays(job, t, s, is_centre, tb);
  if (n == 0) return 0;
  rtcIntersect1M(d.trace_scene, &contexts.camera, tb.rayhit, static_cast<unsigned>(n), sizeof(RTCRayHit));
  if (is_centre && !raw && centre_pass) WriteDepthAndMask(job, t, n, tb);
  if (s < 0) return n;  // the extra centre pass only feeds depth and masks

  int num_hits = 0, num_textured = 0;
  GatherHits(job, t, n, tb, &num_hits, &num_textured);
  if (num_textured > 0) ApplyTextures(job, num_textured, tb);
  const int num_shadow = AmbientAndShadowRays(job, t, s, num_hits, tb);
  if (num_shadow == 0) return n;
  if (job.motion) {  // shadow rays at their camera ray's time (moving objects)
    for (int k = 0; k < num_shadow; ++k)
      tb.shadow[k].time = job.moving ? tb.pixel_time[tb.shadow_pixel[k]] : job.motion->time_mid;
  }
  OccludeShadowRays(job, &contexts.shadow, num_shadow, tb);
  if (raw) return n;
  for (int k = 0; k < num_shadow; ++k) {
    // Embree sets tfar to -inf for occluded rays.
    if (tb.shadow[k].tfar >= 0.0f) tb.sum[tb.shadow_pixel[k]] = _mm_add_ps(tb.sum[tb.shadow_pixel[k]], tb.direct[k]);
  }
  return n;
}

// One tile: a pixel-centre pass for depth and masks (shared with the only sample when spp == 1),
// then the samples (TracePass; with adaptive sampling in stages of doubling size, each pass only
// for the pixels still active); then the resolve. The raw cast computes the same shadow rays (it
// needs the normal and the sun sample) but no albedo, texture, sky or ambient term.
void RenderTile(const RenderJob& job, int tile, TileBuffers& tb) {
  TileRect t;
  t.tx0 = (tile % job.tiles_x) * kTile;
  t.ty0 = (tile / job.tiles_x) * kTile;
  t.tw = std::min(kTile, job.width - t.tx0);
  t.th = std::min(kTile, job.height - t.ty0);
  TileContexts contexts;
  for (int i = 0; i < kTilePixels; ++i) {
    tb.sum[i] = _mm_setzero_ps();
    tb.count[i] = 0;
  }
  if (job.adaptive) StartAdaptiveTile(tb);

  const bool centre_pass = job.settings.want_depth || job.settings.want_mask;
  if (centre_pass && job.spp > 1) TracePass(job, t, -1, centre_pass, contexts, tb);
  int64_t samples = 0;
  int stage_end = job.adaptive ? job.min_spp : job.spp;
  for (int s = 0; s < job.spp; ++s) {
    if (s == stage_end) {
      if (!CloseAdaptiveStage(job, tb)) break;
      stage_end *= 2;
    }
    samples += TracePass(job, t, s, centre_pass, contexts, tb);
    if (job.adaptive && s + 1 == job.min_spp / 2) MarkHalf(tb);  // the first stage's first half
  }
  job.samples.fetch_add(samples, std::memory_order_relaxed);
  if (!job.raw) ResolveTile(job, t, tb);
}

}  // namespace

}  // namespace tracer_internal

using tracer_internal::kTile;
using tracer_internal::PrepareImage;
using tracer_internal::RenderJob;
using tracer_internal::RenderTile;
using tracer_internal::SetSkyTerms;
using tracer_internal::TileBuffers;
using tracer_internal::ToF;

bool AdaptiveApplies(const AdaptiveSampling& adaptive, int spp) {
  const auto power_of_two = [](int k) { return k >= 1 && (k & (k - 1)) == 0; };
  return adaptive.enabled && power_of_two(spp) && spp <= 64 && adaptive.min_spp >= 2 &&
         power_of_two(adaptive.min_spp) && adaptive.min_spp < spp;
}

void SetFlushDenormals() {
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

void Tracer::Render(const CameraRays& rays, const Rigid3& world_from_cam, const ShadeSettings& settings,
                    CameraImage* image, const CameraMotion* motion) const {
  const Impl& d = *impl_;
  const int width = rays.width, height = rays.height;
  if (!settings.raw_cast_only) PrepareImage(settings, width, height, image);
  const int spp = std::max(1, settings.spp);
  const Lighting& light = d.scene.lighting;
  RenderJob job(d, rays, settings, image);
  job.world_from_cam_rot = world_from_cam.RotationMatrix().cast<float>();
  job.origin = ToF(world_from_cam.translation);
  job.motion = motion;
  job.moving = motion && (motion->shutter > 0.0f || motion->readout > 0.0f);
  if (job.moving && (motion->rotation.size() < 2 || motion->origin.size() != motion->rotation.size()))
    throw std::invalid_argument("CameraMotion: a moving camera needs at least two poses");
  job.row_time_scale = job.moving && height > 1 ? motion->readout / static_cast<float>(height - 1) : 0.0f;
  job.spp = spp;
  job.inv_spp = 1.0f / static_cast<float>(spp);
  job.inv_sqrt_spp = 1.0f / std::sqrt(static_cast<float>(spp));
  job.theta_max = static_cast<float>(0.5 * rays.camera.max_fov_deg * M_PI / 180.0);
  const AdaptiveSampling& adaptive = settings.adaptive;
  job.adaptive = AdaptiveApplies(adaptive, spp) && !settings.raw_cast_only && !settings.rotate_pattern;
  job.min_spp = job.adaptive ? adaptive.min_spp : spp;
  job.adaptive_threshold = adaptive.threshold;
  job.output_scale = adaptive.output_scale > 0.0f ? adaptive.output_scale : light.exposure;
  job.precomputed_samples = !settings.rotate_pattern && !job.adaptive && rays.sample_spp == spp;
  job.soft_sun = settings.soft_shadows && d.sun_disc_radius > 0.0f && spp > 1;
  job.textures = settings.textures;
  job.spp_u = static_cast<uint32_t>(spp);
  SetSkyTerms(d, settings, &job);
  job.exposure_over_count.assign(spp + 1, 0.0f);
  for (int c = 1; c <= spp; ++c) job.exposure_over_count[c] = light.exposure / static_cast<float>(c);
  for (int s = 0; s < std::min(spp, 64); ++s) {
    if (job.adaptive)
      job.offsets[s] = CameraRays::AdaptiveSample(s, spp, &job.adaptive_stratum[s]);
    else
      job.offsets[s] = CameraRays::SampleOffset(s, spp);
  }
  job.tiles_x = (width + kTile - 1) / kTile;
  job.tiles_y = (height + kTile - 1) / kTile;

  const int num_tiles = job.tiles_x * job.tiles_y;
  tbb::parallel_for(tbb::blocked_range<int>(0, num_tiles, 16), [&](const tbb::blocked_range<int>& range) {
    SetFlushDenormals();
    thread_local std::unique_ptr<TileBuffers> buffers;
    if (!buffers) buffers = std::make_unique<TileBuffers>();
    for (int tile = range.begin(); tile < range.end(); ++tile) RenderTile(job, tile, *buffers);
  });
  if (!settings.raw_cast_only) image->samples = job.samples.load();
}

}  // namespace rovo
