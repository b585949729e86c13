// Point and spot lights at a hit (formula and light choice: render/tracer.h): the SSE loop over the
// light grid's blocks, then shadow rays to the strongest lights or to one drawn light.
#include <emmintrin.h>

#include <algorithm>

#include "render/sse_math.h"
#include "render/tracer_internal.h"

namespace rovo {
namespace tracer_internal {

namespace {

using LightBlock = Tracer::Impl::LightBlock;

// Calls visit(block) for the blocks of lights that may reach world point x: the grid cell's blocks
// (none outside the grid), then the blocks of the lights without a range.
template <typename F>
void ForEachBlockNear(const Tracer::Impl::LightGrid& g, const Eigen::Vector3f& x, F&& visit) {
  if (g.nx > 0) {
    const float fx = (x.x() - g.x0) * g.inv_cell, fy = (x.y() - g.y0) * g.inv_cell, fz = (x.z() - g.z0) * g.inv_cell;
    if (fx >= 0.0f && fy >= 0.0f && fz >= 0.0f && fx < static_cast<float>(g.nx) && fy < static_cast<float>(g.ny) &&
        fz < static_cast<float>(g.nz)) {
      const size_t c =
          (static_cast<size_t>(static_cast<int>(fz)) * g.ny + static_cast<int>(fy)) * g.nx + static_cast<int>(fx);
      for (uint32_t k = g.cell_begin[c]; k < g.cell_begin[c + 1]; ++k) visit(g.blocks[k]);
    }
  }
  for (const LightBlock& b : g.unbounded) visit(b);
}

// What the lights' formula reads of one hit.
struct LitHit {
  Eigen::Vector3f x, n, view;
  __m128 diffuse;  // albedo / pi
  float ks, shininess;
  float highlight_floor;  // max(0, n.h) below which max(0, n.h)^m < kNegligibleHighlight
};

// The hit in SSE lanes, for four lights at once.
struct LitHitX4 {
  explicit LitHitX4(const LitHit& h)
      : x(_mm_set1_ps(h.x.x())),
        y(_mm_set1_ps(h.x.y())),
        z(_mm_set1_ps(h.x.z())),
        nx(_mm_set1_ps(h.n.x())),
        ny(_mm_set1_ps(h.n.y())),
        nz(_mm_set1_ps(h.n.z())),
        vx(_mm_set1_ps(h.view.x())),
        vy(_mm_set1_ps(h.view.y())),
        vz(_mm_set1_ps(h.view.z())),
        dr(_mm_shuffle_ps(h.diffuse, h.diffuse, _MM_SHUFFLE(0, 0, 0, 0))),
        dg(_mm_shuffle_ps(h.diffuse, h.diffuse, _MM_SHUFFLE(1, 1, 1, 1))),
        db(_mm_shuffle_ps(h.diffuse, h.diffuse, _MM_SHUFFLE(2, 2, 2, 2))),
        glossy(h.ks > 0.0f),
        spec_scale(_mm_set1_ps(h.ks * (h.shininess + 8.0f) * (kInvPi / 8.0f))),
        shininess(_mm_set1_ps(h.shininess)),
        highlight_floor(_mm_set1_ps(h.highlight_floor)) {}
  __m128 x, y, z, nx, ny, nz, vx, vy, vz, dr, dg, db;
  bool glossy;
  __m128 spec_scale, shininess, highlight_floor;
};

inline __m128 Dot3(__m128 ax, __m128 ay, __m128 az, __m128 bx, __m128 by, __m128 bz) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(ax, bx), _mm_mul_ps(ay, by)), _mm_mul_ps(az, bz));
}

// The unshadowed light of a block's four lights at the hit (render/tracer.h's formula, four at a time, pow by
// Log2x4 / Exp2x4): the geometric factor A * W * cos / d^2 into *geometry and the Blinn-Phong term
// ks * (m + 8) / (8 pi) * max(0, n.h)^m into *specular; returns r + g + b of the light, 0 where a
// light does not reach the hit.
inline __m128 BlockWeights(const LightBlock& b, const LitHitX4& h, __m128* geometry, __m128* specular) {
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
  const __m128 tx = _mm_sub_ps(_mm_load_ps(b.px), h.x), ty = _mm_sub_ps(_mm_load_ps(b.py), h.y),
               tz = _mm_sub_ps(_mm_load_ps(b.pz), h.z);
  const __m128 d2 = Dot3(tx, ty, tz, tx, ty, tz);
  const __m128 q = _mm_mul_ps(d2, _mm_load_ps(b.inv_range2));
  const __m128 n_dot_to = Dot3(h.nx, h.ny, h.nz, tx, ty, tz);
  const __m128 inv_d = RsqrtNewton(d2);
  const __m128 lx = _mm_mul_ps(tx, inv_d), ly = _mm_mul_ps(ty, inv_d), lz = _mm_mul_ps(tz, inv_d);
  // Spot: c = -l.a > cos(angle / 2), A = c * smoothstep(min((c - c0) / s, 1)); point lights A = 1.
  const __m128 c = _mm_sub_ps(zero, Dot3(lx, ly, lz, _mm_load_ps(b.ax), _mm_load_ps(b.ay), _mm_load_ps(b.az)));
  const __m128 c0 = _mm_load_ps(b.spot_cos);
  const __m128 lit = _mm_and_ps(_mm_and_ps(_mm_cmplt_ps(q, one), _mm_cmpgt_ps(n_dot_to, zero)),
                                _mm_and_ps(_mm_cmpgt_ps(d2, _mm_set1_ps(1e-12f)), _mm_cmpgt_ps(c, c0)));
  const __m128 u = _mm_min_ps(_mm_mul_ps(_mm_sub_ps(c, c0), _mm_load_ps(b.inv_smooth)), one);
  const __m128 smooth = _mm_mul_ps(_mm_mul_ps(u, u), _mm_sub_ps(_mm_set1_ps(3.0f), _mm_add_ps(u, u)));
  const __m128 is_spot = _mm_load_ps(b.is_spot);
  const __m128 a = _mm_or_ps(_mm_and_ps(is_spot, _mm_mul_ps(c, smooth)), _mm_andnot_ps(is_spot, one));
  const __m128 window = _mm_mul_ps(_mm_sub_ps(one, _mm_mul_ps(q, q)), _mm_sub_ps(one, _mm_mul_ps(q, q)));
  const __m128 inv_d3 = _mm_mul_ps(inv_d, _mm_mul_ps(inv_d, inv_d));
  *geometry = _mm_and_ps(lit, _mm_mul_ps(_mm_mul_ps(window, a), _mm_mul_ps(n_dot_to, inv_d3)));
  const __m128 ir = _mm_load_ps(b.ir), ig = _mm_load_ps(b.ig), ib = _mm_load_ps(b.ib);
  __m128 w = Dot3(h.dr, h.dg, h.db, ir, ig, ib);
  *specular = zero;
  if (h.glossy) {
    const __m128 hx = _mm_add_ps(lx, h.vx), hy = _mm_add_ps(ly, h.vy), hz = _mm_add_ps(lz, h.vz);
    const __m128 len2 = _mm_max_ps(Dot3(hx, hy, hz, hx, hy, hz), _mm_set1_ps(1e-30f));
    const __m128 nh =
        _mm_max_ps(_mm_mul_ps(Dot3(h.nx, h.ny, h.nz, hx, hy, hz), RsqrtNewton(len2)), _mm_set1_ps(1e-30f));
    const __m128 bright = _mm_cmpgt_ps(nh, h.highlight_floor);
    if (_mm_movemask_ps(bright) != 0) {
      *specular = _mm_and_ps(bright, _mm_mul_ps(h.spec_scale, Exp2x4(_mm_mul_ps(h.shininess, Log2x4(nh)))));
      w = _mm_add_ps(w, _mm_mul_ps(*specular, _mm_add_ps(_mm_add_ps(ir, ig), ib)));
    }
  }
  return _mm_mul_ps(w, *geometry);
}

// The unshadowed light of lane `lane` of block b: (albedo / pi + specular) * I * geometry.
inline __m128 LaneDirect(const LightBlock& b, int lane, const LitHit& hit, float geometry, float specular) {
  const __m128 intensity = _mm_setr_ps(b.ir[lane], b.ig[lane], b.ib[lane], 0.0f);
  return _mm_mul_ps(_mm_mul_ps(_mm_add_ps(hit.diffuse, _mm_set1_ps(specular)), intensity), _mm_set1_ps(geometry));
}

// The lights that reach a hit, as lanes of their blocks (unlit lanes weigh 0).
struct LitLights {
  alignas(16) float weight[kMaxLightLanes];  // r + g + b of the unshadowed light
  alignas(16) float geometry[kMaxLightLanes];
  alignas(16) float specular[kMaxLightLanes];
  const LightBlock* block[kMaxLightLanes / 4];
  int num_lanes = 0;
  float total = 0.0f;
  __m128 Direct(int j, const LitHit& hit) const {
    return LaneDirect(*block[j / 4], j % 4, hit, geometry[j], specular[j]);
  }
};

// Removes the blocks none of whose lanes lights the hit; false when there is none.
bool DropUnlitBlocks(LitLights* lit) {
  int kept = 0;
  for (int b = 0; b < lit->num_lanes / 4; ++b) {
    const float* w = lit->weight + 4 * b;
    if (!(w[0] > 0.0f || w[1] > 0.0f || w[2] > 0.0f || w[3] > 0.0f)) continue;
    if (kept != b) {
      std::copy_n(lit->weight + 4 * b, 4, lit->weight + 4 * kept);
      std::copy_n(lit->geometry + 4 * b, 4, lit->geometry + 4 * kept);
      std::copy_n(lit->specular + 4 * b, 4, lit->specular + 4 * kept);
      lit->block[kept] = lit->block[b];
    }
    ++kept;
  }
  const bool freed = 4 * kept < lit->num_lanes;
  lit->num_lanes = 4 * kept;
  return freed;
}

// Evaluates the blocks near the hit without branches into `lit`; when it is full, blocks that light
// nothing make room, and lights beyond that are added to the pixel at once (V = 1).
void GatherLitLights(const RenderJob& job, const LitHit& hit, int local, TileBuffers& tb, LitLights* lit) {
  __m128 total4 = _mm_setzero_ps();
  const LitHitX4 hit4(hit);
  ForEachBlockNear(job.d.light_grid, hit.x, [&](const LightBlock& b) {
    __m128 g, spec;
    const __m128 w = BlockWeights(b, hit4, &g, &spec);
    if (lit->num_lanes == kMaxLightLanes && !DropUnlitBlocks(lit)) {
      alignas(16) float gl[4], sl[4];
      _mm_store_ps(gl, g);
      _mm_store_ps(sl, spec);
      for (int k = 0; k < 4; ++k)
        if (gl[k] > 0.0f) tb.sum[local] = _mm_add_ps(tb.sum[local], LaneDirect(b, k, hit, gl[k], sl[k]));
      return;
    }
    _mm_store_ps(lit->weight + lit->num_lanes, w);
    _mm_store_ps(lit->geometry + lit->num_lanes, g);
    _mm_store_ps(lit->specular + lit->num_lanes, spec);
    lit->block[lit->num_lanes / 4] = &b;
    lit->num_lanes += 4;
    total4 = _mm_add_ps(total4, w);
  });
  alignas(16) float lanes[4];
  _mm_store_ps(lanes, total4);
  lit->total = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
}

// A shadow ray from `origin` to lane j's light carrying `light`, unless the light is closer than the
// ray's start.
void PushLightShadowRay(const LitLights& lit, int j, const Eigen::Vector3f& origin, float offset, int local,
                        __m128 light, TileBuffers& tb, int* num_shadow) {
  const LightBlock& b = *lit.block[j / 4];
  const int lane = j % 4;
  const Eigen::Vector3f to = Eigen::Vector3f(b.px[lane], b.py[lane], b.pz[lane]) - origin;
  const float dist = to.norm();
  if (!(dist > offset + 1e-3f)) return;
  PushShadowRay(tb, num_shadow, origin, to / dist, offset, dist - 1e-3f, local, light, b.light[lane] + 1);
}

// Lights below the share floor (ShadeSettings::min_shadowed_share of the hit's total) are added at once
// (V = 1) and leave the lanes; returns the weight left.
float AddLightsBelowFloor(const RenderJob& job, const LitHit& hit, int local, TileBuffers& tb, LitLights* lit) {
  const float floor_weight = job.settings.min_shadowed_share * lit->total;
  float left = 0.0f;
  for (int j = 0; j < lit->num_lanes; ++j) {
    if (!(lit->weight[j] > 0.0f)) continue;
    if (lit->weight[j] >= floor_weight) {
      left += lit->weight[j];
      continue;
    }
    tb.sum[local] = _mm_add_ps(tb.sum[local], lit->Direct(j, hit));
    lit->weight[j] = 0.0f;
  }
  return left;
}

// The ShadeSettings::max_shadowed_lights strongest lights above the floor get a shadow ray each; the
// others are added at once (V = 1).
void AddStrongestLights(const RenderJob& job, const LitHit& hit, const Eigen::Vector3f& shadow_origin, float offset,
                        int local, LitLights& lit, TileBuffers& tb, int* num_shadow) {
  const int k_max = job.settings.shadows ? std::clamp(job.settings.max_shadowed_lights, 0, kMaxShadowedLights) : 0;
  if (k_max > 0 && job.settings.min_shadowed_share > 0.0f) AddLightsBelowFloor(job, hit, local, tb, &lit);
  int best[kMaxShadowedLights];
  int num_best = 0;
  for (int j = 0; j < lit.num_lanes; ++j) {
    if (!(lit.weight[j] > 0.0f)) continue;
    int c = j;
    if (num_best < k_max) {
      best[num_best++] = c;
      continue;
    }
    int weakest = -1;
    for (int b = 0; b < num_best; ++b)
      if (lit.weight[best[b]] < (weakest < 0 ? lit.weight[c] : lit.weight[best[weakest]])) weakest = b;
    if (weakest >= 0) std::swap(c, best[weakest]);
    tb.sum[local] = _mm_add_ps(tb.sum[local], lit.Direct(c, hit));  // beyond the shadowed ones: V = 1
  }
  for (int b = 0; b < num_best; ++b)
    PushLightShadowRay(lit, best[b], shadow_origin, offset, local, lit.Direct(best[b], hit), tb, num_shadow);
}

// ShadeSettings::sample_lights: of the lights above the floor, one drawn with probability p_i = w_i /
// sum(w) by the inverse CDF at `u`; its shadow ray carries direct_i / p_i.
void AddSampledLight(const RenderJob& job, const LitHit& hit, const Eigen::Vector3f& shadow_origin, float offset,
                     float u, int local, LitLights& lit, TileBuffers& tb, int* num_shadow) {
  const float drawn_total = AddLightsBelowFloor(job, hit, local, tb, &lit);
  if (!(drawn_total > 0.0f)) return;
  // Inverse CDF; rounding may run past the last drawn lane, so it falls back to the last one.
  const float target = u * drawn_total;
  float below = 0.0f;
  int k = -1;
  for (int j = 0; j < lit.num_lanes; ++j) {
    if (!(lit.weight[j] > 0.0f)) continue;
    k = j;
    below += lit.weight[j];
    if (below > target) break;
  }
  const __m128 direct = lit.Direct(k, hit);
  const __m128 estimate =
      lit.weight[k] == drawn_total ? direct : _mm_mul_ps(direct, _mm_set1_ps(drawn_total / lit.weight[k]));
  PushLightShadowRay(lit, k, shadow_origin, offset, local, estimate, tb, num_shadow);
}

}  // namespace

void AddPointLights(const RenderJob& job, int h, const Eigen::Vector3f& x, const Eigen::Vector3f& view,
                    const Eigen::Vector3f& shadow_origin, float offset, float u, int local, TileBuffers& tb,
                    int* num_shadow) {
  const Tracer::Impl& d = job.d;
  const int material = tb.material[h];
  const LitHit hit{x,
                   tb.normal[h],
                   view,
                   _mm_mul_ps(tb.albedo[h], _mm_set1_ps(kInvPi)),
                   d.material_specular[material],
                   d.material_shininess[material],
                   d.material_highlight_floor[material]};
  LitLights lit;
  GatherLitLights(job, hit, local, tb, &lit);
  if (!(lit.total > 0.0f)) return;
  if (job.settings.shadows && job.settings.sample_lights)
    AddSampledLight(job, hit, shadow_origin, offset, u, local, lit, tb, num_shadow);
  else
    AddStrongestLights(job, hit, shadow_origin, offset, local, lit, tb, num_shadow);
}

}  // namespace tracer_internal
}  // namespace rovo
