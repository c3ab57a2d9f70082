// Mesh motion on 4 ranks: the cases of tests/support/DistributedMotionTests.hpp.
constexpr int kRanks = 4;
#include "support/DistributedMotionTests.hpp"
