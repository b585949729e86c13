#include "render/tracer.h"

#include <pmmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
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

// One tile: a pixel-centre pass for depth and masks (shared with the only sample when spp == 1),
// then per sample the camera rays, the three shading passes and the shadow rays; then the resolve.
// The raw cast computes the same shadow rays (it needs the normal and the sun sample) but no
// albedo, texture, sky or ambient term.
void RenderTile(const RenderJob& job, int tile, TileBuffers& tb) {
  const Tracer::Impl& d = job.d;
  const ShadeSettings& settings = job.settings;
  const int spp = job.spp;
  const bool raw = job.raw;
  TileRect t;
  t.tx0 = (tile % job.tiles_x) * kTile;
  t.ty0 = (tile / job.tiles_x) * kTile;
  t.tw = std::min(kTile, job.width - t.tx0);
  t.th = std::min(kTile, job.height - t.ty0);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  // Shadow rays towards a wide sun disc are not coherent; Embree 3.13's coherent stream path
  // never returned for such rays (a 30-degree overcast sun hung the render), so they go
  // through the incoherent path.
  RTCIntersectContext shadow_context;
  rtcInitIntersectContext(&shadow_context);
  shadow_context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  for (int i = 0; i < kTilePixels; ++i) {
    tb.sum[i] = _mm_setzero_ps();
    tb.count[i] = 0;
  }

  const bool centre_pass = settings.want_depth || settings.want_mask;
  for (int s = (centre_pass && spp > 1) ? -1 : 0; s < spp; ++s) {
    const bool is_centre = s < 0 || spp == 1;
    const int n = MakeSampleRays(job, t, s, is_centre, tb);
    if (n == 0) continue;
    rtcIntersect1M(d.trace_scene, &context, tb.rayhit, static_cast<unsigned>(n), sizeof(RTCRayHit));
    if (is_centre && !raw && centre_pass) WriteDepthAndMask(job, t, n, tb);
    if (s < 0) continue;  // the extra centre pass only feeds depth and masks

    int num_hits = 0, num_textured = 0;
    GatherHits(job, t, n, tb, &num_hits, &num_textured);
    if (num_textured > 0) ApplyTextures(job, num_textured, tb);
    const int num_shadow = AmbientAndShadowRays(job, t, s, num_hits, tb);
    if (num_shadow == 0) continue;
    if (job.motion) {  // shadow rays at their camera ray's time (moving objects)
      for (int k = 0; k < num_shadow; ++k)
        tb.shadow[k].time = job.moving ? tb.pixel_time[tb.shadow_pixel[k]] : job.motion->time_mid;
    }
    rtcOccluded1M(d.trace_scene, &shadow_context, tb.shadow, static_cast<unsigned>(num_shadow), sizeof(RTCRay));
    if (raw) continue;
    for (int k = 0; k < num_shadow; ++k) {
      // Embree sets tfar to -inf for occluded rays.
      if (tb.shadow[k].tfar >= 0.0f) tb.sum[tb.shadow_pixel[k]] = _mm_add_ps(tb.sum[tb.shadow_pixel[k]], tb.direct[k]);
    }
  }
  if (!raw) ResolveTile(job, t, tb);
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
  job.inv_sqrt_spp = 1.0f / std::sqrt(static_cast<float>(spp));
  job.theta_max = static_cast<float>(0.5 * rays.camera.max_fov_deg * M_PI / 180.0);
  job.precomputed_samples = !settings.rotate_pattern && rays.sample_spp == spp;
  job.soft_sun = settings.soft_shadows && d.sun_disc_radius > 0.0f && spp > 1;
  job.textures = settings.textures;
  job.spp_u = static_cast<uint32_t>(spp);
  SetSkyTerms(d, settings, &job);
  job.exposure_over_count.assign(spp + 1, 0.0f);
  for (int c = 1; c <= spp; ++c) job.exposure_over_count[c] = light.exposure / static_cast<float>(c);
  for (int s = 0; s < std::min(spp, 64); ++s) job.offsets[s] = CameraRays::SampleOffset(s, spp);
  job.tiles_x = (width + kTile - 1) / kTile;
  job.tiles_y = (height + kTile - 1) / kTile;

  const int num_tiles = job.tiles_x * job.tiles_y;
  tbb::parallel_for(tbb::blocked_range<int>(0, num_tiles, 16), [&](const tbb::blocked_range<int>& range) {
    SetFlushDenormals();
    thread_local std::unique_ptr<TileBuffers> buffers;
    if (!buffers) buffers = std::make_unique<TileBuffers>();
    for (int tile = range.begin(); tile < range.end(); ++tile) RenderTile(job, tile, *buffers);
  });
}

}  // namespace rovo
