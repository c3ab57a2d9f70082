#include "core/parallel/Partition.hpp"

#include "core/Error.hpp"

#include <metis.h>

#include <algorithm>
#include <fstream>
#include <string>
#include <map>
#include <numeric>

namespace mfsi {

namespace {

using Quad = std::array<lid_t, 4>;

Quad sortedQuad(lid_t a, lid_t b, lid_t c, lid_t d) {
  Quad q{a, b, c, d};
  std::sort(q.begin(), q.end());
  return q;
}

/// Union-find over cells with path halving; the root of a set is its smallest cell.
struct Groups {
  std::vector<lid_t> parent;
  explicit Groups(lid_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  lid_t find(lid_t c) {
    while (parent[c] != c) c = parent[c] = parent[parent[c]];
    return c;
  }
  void join(lid_t a, lid_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (b < a) std::swap(a, b);
    parent[b] = a;
  }
};

/// CSR of per-cell neighbour lists (each sorted on the way).
CellGraph toGraph(std::vector<std::vector<lid_t>>& adj) {
  const lid_t nCells = static_cast<lid_t>(adj.size());
  CellGraph g;
  g.offsets.assign(nCells + 1, 0);
  for (lid_t c = 0; c < nCells; ++c) {
    std::sort(adj[c].begin(), adj[c].end());
    g.offsets[c + 1] = g.offsets[c] + static_cast<lid_t>(adj[c].size());
    g.neighbours.insert(g.neighbours.end(), adj[c].begin(), adj[c].end());
  }
  return g;
}

}  // namespace

CellGraph cellDualGraph(const HexMeshInput& mesh) {
  const lid_t nCells = static_cast<lid_t>(mesh.cells.size());
  // Each face as its sorted node quad, with the cell it belongs to; equal quads are shared faces.
  std::vector<std::pair<Quad, lid_t>> faces;
  faces.reserve(6 * mesh.cells.size());
  for (lid_t c = 0; c < nCells; ++c) {
    const auto& cn = mesh.cells[c];
    for (const auto& f : kHexFaces) faces.emplace_back(sortedQuad(cn[f[0]], cn[f[1]], cn[f[2]], cn[f[3]]), c);
  }
  std::sort(faces.begin(), faces.end());
  std::vector<std::vector<lid_t>> adj(nCells);
  for (std::size_t i = 0; i + 1 < faces.size(); ++i) {
    if (faces[i].first != faces[i + 1].first) continue;
    const lid_t a = faces[i].second, b = faces[i + 1].second;
    if (a != b) {
      adj[a].push_back(b);
      adj[b].push_back(a);
    }
    ++i;
  }
  return toGraph(adj);
}

Partition describePartition(const CellGraph& graph, std::vector<int> cellRank, int parts) {
  Partition p;
  p.parts = parts;
  p.cellsPerRank.assign(parts, 0);
  const lid_t nCells = static_cast<lid_t>(cellRank.size());
  for (lid_t c = 0; c < nCells; ++c) {
    MFSI_CHECK(cellRank[c] >= 0 && cellRank[c] < parts,
               "partition: cell " << c << " is given rank " << cellRank[c] << ", outside [0, " << parts << ")");
    ++p.cellsPerRank[cellRank[c]];
    for (lid_t k = graph.offsets[c]; k < graph.offsets[c + 1]; ++k)
      if (graph.neighbours[k] > c && cellRank[graph.neighbours[k]] != cellRank[c]) ++p.edgeCut;
  }
  const double mean = static_cast<double>(nCells) / parts;
  p.imbalance = mean > 0 ? *std::max_element(p.cellsPerRank.begin(), p.cellsPerRank.end()) / mean : 1;
  p.cellRank = std::move(cellRank);
  return p;
}

Partition partitionGraph(const CellGraph& graph, const PartitionOptions& options) {
  const lid_t nCells = static_cast<lid_t>(graph.offsets.size()) - 1;
  const int parts = options.parts;
  MFSI_CHECK(parts >= 1, "partition: the number of ranks must be at least 1 (got " << parts << ")");
  MFSI_CHECK(options.cellWeights.empty() || static_cast<lid_t>(options.cellWeights.size()) == nCells,
             "partition: " << options.cellWeights.size() << " cell weights for " << nCells << " cells");
  if (parts == 1) return describePartition(graph, std::vector<int>(nCells, 0), 1);

  // Contract the groups: unit u = a set of cells that moves together.
  Groups groups(nCells);
  for (const auto& g : options.keepTogether) {
    for (lid_t c : g) MFSI_CHECK(c >= 0 && c < nCells, "partition: a kept-together cell " << c << " is not a cell");
    for (std::size_t i = 1; i < g.size(); ++i) groups.join(g[0], g[i]);
  }
  std::vector<lid_t> unitOf(nCells, -1);
  lid_t nUnits = 0;
  for (lid_t c = 0; c < nCells; ++c) {
    const lid_t r = groups.find(c);
    if (unitOf[r] < 0) unitOf[r] = nUnits++;
    unitOf[c] = unitOf[r];
  }
  MFSI_CHECK(parts <= nUnits, "partition: " << parts << " ranks for " << nUnits
                                            << " cells (after keeping each membrane's and baffle's cells together): "
                                               "use at most "
                                            << nUnits << " ranks");
  std::vector<idx_t> vwgt(nUnits, 0);
  for (lid_t c = 0; c < nCells; ++c) vwgt[unitOf[c]] += options.cellWeights.empty() ? 1 : options.cellWeights[c];
  std::vector<std::map<lid_t, idx_t>> uadj(nUnits);
  for (lid_t c = 0; c < nCells; ++c)
    for (lid_t k = graph.offsets[c]; k < graph.offsets[c + 1]; ++k) {
      const lid_t a = unitOf[c], b = unitOf[graph.neighbours[k]];
      if (a != b) ++uadj[a][b];
    }
  std::vector<idx_t> xadj(nUnits + 1, 0), adjncy, adjwgt;
  for (lid_t u = 0; u < nUnits; ++u) {
    for (const auto& [v, w] : uadj[u]) {
      adjncy.push_back(v);
      adjwgt.push_back(w);
    }
    xadj[u + 1] = static_cast<idx_t>(adjncy.size());
  }
  idx_t nv = nUnits, ncon = 1, np = parts, objval = 0;
  std::vector<idx_t> part(nUnits, 0);
  idx_t opts[METIS_NOPTIONS];
  METIS_SetDefaultOptions(opts);
  opts[METIS_OPTION_SEED] = options.seed;
  opts[METIS_OPTION_NUMBERING] = 0;
  // An empty adjacency (disconnected units) is legal; METIS wants non-null arrays.
  if (adjncy.empty()) {
    adjncy.push_back(0);
    adjwgt.push_back(0);
  }
  const int rc = METIS_PartGraphKway(&nv, &ncon, xadj.data(), adjncy.data(), vwgt.data(), nullptr, adjwgt.data(),
                                     &np, nullptr, nullptr, opts, &objval, part.data());
  MFSI_CHECK(rc == METIS_OK, "partition: METIS failed (code " << rc << ") on " << nUnits << " units into " << parts
                                                               << " parts");
  std::vector<int> cellRank(nCells);
  for (lid_t c = 0; c < nCells; ++c) cellRank[c] = static_cast<int>(part[unitOf[c]]);
  return describePartition(graph, std::move(cellRank), parts);
}

Partition partitionCells(const HexMeshInput& mesh, const PartitionOptions& options) {
  return partitionGraph(cellDualGraph(mesh), options);
}

CellGraph cellDualGraph(const HexMesh& mesh) {
  const lid_t nCells = mesh.nCells();
  auto owner = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.faceOwner());
  auto neighbour = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.faceNeighbour());
  std::vector<std::vector<lid_t>> adj(nCells);
  auto join = [&](lid_t a, lid_t b) {
    adj[a].push_back(b);
    adj[b].push_back(a);
  };
  for (lid_t f = 0; f < mesh.nInternalFaces(); ++f) join(owner(f), neighbour(f));
  for (const Patch& p : mesh.patches())
    if (p.kind == PatchKind::BaffleMaster) {
      const Patch& slave = mesh.patches()[p.pairedPatch];
      for (lid_t i = 0; i < p.size; ++i) join(owner(p.start + i), owner(slave.start + i));
    }
  return toGraph(adj);
}

std::vector<int> readPartitionMap(const std::string& file, std::size_t nCells, int ranks) {
  std::ifstream in(file);
  if (!in) throw InputError("--partition '" + file + "': cannot read the file");
  std::vector<int> map;
  std::vector<std::size_t> cells(static_cast<std::size_t>(ranks), 0);
  std::string line;
  for (long long no = 1; std::getline(in, line); ++no) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto last = line.find_last_not_of(" \t\r");
    const std::string t = line.substr(first, last - first + 1);
    long long r = -1;
    if (t.size() <= 6 && t.find_first_not_of("0123456789") == std::string::npos) r = std::stoll(t);
    if (r < 0 || r >= ranks)
      throw InputError(file + ":" + std::to_string(no) + ": '" + t + "' is not a rank of this run (0 to " +
                       std::to_string(ranks - 1) + ")");
    if (map.size() == nCells)
      throw InputError(file + ":" + std::to_string(no) + ": more lines than the mesh's " + std::to_string(nCells) +
                       " cells (a map of another mesh?)");
    map.push_back(static_cast<int>(r));
    ++cells[static_cast<std::size_t>(r)];
  }
  if (map.size() != nCells)
    throw InputError(file + ": " + std::to_string(map.size()) + " cells mapped, the mesh has " + std::to_string(nCells) +
                     " (a map of another mesh?)");
  for (int r = 0; r < ranks; ++r)
    if (cells[static_cast<std::size_t>(r)] == 0)
      throw InputError(file + ": rank " + std::to_string(r) + " gets no cell (a map for fewer ranks than the " +
                       std::to_string(ranks) + " this run has?)");
  return map;
}

}  // namespace mfsi
