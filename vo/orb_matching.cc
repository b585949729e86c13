#include "vo/orb_matching.h"

#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace rovo {
namespace {

// The two smallest Hamming distances seen, and the index of the smallest (the first on ties).
struct TopTwo {
  int best = std::numeric_limits<int>::max(), second = std::numeric_limits<int>::max();
  int index = -1;
  void Add(int d, int i) {
    if (d < best) {
      second = best;
      best = d;
      index = i;
    } else if (d < second) {
      second = d;
    }
  }
};

using OrbWords = std::array<uint64_t, 4>;  // one 256-bit ORB descriptor

std::vector<OrbWords> DescriptorWords(const cv::Mat& desc) {
  if (desc.type() != CV_8U || desc.cols != 32)
    throw std::invalid_argument("MutualRatioOrbMatches: descriptors must be 32-byte CV_8U rows");
  std::vector<OrbWords> out(desc.rows);
  for (int i = 0; i < desc.rows; ++i) std::memcpy(out[i].data(), desc.ptr<uint8_t>(i), 32);
  return out;
}

// Every Hamming distance between `a` and `b` once, kept as each row's and each column's two nearest
// (BFMatcher::knnMatch with k = 2 both ways computes the matrix twice, with a byte-table popcount).
#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target_clones("popcnt", "default")))
#endif
void NearestTwoBothWays(const std::vector<OrbWords>& a, const std::vector<OrbWords>& b, std::vector<TopTwo>* in_b,
                        std::vector<TopTwo>* in_a) {
  in_b->assign(a.size(), TopTwo());
  in_a->assign(b.size(), TopTwo());
  for (size_t i = 0; i < a.size(); ++i) {
    const OrbWords& x = a[i];
    TopTwo row;
    for (size_t j = 0; j < b.size(); ++j) {
      const OrbWords& y = b[j];
      const int d = __builtin_popcountll(x[0] ^ y[0]) + __builtin_popcountll(x[1] ^ y[1]) +
                    __builtin_popcountll(x[2] ^ y[2]) + __builtin_popcountll(x[3] ^ y[3]);
      row.Add(d, static_cast<int>(j));
      (*in_a)[j].Add(d, static_cast<int>(i));
    }
    (*in_b)[i] = row;
  }
}

}  // namespace

std::vector<std::pair<int, int>> MutualRatioOrbMatches(const cv::Mat& desc_a, const cv::Mat& desc_b, double max_ratio,
                                                       int max_distance) {
  std::vector<std::pair<int, int>> out;
  if (desc_a.rows < 2 || desc_b.rows < 2) return out;
  std::vector<TopTwo> ab, ba;
  NearestTwoBothWays(DescriptorWords(desc_a), DescriptorWords(desc_b), &ab, &ba);
  auto best = [&](const TopTwo& m) {
    if (m.best > max_distance) return -1;
    if (m.best > max_ratio * m.second) return -1;
    return m.index;
  };
  for (int i = 0; i < static_cast<int>(ab.size()); ++i) {
    const int j = best(ab[i]);
    if (j >= 0 && best(ba[j]) == i) out.emplace_back(i, j);
  }
  return out;
}

}  // namespace rovo
