#pragma once
// Run-time choice of AVX2 code in a build for baseline x86-64: a function marked ROVO_TARGET_AVX2 is
// compiled for AVX2 and called only after CpuHasAvx2().

#define ROVO_TARGET_AVX2 __attribute__((target("avx2")))

namespace rovo {

bool CpuHasAvx2();

}  // namespace rovo
