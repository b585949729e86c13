// The shading passes of one sample of a tile: hits and misses, texture lookups, then ambient,
// emission, lights and the sun with their shadow rays.
#include <emmintrin.h>

#include <algorithm>

#include "render/tracer_internal.h"

namespace rovo {
namespace tracer_internal {

namespace {

// log2(x) for x > 0, per lane: exponent plus a quadratic in the mantissa m in [1, 2),
// log2(m) ~ (m - 1) (1.3465 - 0.3465 (m - 1)); exact at powers of two, |error| < 0.01,
// monotonic and continuous (a level-of-detail selector, not a math library).
__m128 FastLog2x4(__m128 x) {
  const __m128i bits = _mm_castps_si128(x);
  const __m128 exponent = _mm_cvtepi32_ps(
      _mm_sub_epi32(_mm_and_si128(_mm_srli_epi32(bits, 23), _mm_set1_epi32(0xff)), _mm_set1_epi32(127)));
  const __m128 m = _mm_sub_ps(
      _mm_castsi128_ps(_mm_or_si128(_mm_and_si128(bits, _mm_set1_epi32(0x007fffff)), _mm_set1_epi32(0x3f800000))),
      _mm_set1_ps(1.0f));
  return _mm_add_ps(exponent, _mm_mul_ps(m, _mm_sub_ps(_mm_set1_ps(1.3465f), _mm_mul_ps(_mm_set1_ps(0.3465f), m))));
}

}  // namespace

// Shading pass 1: misses take the sky; hits get their facing unit normal, base colour and texture
// coordinates and level of detail (compacted lists). Sets the hit and textured-hit counts.
void GatherHits(const RenderJob& job, const TileRect& t, int n, TileBuffers& tb, int* num_hits_out,
                int* num_textured_out) {
  const Tracer::Impl& d = job.d;
  const bool raw = job.raw;
  int num_hits = 0, num_textured = 0;
  for (int r = 0; r < n; ++r) {
    const RTCRayHit& rh = tb.rayhit[r];
    const int local = tb.pixel[r];
    const Eigen::Vector3f dir(rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
      if (!raw) {
        tb.sum[local] = _mm_add_ps(tb.sum[local], MissRadiance(job, dir, t.Pixel(job, local)));
        ++tb.count[local];
      }
      continue;
    }
    const int h = num_hits++;
    tb.hit_ray[h] = r;
    const unsigned inst = rh.hit.instID[0];
    Eigen::Vector3f normal(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
    const Tracer::Impl::TriangleShade* shade;
    if (inst == RTC_INVALID_GEOMETRY_ID) {
      shade = d.static_geom_shade[rh.hit.geomID];
    } else {
      const int obj =
          d.top_instance_object[inst] >= 0 ? d.top_instance_object[inst] : d.static_geom_object[rh.hit.geomID];
      normal = d.object_rotation[obj] * normal;
      shade = d.object_shade[obj];
    }
    const float nlen2 = normal.squaredNorm();
    normal = nlen2 > 0.0f ? Eigen::Vector3f(normal / std::sqrt(nlen2)) : Eigen::Vector3f(-dir);
    const float facing = normal.dot(dir);  // after the flip n.d = -|facing| exactly
    if (facing > 0.0f) normal = -normal;
    tb.normal[h] = normal;
    if (raw) continue;
    const Tracer::Impl::TriangleShade& ts = shade[rh.hit.primID];
    const Tracer::Impl::ShadeMaterial& mat = d.shade_materials[ts.material];
    tb.albedo[h] = _mm_load_ps(mat.base_color);
    tb.material[h] = ts.material;
    if (!job.textures || ts.texels_per_metre < 0.0f) continue;
    const float bu = rh.hit.u, bv = rh.hit.v, bw = 1.0f - bu - bv;
    const int k = num_textured++;
    tb.textured_hit[k] = h;
    tb.texture[k] = mat.texture;
    tb.tex_u[k] = bw * ts.uv[0] + bu * ts.uv[2] + bv * ts.uv[4];
    tb.tex_v[k] = bw * ts.uv[1] + bu * ts.uv[3] + bv * ts.uv[5];
    // Ray-cone footprint in metres, then in texels of level 0.
    const size_t pi = t.Pixel(job, local);
    const float cos_view = std::max(facing > 0.0f ? facing : -facing, 0.1f);  // -normal.dot(dir)
    const float texels = rh.ray.tfar * job.rays.pixel_angle[pi] / cos_view * job.inv_sqrt_spp * ts.texels_per_metre;
    tb.tex_lod[k] = texels;  // turned into the level of detail below, four at a time
  }
  *num_hits_out = num_hits;
  *num_textured_out = num_textured;
}

// Shading pass 2: the texture lookups (a tight loop keeps several independent texel loads in flight).
void ApplyTextures(const RenderJob& job, int num_textured, TileBuffers& tb) {
  // lod = FastLog2(texels) + bias where texels > 0, else 0.
  for (int k = num_textured; k % 4 != 0; ++k) tb.tex_lod[k] = 0.0f;
  const __m128 bias = _mm_set1_ps(job.settings.lod_bias);
  for (int k = 0; k < num_textured; k += 4) {
    const __m128 texels = _mm_load_ps(tb.tex_lod + k);
    _mm_store_ps(tb.tex_lod + k,
                 _mm_and_ps(_mm_cmpgt_ps(texels, _mm_setzero_ps()), _mm_add_ps(FastLog2x4(texels), bias)));
  }
  MipTexture::SampleBatch(tb.texture, tb.tex_u, tb.tex_v, tb.tex_lod, num_textured, tb.texel, job.settings.trilinear);
  for (int k = 0; k < num_textured; ++k) {
    const int h = tb.textured_hit[k];
    tb.albedo[h] = _mm_mul_ps(tb.albedo[h], tb.texel[k]);
  }
}

// Shading pass 3: ambient light, emission, point and spot lights, and the shadow rays of the lit
// hits (sun sample of sample s; lights) into tb.shadow with their direct light; returns the shadow
// ray count. Without shadows the direct light is added at once.
int AmbientAndShadowRays(const RenderJob& job, const TileRect& t, int s, int num_hits, TileBuffers& tb) {
  const Tracer::Impl& d = job.d;
  const bool raw = job.raw;
  int num_shadow = 0;
  for (int h = 0; h < num_hits; ++h) {
    const RTCRayHit& rh = tb.rayhit[tb.hit_ray[h]];
    const int local = tb.pixel[tb.hit_ray[h]];
    const Eigen::Vector3f& normal = tb.normal[h];
    __m128 albedo = _mm_setzero_ps();
    const Eigen::Vector3f dir(rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z);
    const Eigen::Vector3f origin(rh.ray.org_x, rh.ray.org_y, rh.ray.org_z);  // per ray with CameraMotion
    const float tfar = rh.ray.tfar;
    const float offset = 1e-4f * (1.0f + tfar);
    if (!raw) {
      albedo = tb.albedo[h];
      // Ambient: hemisphere mix of sky and ground by the normal's elevation.
      const float up = 0.5f * (1.0f + normal.z());
      tb.sum[local] = _mm_add_ps(
          tb.sum[local],
          _mm_mul_ps(albedo, _mm_add_ps(job.ambient_ground, _mm_mul_ps(_mm_set1_ps(up), job.ambient_delta))));
      ++tb.count[local];
      if (d.any_emission)
        tb.sum[local] = _mm_add_ps(tb.sum[local], _mm_loadu_ps(d.material_emission[tb.material[h]].data()));
      if (!d.lights.empty()) {
        const Eigen::Vector3f x = origin + tfar * dir;
        // The light choice's uniform: a hashed per-pixel rotation of the sample's stratum, stratified
        // over the pixel's samples.
        const float stratum = job.adaptive ? AdaptiveStratum(job, s) : (static_cast<float>(s) + 0.5f) * job.inv_spp;
        const float u = Wrap01(stratum + UnitFloat(Mix64(t.Pixel(job, local) * 0xa0761d6478bd642full + 5)));
        AddPointLights(job, h, x, -dir, x + offset * normal, offset, u, local, tb, &num_shadow);
      }
    }
    if (!d.sun_on) continue;
    const Eigen::Vector3f* to_sun = &d.sun_dir;
    if (job.soft_sun) {
      const size_t pi = t.Pixel(job, local);
      to_sun = &d.sun_samples[(static_cast<uint32_t>(Mix64(pi * 0x9e3779b97f4a7c15ull + 7)) * job.spp_u +
                               static_cast<uint32_t>(s)) &
                              (kSunSamples - 1)];
    }
    const float cos_sun = normal.dot(*to_sun);
    if (cos_sun <= 0.0f) continue;
    const __m128 direct =
        raw ? albedo : _mm_mul_ps(_mm_mul_ps(albedo, job.sun_radiance), _mm_set1_ps(cos_sun * kInvPi));
    if (!job.settings.shadows) {
      if (!raw) tb.sum[local] = _mm_add_ps(tb.sum[local], direct);
      continue;
    }
    const Eigen::Vector3f shadow_origin = origin + tfar * dir + offset * normal;
    PushShadowRay(tb, &num_shadow, shadow_origin, *to_sun, offset, std::numeric_limits<float>::infinity(), local,
                  direct, 0);
  }
  return num_shadow;
}

}  // namespace tracer_internal

}  // namespace rovo
