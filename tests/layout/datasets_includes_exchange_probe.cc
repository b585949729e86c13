// Layout probe (tests/CMakeLists.txt): built against rovo_datasets, the bottom library. The first include
// must be found; the second must fail to compile, because the exchange formats sit above the dataset format.
#include "datasets/exchange/exchange.h"
#include "datasets/rig.h"
