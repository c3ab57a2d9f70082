// Mesh motion on 2 ranks: the cases of tests/support/DistributedMotionTests.hpp.
constexpr int kRanks = 2;
#include "support/DistributedMotionTests.hpp"
