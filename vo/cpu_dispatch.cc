#include "vo/cpu_dispatch.h"

namespace rovo {

bool CpuHasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2") != 0;
  return has;
}

}  // namespace rovo
