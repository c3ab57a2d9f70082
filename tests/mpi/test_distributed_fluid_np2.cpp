// The fluid on 2 ranks: the cases of tests/support/DistributedFluidTests.hpp.
constexpr int kRanks = 2;
#include "support/DistributedFluidTests.hpp"
