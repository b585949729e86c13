// The lights' state of the tracer: per-material emission and specular tables, the lights' world
// placement at a frame and the 3-D light grid of blocks of four lights (render/tracer_internal.h).
#include <algorithm>
#include <cmath>
#include <cstring>

#include "render/tracer_internal.h"

namespace rovo {

// Per-material emission and specular tables; the lights' constant parts (world-fixed lights are
// placed here, lights on objects by PlaceLights).
void Tracer::Impl::SetUpLights() {
  material_emission.assign(scene.materials.size(), {0.0f, 0.0f, 0.0f, 0.0f});
  material_specular.assign(scene.materials.size(), 0.0f);
  material_shininess.assign(scene.materials.size(), 0.0f);
  material_highlight_floor.assign(scene.materials.size(), 0.0f);
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const Material& mat = scene.materials[m];
    if (mat.IsEmissive()) any_emission = true;
    material_emission[m] = {mat.emission.x(), mat.emission.y(), mat.emission.z(), 0.0f};
    material_specular[m] = mat.specular;
    material_shininess[m] = mat.shininess;
    if (mat.shininess > 0.0f)
      material_highlight_floor[m] = std::pow(tracer_internal::kNegligibleHighlight, 1.0f / mat.shininess);
  }
  lights.resize(scene.lights.size());
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& in = scene.lights[i];
    if (in.object >= static_cast<int>(scene.objects.size()))
      throw std::invalid_argument("light '" + in.name + "': object index " + std::to_string(in.object) +
                                  " out of range");
    ShadeLight& l = lights[i];
    l.intensity = in.intensity;
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

namespace {

using LightBlock = Tracer::Impl::LightBlock;

LightBlock EmptyBlock() {
  LightBlock b;
  for (int k = 0; k < 4; ++k) {
    b.px[k] = b.py[k] = b.pz[k] = 1e18f;  // beyond any range: q = d^2 / 1 >= 1
    b.inv_range2[k] = 1.0f;
    b.ax[k] = b.ay[k] = b.az[k] = 0.0f;
    b.spot_cos[k] = -2.0f;
    b.inv_smooth[k] = std::numeric_limits<float>::infinity();
    b.is_spot[k] = 0.0f;
    b.ir[k] = b.ig[k] = b.ib[k] = 0.0f;
    b.light[k] = LightBlock::kNoLight;
  }
  return b;
}

void SetLane(const Tracer::Impl::ShadeLight& l, uint32_t index, int k, LightBlock* b) {
  b->px[k] = l.position.x();
  b->py[k] = l.position.y();
  b->pz[k] = l.position.z();
  b->inv_range2[k] = l.inv_range2;
  if (l.spot) {
    b->ax[k] = l.spot_axis.x();
    b->ay[k] = l.spot_axis.y();
    b->az[k] = l.spot_axis.z();
    b->spot_cos[k] = l.spot_cos;
    if (l.spot_smooth > 0.0f) b->inv_smooth[k] = 1.0f / l.spot_smooth;
    const uint32_t all = 0xffffffffu;
    std::memcpy(&b->is_spot[k], &all, sizeof(float));
  }
  b->ir[k] = l.intensity.x();
  b->ig[k] = l.intensity.y();
  b->ib[k] = l.intensity.z();
  b->light[k] = index;
}

// Appends the lights `indices[0, n)` as blocks of four.
void AppendBlocks(const std::vector<Tracer::Impl::ShadeLight>& lights, const uint32_t* indices, size_t n,
                  std::vector<LightBlock>* out) {
  for (size_t i = 0; i < n; i += 4) {
    LightBlock b = EmptyBlock();
    for (size_t k = 0; k < 4 && i + k < n; ++k)
      SetLane(lights[indices[i + k]], indices[i + k], static_cast<int>(k), &b);
    out->push_back(b);
  }
}

// Whether a sphere (centre v relative to a cone's apex, radius rho) meets the cone of unit axis `axis`
// and half-angle alpha (cos_a, sin_a), alpha <= 90 degrees (Eberly, "Intersection of a Sphere and a
// Cone": the cone moved back by rho / sin(alpha) contains the sphere's centre, and the centre is not
// behind the apex farther than rho).
bool SphereMeetsCone(const Eigen::Vector3f& v, float rho, const Eigen::Vector3f& axis, float cos_a, float sin_a) {
  const Eigen::Vector3f shifted = v + (rho / sin_a) * axis;
  const float e = axis.dot(shifted);
  if (!(e > 0.0f && e * e >= shifted.squaredNorm() * cos_a * cos_a)) return false;
  const float back = -axis.dot(v);
  if (back > 0.0f && back * back >= v.squaredNorm() * sin_a * sin_a) return v.squaredNorm() <= rho * rho;
  return true;
}

// Whether light l may reach some point of the axis-aligned box [lo, hi]: the box comes closer than
// the range (exact), and for a spot of up to 180 degrees, the box's bounding sphere meets the cone
// (conservative); wider spots are not culled.
bool LightMayReachBox(const Tracer::Impl::ShadeLight& l, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  const Eigen::Vector3f gap = (lo - l.position).cwiseMax(l.position - hi).cwiseMax(0.0f);
  if (gap.squaredNorm() * l.inv_range2 >= 1.0f) return false;
  if (!l.spot || l.spot_cos < 0.0f) return true;
  const Eigen::Vector3f v = 0.5f * (lo + hi) - l.position;
  const float rho = 0.5001f * (hi - lo).norm();
  return SphereMeetsCone(v, rho, l.spot_axis, l.spot_cos, std::sqrt(1.0f - l.spot_cos * l.spot_cos));
}

// Calls visit(cell) for each cell of the grid that light l (with a range) may reach.
template <typename F>
void ForEachCellReached(const Tracer::Impl::LightGrid& g, const Tracer::Impl::ShadeLight& l, F&& visit) {
  const float cell = 1.0f / g.inv_cell, r = 1.0f / std::sqrt(l.inv_range2);
  const Eigen::Vector3f origin(g.x0, g.y0, g.z0);
  const int n[3] = {g.nx, g.ny, g.nz};
  int c0[3], c1[3];
  for (int a = 0; a < 3; ++a) {
    c0[a] = std::clamp(static_cast<int>((l.position[a] - r - origin[a]) * g.inv_cell), 0, n[a] - 1);
    c1[a] = std::clamp(static_cast<int>((l.position[a] + r - origin[a]) * g.inv_cell), 0, n[a] - 1);
  }
  for (int cz = c0[2]; cz <= c1[2]; ++cz)
    for (int cy = c0[1]; cy <= c1[1]; ++cy)
      for (int cx = c0[0]; cx <= c1[0]; ++cx) {
        const Eigen::Vector3f lo = origin + cell * Eigen::Vector3f(cx, cy, cz);
        if (LightMayReachBox(l, lo, lo + Eigen::Vector3f::Constant(cell)))
          visit((static_cast<size_t>(cz) * g.ny + cy) * g.nx + cx);
      }
}

}  // namespace

// Cubic cells of a quarter of the median range (at least 1 m, at most kMaxCells cells) over the
// lights' range spheres; a light is listed in the cells it may reach (LightMayReachBox). The lights
// without a range form the unbounded blocks.
void Tracer::Impl::BuildLightGrid() {
  constexpr double kMaxCells = 1 << 20;
  LightGrid& g = light_grid;
  g = LightGrid();
  std::vector<float> ranges;
  std::vector<uint32_t> unbounded;
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (uint32_t i = 0; i < lights.size(); ++i) {
    const ShadeLight& l = lights[i];
    if (l.inv_range2 <= 0.0f) {
      unbounded.push_back(i);
      continue;
    }
    const float r = 1.0f / std::sqrt(l.inv_range2);
    ranges.push_back(r);
    lo = lo.cwiseMin(l.position - Eigen::Vector3f::Constant(r));
    hi = hi.cwiseMax(l.position + Eigen::Vector3f::Constant(r));
  }
  AppendBlocks(lights, unbounded.data(), unbounded.size(), &g.unbounded);
  if (ranges.empty()) return;
  std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
  const Eigen::Vector3f extent = hi - lo;
  float cell = std::max(1.0f, 0.25f * ranges[ranges.size() / 2]);
  cell = std::max(cell, static_cast<float>(std::cbrt(static_cast<double>(extent.prod()) / kMaxCells)));
  g.x0 = lo.x();
  g.y0 = lo.y();
  g.z0 = lo.z();
  // Larger cells until the rounded-up counts fit (a flat spread rounds its thin axis up to one cell).
  for (;; cell *= 1.25f) {
    g.inv_cell = 1.0f / cell;
    g.nx = std::max(1, static_cast<int>(std::ceil(extent.x() * g.inv_cell)));
    g.ny = std::max(1, static_cast<int>(std::ceil(extent.y() * g.inv_cell)));
    g.nz = std::max(1, static_cast<int>(std::ceil(extent.z() * g.inv_cell)));
    if (static_cast<double>(g.nx) * g.ny * g.nz <= kMaxCells) break;
  }
  // Two passes over the lights' spheres: count, then fill a CSR list of light indices per cell.
  const size_t num_cells = static_cast<size_t>(g.nx) * g.ny * g.nz;
  std::vector<uint32_t> begin(num_cells + 1, 0), items;
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<uint32_t> fill(pass == 0 ? 0 : num_cells, 0);
    for (uint32_t i = 0; i < lights.size(); ++i) {
      const ShadeLight& l = lights[i];
      if (l.inv_range2 <= 0.0f) continue;
      ForEachCellReached(g, l, [&](size_t c) {
        if (pass == 0)
          ++begin[c + 1];
        else
          items[begin[c] + fill[c]++] = i;
      });
    }
    if (pass == 0) {
      for (size_t c = 1; c <= num_cells; ++c) begin[c] += begin[c - 1];
      items.resize(begin.back());
    }
  }
  // Each cell's lights as blocks of four.
  g.cell_begin.assign(num_cells + 1, 0);
  for (size_t c = 0; c < num_cells; ++c) {
    AppendBlocks(lights, items.data() + begin[c], begin[c + 1] - begin[c], &g.blocks);
    g.cell_begin[c + 1] = static_cast<uint32_t>(g.blocks.size());
  }
}

}  // namespace rovo
