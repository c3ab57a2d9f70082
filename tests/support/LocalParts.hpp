#pragma once
/// \file
/// \brief Helpers of the decomposition tests: meshes with a baffle, and partitions good and bad.
#include "core/BlockMesh.hpp"
#include "core/HexMesh.hpp"
#include "core/parallel/Halo.hpp"
#include "core/parallel/LocalMesh.hpp"
#include "core/parallel/Partition.hpp"

#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace mfsi::test {

/// A long thin box (40 x 4 x 2 cells) with a baffle across its middle (x = 0.5), so ghosts,
/// patches and a baffle all cross rank boundaries; with `rightEnd`, its face at x = 1 is that
/// patch (the rest stay the default patch).
inline HexMeshInput longBoxWithBaffle(const std::string& rightEnd = "") {
  BlockMeshSpec spec = boxSpec({0, 0, 0}, {1, 0.1, 0.05}, {40, 4, 2});
  if (!rightEnd.empty()) spec.blocks[0].patches = {"", rightEnd, "", "", "", ""};
  BaffleRect b;
  b.name = "panel";
  b.axis = 0;
  b.position = 0.5;
  b.min = {0.5, 0.0, 0.0};
  b.max = {0.5, 0.1, 0.05};
  spec.baffles.push_back(b);
  return generateBlockMesh(spec);
}

/// METIS options for `ranks` ranks that keep the cells on both sides of longBoxWithBaffle's
/// panel on one rank (as a run keeps a membrane's cells together).
inline PartitionOptions keepPanelTogether(const HexMeshInput& in, int ranks) {
  PartitionOptions opt;
  opt.parts = ranks;
  std::vector<lid_t> panel;
  for (std::size_t c = 0; c < in.cells.size(); ++c) {
    double x = 0;
    for (lid_t n : in.cells[c]) x += in.points[n][0] / 8;
    if (std::abs(x - 0.5) < 0.03) panel.push_back(static_cast<lid_t>(c));
  }
  opt.keepTogether = {panel};
  return opt;
}

/// METIS over `parts` ranks with the default options.
inline std::vector<int> metisParts(const HexMeshInput& in, int parts) {
  PartitionOptions opt;
  opt.parts = parts;
  return partitionCells(in, opt).cellRank;
}

/// A deliberately bad partition: every cell on a random rank (fixed seed), so nearly every face
/// is cut and most cells are ghosts somewhere.
inline std::vector<int> randomPartition(std::size_t nCells, int ranks, unsigned seed = 12345) {
  std::mt19937 gen(seed);
  std::uniform_int_distribution<int> pick(0, ranks - 1);
  std::vector<int> r(nCells);
  for (auto& x : r) x = pick(gen);
  for (int k = 0; k < ranks && static_cast<std::size_t>(k) < nCells; ++k) r[k] = k;  // no empty rank
  return r;
}

/// The domain of a rank's part on MPI_COMM_WORLD.
inline RankDomain worldDomain(const LocalMeshPart& part) {
  RankDomain domain;
  domain.comm = MPI_COMM_WORLD;
  domain.cells = part.cells;
  domain.nodes = part.nodes;
  domain.incompleteNode = part.incompleteNode;
  return domain;
}

}  // namespace mfsi::test
