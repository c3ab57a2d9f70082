#pragma once
/// \file
/// \brief The distributed fluid tests themselves, for the rank count `kRanks` that the including
/// file (tests/mpi/test_distributed_fluid_np<N>.cpp) defines: PIMPLE steps on each rank's part
/// give the whole mesh's velocity and pressure to 1e-10, and the same bits when repeated, for a 3D
/// lid-driven cavity (METIS and a random, ghost-heavy partition), the cavity on a distorted mesh
/// (non-orthogonal corrections), the unstructured Gmsh cylinder mesh (its inlet profile spans
/// ranks at 4) and two channels of two fluids parted by a baffle (FluidOptions::regions: each
/// rank finds which of its cells hold which fluid) on a random partition.
#include "core/parallel/Partition.hpp"
#include "support/DistributedFluid.hpp"
#include "support/DistributedFluidCases.hpp"
#include "support/FluidRegionCases.hpp"
#include "support/LocalParts.hpp"

TEST(DistributedFluid, CavityOnMetisParts) {
  const mfsi::HexMeshInput in = mfsi::test::cavityCube(8);
  mfsi::test::checkDistributedFluid(in, mfsi::test::cavityOptions(), mfsi::test::metisParts(in, kRanks), 4, 0.05);
}

TEST(DistributedFluid, CavityOnARandomPartition) {
  const mfsi::HexMeshInput in = mfsi::test::cavityCube(6);
  mfsi::test::checkDistributedFluid(in, mfsi::test::cavityOptions(),
                                    mfsi::test::randomPartition(in.cells.size(), kRanks), 3, 0.05);
}

TEST(DistributedFluid, DistortedCavity) {
  const mfsi::HexMeshInput in = mfsi::test::cavityCube(8, 0.25);
  mfsi::test::checkDistributedFluid(in, mfsi::test::cavityOptions(1), mfsi::test::metisParts(in, kRanks), 3, 0.05);
}

TEST(DistributedFluid, UnstructuredCylinder) {
  const mfsi::HexMeshInput in = mfsi::test::gradedCylinder();
  mfsi::test::checkDistributedFluid(in, mfsi::test::cylinderOptions(), mfsi::test::metisParts(in, kRanks), 3, 0.01);
}

TEST(DistributedFluid, TwoFluidsOnARandomPartition) {
  const mfsi::HexMeshInput in = mfsi::test::twoChannels();
  const mfsi::fluid::FluidOptions o = mfsi::test::twoChannelOptions(mfsi::test::tightOptions());
  mfsi::test::checkDistributedFluid(in, o, mfsi::test::randomPartition(in.cells.size(), kRanks), 3, 0.05);
}
