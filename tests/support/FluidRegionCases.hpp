#pragma once
/// \file
/// \brief Two channels parted by a baffle, each its own fluid (FluidOptions::regions): channel A
/// (y in [0, 0.5]) and channel B (y in [0.5, 1], A mirrored in the baffle's plane), fed alike
/// through parabolic inlets; B's fluid is 4 times as dense and 4 times as viscous as A's.
#include "core/BlockMesh.hpp"
#include "fluid/FluidOptions.hpp"

namespace mfsi::test {

inline HexMeshInput twoChannels() {
  BlockMeshSpec spec;
  BlockSpec a, b;
  a.min = {0, 0, 0};
  a.max = {2, 0.5, 0.5};
  a.cells = {10, 4, 3};
  a.patches = {"inA", "outA", "wall", "", "wall", "wall"};
  b = a;
  b.min = {0, 0.5, 0};
  b.max = {2, 1, 0.5};
  b.patches = {"inB", "outB", "", "wall", "wall", "wall"};
  spec.blocks = {a, b};
  spec.baffles.push_back(BaffleRect{"panel", 1, 0.5, {0, 0.5, 0}, {2, 0.5, 0.5}});
  return generateBlockMesh(spec);
}

/// `o` with the two fluids and the channels' boundary conditions.
inline fluid::FluidOptions twoChannelOptions(fluid::FluidOptions o = {}) {
  o.density = 1.0;
  o.viscosity = 0.01;
  o.regions.push_back({"inB", 4.0, 0.04});
  o.boundaries["wall"].type = fluid::BoundaryType::Wall;
  for (const char* in : {"inA", "inB"}) {
    o.boundaries[in].type = fluid::BoundaryType::FlowRate;
    o.boundaries[in].flowRate = 0.05;  // 0.2 m/s mean: Re = 10 on the channel height
    o.boundaries[in].profile = fluid::Profile::Parabolic;
    o.boundaries[in].parabolicAxes = {false, true, true};
  }
  for (const char* out : {"outA", "outB"}) o.boundaries[out].type = fluid::BoundaryType::FixedPressure;
  return o;
}

}  // namespace mfsi::test
