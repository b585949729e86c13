#pragma once
// Deterministic random numbers for scene generation. std::mt19937_64's output sequence is fixed by
// the C++ standard, but the std:: distributions are implementation-defined, so the conversions to
// uniform/normal values are written here: the same seed gives the same scene on every platform.

#include <cmath>
#include <cstdint>
#include <random>

namespace rovo {

// SplitMix64 finalizer: decorrelates seeds (e.g. SubSeed(seed, "textures") vs SubSeed(seed, "route")).
inline uint64_t MixSeed(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Independent stream seed for a named purpose and an index.
inline uint64_t SubSeed(uint64_t seed, const char* tag, uint64_t index = 0) {
  uint64_t h = 1469598103934665603ull;
  for (const char* c = tag; *c; ++c) h = (h ^ static_cast<unsigned char>(*c)) * 1099511628211ull;
  return MixSeed(MixSeed(seed ^ h) + index);
}

class SceneRng {
 public:
  explicit SceneRng(uint64_t seed) : engine_(seed) {}

  // Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(engine_() >> 11) * (1.0 / 9007199254740992.0); }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Uniform integer in [lo, hi] (inclusive); the modulo bias is below 2^-40 for the ranges used here.
  int UniformInt(int lo, int hi) {
    const uint64_t span = static_cast<uint64_t>(static_cast<int64_t>(hi) - lo + 1);
    return lo + static_cast<int>(engine_() % span);
  }
  bool Bernoulli(double p) { return Uniform() < p; }
  // Standard normal by Box-Muller (one value per call; no cached pair, so the stream is simple).
  double Normal(double mean = 0.0, double stddev = 1.0) {
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    return mean + stddev * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
  uint64_t Next() { return engine_(); }

 private:
  std::mt19937_64 engine_;
};

}  // namespace rovo
