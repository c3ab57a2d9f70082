// The fluid on 4 ranks: the cases of tests/support/DistributedFluidTests.hpp.
constexpr int kRanks = 4;
#include "support/DistributedFluidTests.hpp"
