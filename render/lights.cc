// Point and spot lights: per-material emission and specular tables, the lights' world placement
// at a frame, the 2-D light grid, and their contribution at a hit (formula: render/tracer.h).
#include <algorithm>

#include "render/tracer_internal.h"

namespace rovo {
namespace tracer_internal {

namespace {

// The lights that may reach world point x: the grid cell's list (empty outside the grid), then the
// lights without a range.
template <typename F>
void ForEachLightNear(const Tracer::Impl::LightGrid& g, const Eigen::Vector3f& x, F&& visit) {
  if (g.nx > 0) {
    const float fx = (x.x() - g.x0) * g.inv_cell, fy = (x.y() - g.y0) * g.inv_cell;
    if (fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(g.nx) && fy < static_cast<float>(g.ny)) {
      const size_t c = static_cast<size_t>(static_cast<int>(fy)) * g.nx + static_cast<int>(fx);
      for (uint32_t k = g.cell_begin[c]; k < g.cell_begin[c + 1]; ++k) visit(g.items[k]);
    }
  }
  for (uint32_t i : g.unbounded) visit(i);
}

}  // namespace

void AddPointLights(const RenderJob& job, int h, const Eigen::Vector3f& x, const Eigen::Vector3f& view,
                    const Eigen::Vector3f& shadow_origin, float offset, int local, TileBuffers& tb, int* num_shadow) {
  const Tracer::Impl& d = job.d;
  const Eigen::Vector3f& n = tb.normal[h];
  const int material = tb.material[h];
  const float ks = d.material_specular[material], shininess = d.material_shininess[material];
  const __m128 diffuse = _mm_mul_ps(tb.albedo[h], _mm_set1_ps(kInvPi));
  const int k_max = job.settings.shadows ? std::clamp(job.settings.max_shadowed_lights, 0, kMaxShadowedLights) : 0;
  struct Candidate {
    float rank;
    uint32_t light;
    __m128 direct;
  };
  Candidate best[kMaxShadowedLights];
  int num_best = 0;
  ForEachLightNear(d.light_grid, x, [&](uint32_t i) {
    const Tracer::Impl::ShadeLight& l = d.lights[i];
    const Eigen::Vector3f to = l.position - x;
    const float d2 = to.squaredNorm();
    float weight = 1.0f;  // A * W
    if (l.inv_range2 > 0.0f) {
      const float q = d2 * l.inv_range2;
      if (q >= 1.0f) return;
      weight = (1.0f - q * q) * (1.0f - q * q);
    }
    const float n_dot_to = n.dot(to);
    if (n_dot_to <= 0.0f || !(d2 > 1e-12f)) return;  // behind the surface: no square root needed
    const float inv_d = 1.0f / std::sqrt(d2);
    const Eigen::Vector3f to_light = to * inv_d;
    const float cos_light = n_dot_to * inv_d;
    if (l.spot) {
      const float c = -to_light.dot(l.spot_axis);
      if (c <= l.spot_cos) return;
      const float t = c - l.spot_cos;
      float a = c;
      if (t < l.spot_smooth) {
        const float u = t / l.spot_smooth;
        a *= u * u * (3.0f - 2.0f * u);
      }
      weight *= a;
    }
    const float geometry = weight * cos_light / d2;
    __m128 brdf = diffuse;
    if (ks > 0.0f) {
      const float nh = std::max(0.0f, n.dot((to_light + view).normalized()));
      brdf = _mm_add_ps(brdf, _mm_set1_ps(ks * (shininess + 8.0f) * (kInvPi / 8.0f) * std::pow(nh, shininess)));
    }
    Candidate c{l.rank_intensity * geometry, i,
                _mm_mul_ps(brdf, _mm_mul_ps(Load3(l.intensity), _mm_set1_ps(geometry)))};
    if (num_best < k_max) {
      best[num_best++] = c;
      return;
    }
    int weakest = -1;
    for (int b = 0; b < num_best; ++b)
      if (best[b].rank < (weakest < 0 ? c.rank : best[weakest].rank)) weakest = b;
    if (weakest >= 0) std::swap(c, best[weakest]);
    tb.sum[local] = _mm_add_ps(tb.sum[local], c.direct);  // beyond the shadowed ones: V = 1
  });
  for (int b = 0; b < num_best; ++b) {
    const Eigen::Vector3f to = d.lights[best[b].light].position - shadow_origin;
    const float dist = to.norm();
    if (!(dist > offset + 1e-3f)) continue;
    PushShadowRay(tb, num_shadow, shadow_origin, to / dist, offset, dist - 1e-3f, local, best[b].direct);
  }
}

}  // namespace tracer_internal

// Per-material emission and specular tables; the lights' constant parts (world-fixed lights are
// placed here, lights on objects by PlaceLights).
void Tracer::Impl::SetUpLights() {
  material_emission.assign(scene.materials.size(), {0.0f, 0.0f, 0.0f, 0.0f});
  material_specular.assign(scene.materials.size(), 0.0f);
  material_shininess.assign(scene.materials.size(), 0.0f);
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const Material& mat = scene.materials[m];
    if (mat.IsEmissive()) any_emission = true;
    material_emission[m] = {mat.emission.x(), mat.emission.y(), mat.emission.z(), 0.0f};
    material_specular[m] = mat.specular;
    material_shininess[m] = mat.shininess;
  }
  lights.resize(scene.lights.size());
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& in = scene.lights[i];
    if (in.object >= static_cast<int>(scene.objects.size()))
      throw std::invalid_argument("light '" + in.name + "': object index " + std::to_string(in.object) +
                                  " out of range");
    ShadeLight& l = lights[i];
    l.intensity = in.intensity;
    l.rank_intensity = in.intensity.sum();
    l.inv_range2 = in.range > 0.0 ? static_cast<float>(1.0 / (in.range * in.range)) : 0.0f;
    l.spot = in.spot;
    if (in.spot) {
      const double c0 = std::cos(0.5 * in.spot_angle_deg * M_PI / 180.0);
      l.spot_cos = static_cast<float>(c0);
      l.spot_smooth = static_cast<float>((1.0 - c0) * in.spot_blend);
    }
    if (in.object >= 0 && scene.objects[in.object].IsDynamic()) lights_move = true;
  }
  if (!lights.empty()) PlaceLights(0);
}

// World positions and spot axes of the lights at `frame` (objects that move: their pose at the
// frame), then the light grid.
void Tracer::Impl::PlaceLights(int frame) {
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& in = scene.lights[i];
    Rigid3 world_from_light_frame = Rigid3::Identity();
    if (in.object >= 0) {
      const Object& obj = scene.objects[in.object];
      if (!obj.IsDynamic()) {
        world_from_light_frame = obj.world_from_object;
      } else if (frame >= 0 && frame < static_cast<int>(obj.world_from_object_per_frame.size())) {
        world_from_light_frame = obj.world_from_object_per_frame[frame];
      }
    }
    ShadeLight& l = lights[i];
    l.position = (world_from_light_frame * in.position).cast<float>();
    if (in.spot) l.spot_axis = (world_from_light_frame.rotation * in.spot_direction).normalized().cast<float>();
  }
  BuildLightGrid();
}

// Cells of about half the median range (at least 1 m, at most 1024 x 1024 cells) over the range
// discs of the lights that have a range.
void Tracer::Impl::BuildLightGrid() {
  LightGrid& g = light_grid;
  g = LightGrid();
  std::vector<float> ranges;
  Eigen::Vector2f lo(std::numeric_limits<float>::max(), std::numeric_limits<float>::max()), hi = -lo;
  for (uint32_t i = 0; i < lights.size(); ++i) {
    const ShadeLight& l = lights[i];
    if (l.inv_range2 <= 0.0f) {
      g.unbounded.push_back(i);
      continue;
    }
    const float r = 1.0f / std::sqrt(l.inv_range2);
    ranges.push_back(r);
    lo = lo.cwiseMin(l.position.head<2>() - Eigen::Vector2f::Constant(r));
    hi = hi.cwiseMax(l.position.head<2>() + Eigen::Vector2f::Constant(r));
  }
  if (ranges.empty()) return;
  std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
  float cell = std::max(1.0f, 0.5f * ranges[ranges.size() / 2]);
  cell = std::max(cell, std::max(hi.x() - lo.x(), hi.y() - lo.y()) / 1024.0f);
  g.x0 = lo.x();
  g.y0 = lo.y();
  g.inv_cell = 1.0f / cell;
  g.nx = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) * g.inv_cell)));
  g.ny = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) * g.inv_cell)));
  // Two passes over the lights' cell rectangles: count, then fill.
  std::vector<uint32_t> count(static_cast<size_t>(g.nx) * g.ny + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    for (uint32_t i = 0; i < lights.size(); ++i) {
      const ShadeLight& l = lights[i];
      if (l.inv_range2 <= 0.0f) continue;
      const float r = 1.0f / std::sqrt(l.inv_range2);
      const int cx0 = std::clamp(static_cast<int>((l.position.x() - r - g.x0) * g.inv_cell), 0, g.nx - 1);
      const int cx1 = std::clamp(static_cast<int>((l.position.x() + r - g.x0) * g.inv_cell), 0, g.nx - 1);
      const int cy0 = std::clamp(static_cast<int>((l.position.y() - r - g.y0) * g.inv_cell), 0, g.ny - 1);
      const int cy1 = std::clamp(static_cast<int>((l.position.y() + r - g.y0) * g.inv_cell), 0, g.ny - 1);
      for (int cy = cy0; cy <= cy1; ++cy)
        for (int cx = cx0; cx <= cx1; ++cx) {
          const size_t c = static_cast<size_t>(cy) * g.nx + cx;
          if (pass == 0)
            ++count[c + 1];
          else
            g.items[g.cell_begin[c] + count[c]++] = i;
        }
    }
    if (pass == 0) {
      for (size_t c = 1; c < count.size(); ++c) count[c] += count[c - 1];
      g.cell_begin = count;
      g.items.resize(count.back());
      std::fill(count.begin(), count.end(), 0);
    }
  }
}

}  // namespace rovo
