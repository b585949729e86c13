// Layout probe (tests/CMakeLists.txt): built against rovo_eval, which depends on datasets alone. The first
// include must be found; the second must fail to compile, because scoring may not use the VO.
#include "eval/metrics.h"
#include "vo/pipeline.h"
