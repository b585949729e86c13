// Camera rays and the sampler: per-camera pixel-centre bearings (CameraRays), the fixed sample
// pattern, and a tile's camera rays for one sample, for a still or a moving camera.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <optional>

#include "render/tracer_internal.h"

namespace rovo {
namespace tracer_internal {

// A camera ray of a moving camera (render/tracer.h, CameraMotion): the time of sample s of pixel
// pi in row y (s < 0: the pixel centre at the row's mid-exposure), and the pose at that time.
void InitMovingRay(const RenderJob& job, size_t pi, int y, int s, const Eigen::Vector3f& bearing, RTCRayHit* rh) {
  const CameraMotion& m = *job.motion;
  float time = m.time_mid + (static_cast<float>(y) - 0.5f * static_cast<float>(job.height - 1)) * job.row_time_scale;
  if (s >= 0 && job.spp > 1 && m.shutter > 0.0f) {
    const float stratum = job.adaptive ? AdaptiveStratum(job, s) : (s + 0.5f) / static_cast<float>(job.spp);
    const float w = Wrap01(stratum + UnitFloat(Mix64(pi * 0xd1b54a32d192ed03ull + 3)));
    time += (w - 0.5f) * m.shutter;
  }
  time = std::clamp(time, 0.0f, 1.0f);
  const float f = time * static_cast<float>(m.rotation.size() - 1);
  const size_t k = std::min(static_cast<size_t>(f), m.rotation.size() - 2);
  const float a = f - static_cast<float>(k);
  const Eigen::Matrix3f rot = m.rotation[k] + a * (m.rotation[k + 1] - m.rotation[k]);
  const Eigen::Vector3f org = m.origin[k] + a * (m.origin[k + 1] - m.origin[k]);
  InitRay(rh, org, rot * bearing, time);
}

// The camera rays of sample s (-1 or spp == 1: pixel centres) of the tile's valid pixels into
// tb.rayhit / tb.pixel; returns their count.
int MakeSampleRays(const RenderJob& job, const TileRect& t, int s, bool is_centre, TileBuffers& tb) {
  const CameraRays& rays = job.rays;
  const int spp = job.spp;
  int n = 0;
  for (int ly = 0; ly < t.th; ++ly) {
    const size_t row = static_cast<size_t>(t.ty0 + ly) * job.width + t.tx0;
    for (int lx = 0; lx < t.tw; ++lx) {
      const size_t pi = row + lx;
      if (!rays.valid[pi] || (job.adaptive && !tb.active[ly * kTile + lx])) continue;
      Eigen::Vector3f bearing;
      if (is_centre) {
        bearing = rays.bearing[pi];
      } else if (job.precomputed_samples) {
        bearing = rays.sample_bearing[s][pi];
        if (bearing.x() == 0.0f && bearing.y() == 0.0f && bearing.z() == 0.0f) continue;
      } else {
        Eigen::Vector2f offset;
        if (job.settings.rotate_pattern) {
          const uint64_t h = Mix64(pi * 0x632be59bd9b4e019ull + 1);
          offset.x() = Wrap01((s + 0.5f) / spp + UnitFloat(h)) - 0.5f;
          offset.y() = Wrap01(RadicalInverse2(static_cast<uint32_t>(s)) + UnitFloat(Mix64(h))) - 0.5f;
        } else {
          offset = s < 64 ? job.offsets[s] : CameraRays::SampleOffset(s, spp);
        }
        if (!rays.SampleBearing(t.tx0 + lx + offset.x(), t.ty0 + ly + offset.y(), &bearing)) continue;
      }
      if (job.moving) {
        InitMovingRay(job, pi, t.ty0 + ly, is_centre ? -1 : s, bearing, &tb.rayhit[n]);
        tb.pixel_time[ly * kTile + lx] = tb.rayhit[n].ray.time;
      } else {
        InitRay(&tb.rayhit[n], job.origin, job.world_from_cam_rot * bearing, job.motion ? job.motion->time_mid : 0.0f);
      }
      tb.pixel[n] = ly * kTile + lx;
      ++n;
    }
  }
  return n;
}

}  // namespace tracer_internal

using tracer_internal::RadicalInverse2;
using tracer_internal::Wrap01;

Eigen::Vector2f CameraRays::SampleOffset(int s, int spp) {
  if (spp <= 1) return Eigen::Vector2f::Zero();
  const float n = static_cast<float>(spp);
  return Eigen::Vector2f((s + 0.5f) / n - 0.5f, Wrap01(RadicalInverse2(static_cast<uint32_t>(s)) + 0.5f / n) - 0.5f);
}

Eigen::Vector2f CameraRays::AdaptiveSample(int s, int spp, float* stratum) {
  auto bitrev = [](uint32_t j, int bits) {
    uint32_t r = 0;
    for (int b = 0; b < bits; ++b, j >>= 1) r = (r << 1) | (j & 1u);
    return r;
  };
  int m = 0;
  while ((1 << m) < spp) ++m;
  const uint32_t n = 1u << m, mask = n >= 4 ? n / 4 - 1 : 0u;
  const uint32_t j = static_cast<uint32_t>(s) / 2;
  uint32_t column = bitrev(j, m - 1) ^ mask, row = bitrev(j ^ (j >> 1), m) ^ mask;
  if (s % 2 == 1) {
    column = n - 1 - column;
    row = n - 1 - row;
  }
  const float inv = 1.0f / static_cast<float>(n);
  *stratum = (static_cast<float>(column) + 0.5f) * inv;
  return Eigen::Vector2f(*stratum - 0.5f, (static_cast<float>(row) + 0.5f) * inv - 0.5f);
}

namespace {

// Runs `f` in a task arena of `threads` threads (0: the calling arena, all cores).
template <typename F>
void RunWithThreads(int threads, F&& f) {
  if (threads > 0) {
    tbb::task_arena arena(threads);
    arena.execute(f);
  } else {
    f();
  }
}

// The unit bearing of every pixel centre that unprojects inside the field of view.
void UnprojectPixelCentres(const Camera& camera, int threads, CameraRays* rays_out) {
  CameraRays& rays = *rays_out;
  RunWithThreads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& r) {
      for (int y = r.begin(); y < r.end(); ++y) {
        for (int x = 0; x < camera.width; ++x) {
          const std::optional<Eigen::Vector3d> b = camera.Unproject(Eigen::Vector2d(x, y));
          if (!b || !camera.InFov(*b)) continue;
          const size_t i = static_cast<size_t>(y) * camera.width + x;
          rays.bearing[i] = b->normalized().cast<float>();
          rays.valid[i] = 1;
        }
      }
    });
  });
}

// Angular pixel size: mean angle to the valid neighbours among right/left and down/up.
void ComputePixelAngles(const Camera& camera, int threads, CameraRays* rays_out) {
  CameraRays& rays = *rays_out;
  auto angle = [&](size_t i, size_t j) {
    const Eigen::Vector3f& a = rays.bearing[i];
    const Eigen::Vector3f& b = rays.bearing[j];
    return std::atan2(a.cross(b).norm(), a.dot(b));
  };
  RunWithThreads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& r) {
      for (int y = r.begin(); y < r.end(); ++y) {
        for (int x = 0; x < camera.width; ++x) {
          const size_t i = static_cast<size_t>(y) * camera.width + x;
          if (!rays.valid[i]) continue;
          float sum = 0.0f;
          int count = 0;
          for (const int dx : {1, -1}) {
            const int nx = x + dx;
            if (nx < 0 || nx >= camera.width || !rays.valid[i + dx]) continue;
            sum += angle(i, i + dx);
            ++count;
            break;
          }
          for (const int dy : {1, -1}) {
            const int ny = y + dy;
            const size_t j = static_cast<size_t>(ny) * camera.width + x;
            if (ny < 0 || ny >= camera.height || !rays.valid[j]) continue;
            sum += angle(i, j);
            ++count;
            break;
          }
          // An isolated valid pixel: use the equidistant estimate max_fov / diameter.
          rays.pixel_angle[i] =
              count > 0 ? sum / count
                        : static_cast<float>(camera.max_fov_deg * M_PI / 180.0 / std::max(camera.width, camera.height));
        }
      }
    });
  });
}

// The bearings of the fixed `spp`-sample pattern at every valid pixel.
void PrecomputeSampleBearings(const Camera& camera, int threads, int spp, CameraRays* rays_out) {
  CameraRays& rays = *rays_out;
  const size_t n = static_cast<size_t>(camera.width) * camera.height;
  rays.sample_spp = spp;
  rays.sample_bearing.assign(spp, {});
  for (std::vector<Eigen::Vector3f>& v : rays.sample_bearing) v.resize(n);  // every entry is written below
  RunWithThreads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& r) {
      for (int s = 0; s < spp; ++s) {
        const Eigen::Vector2f offset = CameraRays::SampleOffset(s, spp);
        for (int y = r.begin(); y < r.end(); ++y) {
          for (int x = 0; x < camera.width; ++x) {
            const size_t i = static_cast<size_t>(y) * camera.width + x;
            Eigen::Vector3f b;
            rays.sample_bearing[s][i] =
                rays.valid[i] && rays.SampleBearing(x + offset.x(), y + offset.y(), &b) ? b : Eigen::Vector3f::Zero();
          }
        }
      }
    });
  });
}

}  // namespace

CameraRays CameraRays::Make(const Camera& camera, int threads, int spp) {
  CameraRays rays;
  rays.camera = camera;
  rays.width = camera.width;
  rays.height = camera.height;
  const size_t n = static_cast<size_t>(camera.width) * camera.height;
  rays.bearing.assign(n, Eigen::Vector3f::Zero());
  rays.valid.assign(n, 0);
  rays.pixel_angle.assign(n, 0.0f);
  UnprojectPixelCentres(camera, threads, &rays);
  ComputePixelAngles(camera, threads, &rays);
  for (uint8_t v : rays.valid) rays.num_valid += v;
  if (spp > 1 && spp <= kMaxPrecomputedSpp) PrecomputeSampleBearings(camera, threads, spp, &rays);
  return rays;
}

RigCameraRays MakeCameraRays(const std::vector<Camera>& cameras, int threads, int spp) {
  RigCameraRays rays(cameras.size());
  for (size_t i = 0; i < cameras.size(); ++i) {
    const Camera& c = cameras[i];
    size_t same = i;
    for (size_t j = 0; j < i && same == i; ++j) {
      const Camera& o = cameras[j];
      if (o.model == c.model && o.width == c.width && o.height == c.height && o.params == c.params &&
          o.max_fov_deg == c.max_fov_deg)
        same = j;
    }
    rays[i] = same < i ? rays[same] : std::make_shared<const CameraRays>(CameraRays::Make(c, threads, spp));
  }
  return rays;
}

bool CameraRays::SampleBearing(float u, float v, Eigen::Vector3f* bearing_out) const {
  const float x0f = std::floor(u), y0f = std::floor(v);
  const int x0 = static_cast<int>(x0f), y0 = static_cast<int>(y0f);
  if (x0 >= 0 && y0 >= 0 && x0 + 1 < width && y0 + 1 < height) {
    const size_t i00 = static_cast<size_t>(y0) * width + x0;
    const size_t i10 = i00 + 1, i01 = i00 + width, i11 = i01 + 1;
    if (valid[i00] & valid[i10] & valid[i01] & valid[i11]) {
      const float ax = u - x0f, ay = v - y0f;
      const Eigen::Vector3f top = bearing[i00] + ax * (bearing[i10] - bearing[i00]);
      const Eigen::Vector3f bottom = bearing[i01] + ax * (bearing[i11] - bearing[i01]);
      *bearing_out = (top + ay * (bottom - top)).normalized();
      return true;
    }
  }
  const std::optional<Eigen::Vector3d> b = camera.Unproject(Eigen::Vector2d(u, v));
  if (!b || !camera.InFov(*b)) return false;
  *bearing_out = b->normalized().cast<float>();
  return true;
}

}  // namespace rovo
