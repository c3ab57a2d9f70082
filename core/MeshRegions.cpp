#include "core/MeshRegions.hpp"

#include "core/parallel/SharedNodes.hpp"

#include <algorithm>
#include <numeric>

namespace mfsi {

namespace {

/// The cells' components through the mesh's internal faces (union-find with path halving): per
/// cell, the index of its component's root cell.
std::vector<lid_t> cellComponents(const HexMesh& mesh) {
  const lid_t nCells = mesh.nCells(), nIn = mesh.nInternalFaces();
  auto own = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceOwner());
  auto nbr = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceNeighbour());
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
  for (lid_t c = 0; c < nCells; ++c) parent[c] = root(c);
  return parent;
}

/// Every cell's label <- the least label in its component; true when one changed.
bool spreadLeastLabel(const std::vector<lid_t>& component, std::vector<double>& label) {
  std::vector<double> least(label.size(), 0);
  for (std::size_t c = 0; c < label.size(); ++c) least[c] = label[c];
  for (std::size_t c = 0; c < label.size(); ++c)
    least[component[c]] = std::min(least[component[c]], label[c]);
  bool changed = false;
  for (std::size_t c = 0; c < label.size(); ++c) {
    changed = changed || least[component[c]] != label[c];
    label[c] = least[component[c]];
  }
  return changed;
}

}  // namespace

MeshRegions findMeshRegions(const HexMesh& mesh, const std::vector<std::string>& patches,
                            const RankDomain& domain) {
  const lid_t nCells = mesh.nCells();
  auto own = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceOwner());
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.cellGlobalIds());
  // A region is named by its cell of least global id. On a rank's part a region may leave the part
  // and come back, or be joined through other ranks' cells: the labels travel through the cell
  // halo (each ghost's into its owner, the owner's back to every copy) until no rank's change.
  const std::vector<lid_t> component = cellComponents(mesh);
  std::vector<double> label(static_cast<std::size_t>(nCells));
  for (lid_t c = 0; c < nCells; ++c) label[c] = static_cast<double>(gid(c));  // exact below 2^53
  spreadLeastLabel(component, label);
  if (domain.distributed()) {
    for (;;) {
      foldGhostsIntoOwners(domain.comm, domain.cells, 1, label,
                           [&label](lid_t c, const double* copy) { label[c] = std::min(label[c], *copy); });
      copyOwnersToGhosts(domain.comm, domain.cells, 1, label);
      int changed = spreadLeastLabel(component, label) ? 1 : 0;
      MPI_Allreduce(MPI_IN_PLACE, &changed, 1, MPI_INT, MPI_MAX, domain.comm);
      if (changed == 0) break;
    }
  }
  // The regions, and those a face of the patches opens, on every rank.
  std::vector<gid_t> labels, open;
  for (lid_t c = 0; c < nCells; ++c) labels.push_back(static_cast<gid_t>(label[c]));
  for (const Patch& p : mesh.patches()) {
    if (std::find(patches.begin(), patches.end(), p.name) == patches.end()) continue;
    for (lid_t f = p.start; f < p.start + p.size; ++f) open.push_back(labels[own(f)]);
  }
  auto distinct = [](std::vector<gid_t> v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    return v;
  };
  labels = distinct(labels);
  open = distinct(open);
  if (domain.distributed()) {
    labels = gatherRowsEverywhere(domain.comm, labels, {}, 0).ids;
    open = gatherRowsEverywhere(domain.comm, open, {}, 0).ids;
  }
  MeshRegions r;
  r.count = static_cast<int>(labels.size());
  r.firstCell = labels;
  r.closed.assign(labels.size(), 1);
  for (gid_t g : open) r.closed[std::lower_bound(labels.begin(), labels.end(), g) - labels.begin()] = 0;
  r.cellRegion.resize(static_cast<std::size_t>(nCells));
  for (lid_t c = 0; c < nCells; ++c)
    r.cellRegion[c] = static_cast<int>(
        std::lower_bound(labels.begin(), labels.end(), static_cast<gid_t>(label[c])) - labels.begin());
  return r;
}

}  // namespace mfsi
