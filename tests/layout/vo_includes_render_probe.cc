// Layout probe (tests/CMakeLists.txt): built against rovo_vo. The first include must be found; the second
// must fail to compile, because the VO never depends on the renderer.
#include "render/render.h"
#include "vo/pipeline.h"
