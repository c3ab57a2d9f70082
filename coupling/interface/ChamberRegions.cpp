#include "coupling/interface/ChamberRegions.hpp"

#include <algorithm>
#include <numeric>

namespace mfsi::coupling {

ChamberRegions findChamberRegions(const HexMesh& mesh, const std::vector<std::string>& pressurePatches) {
  const lid_t nCells = mesh.nCells(), nIn = mesh.nInternalFaces();
  auto own = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceOwner());
  auto nbr = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceNeighbour());
  // Union-find over the internal faces, with path halving.
  std::vector<lid_t> parent(static_cast<std::size_t>(nCells));
  std::iota(parent.begin(), parent.end(), lid_t(0));
  auto root = [&](lid_t c) {
    while (parent[c] != c) c = parent[c] = parent[parent[c]];
    return c;
  };
  for (lid_t f = 0; f < nIn; ++f) {
    const lid_t a = root(own(f)), b = root(nbr(f));
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  ChamberRegions r;
  r.cellRegion.assign(static_cast<std::size_t>(nCells), -1);
  std::vector<int> label(static_cast<std::size_t>(nCells), -1);
  for (lid_t c = 0; c < nCells; ++c) {
    const lid_t top = root(c);
    if (label[top] < 0) label[top] = r.count++;
    r.cellRegion[c] = label[top];
  }
  r.closed.assign(static_cast<std::size_t>(r.count), 1);
  for (const Patch& p : mesh.patches()) {
    if (std::find(pressurePatches.begin(), pressurePatches.end(), p.name) == pressurePatches.end()) continue;
    for (lid_t f = p.start; f < p.start + p.size; ++f) r.closed[r.cellRegion[own(f)]] = 0;
  }
  return r;
}

}  // namespace mfsi::coupling
