#include "coupling/motion/BodyPatchMotion.hpp"

#include "core/Error.hpp"
#include "core/parallel/SharedNodes.hpp"

#include <algorithm>

namespace mfsi::coupling {

BodyPatchMotion::BodyPatchMotion(const HexMesh& mesh, const std::vector<std::string>& patches)
    : BodyPatchMotion(mesh, patches, RankDomain{}) {}

BodyPatchMotion::BodyPatchMotion(const HexMesh& mesh, const std::vector<std::string>& patches,
                                 const RankDomain& domain) {
  const lid_t nn = mesh.nNodes();
  auto fn = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceNodes());
  std::vector<double> on(static_cast<std::size_t>(nn), 0.0);  // 1: a node of the patches' faces
  for (const auto& name : patches) {
    const std::vector<int> indices = patchIndices(mesh, name);
    MFSI_CHECK(!indices.empty(), "body patch motion: no patch or baffle '" << name << "'");
    for (int pi : indices) {
      const auto& patch = mesh.patches()[pi];
      for (lid_t f = patch.start; f < patch.start + patch.size; ++f)
        for (int a = 0; a < 4; ++a) on[fn(f, a)] = 1;
    }
  }
  if (domain.distributed()) {
    // A node the rank holds is the body's when any rank holds a face of the patches at it.
    MFSI_CHECK(domain.nodes.nLocal == nn, "body patch motion: a node plan of " << domain.nodes.nLocal
                                                                               << " nodes for a part of " << nn);
    foldGhostsIntoOwners(domain.comm, domain.nodes, 1, on, [&on](lid_t i, const double* copy) {
      if (*copy != 0) on[i] = 1;
    });
    copyOwnersToGhosts(domain.comm, domain.nodes, 1, on);
    owned_ = domain.nodes.nOwned;
  } else {
    owned_ = nn;
  }
  // In global-id order (on one mesh: the node order).
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.nodeGlobalIds());
  for (lid_t i = 0; i < nn; ++i)
    if (on[i] != 0) hostNodes_.push_back(i);
  std::sort(hostNodes_.begin(), hostNodes_.end(), [&gid](lid_t a, lid_t b) { return gid(a) < gid(b); });
  comm_ = domain.comm;
  for (lid_t v : hostNodes_) globalIds_.push_back(gid(v));
  const lid_t n = static_cast<lid_t>(hostNodes_.size());
  nodes_ = IndexView("mfsi::coupling::bodyPatch::nodes", n);
  reference_ = Real3View("mfsi::coupling::bodyPatch::reference", n);
  auto hn = Kokkos::create_mirror_view(nodes_);
  auto hr = Kokkos::create_mirror_view(reference_);
  auto pts = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.points());
  for (lid_t i = 0; i < n; ++i) {
    hn(i) = hostNodes_[i];
    for (int k = 0; k < 3; ++k) hr(i, k) = pts(hostNodes_[i], k);
  }
  Kokkos::deep_copy(nodes_, hn);
  Kokkos::deep_copy(reference_, hr);
}

std::vector<std::array<real, 3>> BodyPatchMotion::allReferencePoints() const {
  auto X = Kokkos::create_mirror_view_and_copy(HostSpace(), reference_);
  std::vector<std::array<real, 3>> out;
  if (comm_ == MPI_COMM_NULL) {
    for (lid_t i = 0; i < nNodes(); ++i) out.push_back({X(i, 0), X(i, 1), X(i, 2)});
    return out;
  }
  // The owned nodes' rows: every node of the patches is owned by one rank.
  std::vector<gid_t> ids;
  std::vector<double> values;
  for (lid_t i = 0; i < nNodes(); ++i) {
    if (hostNodes_[i] >= owned_) continue;
    ids.push_back(globalIds_[i]);
    values.insert(values.end(), {X(i, 0), X(i, 1), X(i, 2)});
  }
  const GatheredRows rows = gatherRowsEverywhere(comm_, ids, values, 3);
  for (std::size_t i = 0; i < rows.ids.size(); ++i)
    out.push_back({rows.values[3 * i], rows.values[3 * i + 1], rows.values[3 * i + 2]});
  return out;
}

std::vector<int> BodyPatchMotion::patchIndices(const HexMesh& mesh, const std::string& name) {
  const int pi = mesh.findPatch(name);
  if (pi >= 0) return {pi};
  std::vector<int> out;
  for (const char* side : {"_master", "_slave"}) {
    const int s = mesh.findPatch(name + side);
    if (s >= 0) out.push_back(s);
  }
  return out;
}

void BodyPatchMotion::apply(const ExecSpace& exec, const RigidPlacement& T, const Real3View& displacement) const {
  const IndexView nodes = nodes_;
  const Real3View X = reference_;
  const Real3View d = displacement;
  const std::array<real, 15> f = T.flat();
  const real c00 = f[0], c01 = f[1], c02 = f[2], c0 = f[3], c1 = f[4], c2 = f[5];
  const real q00 = f[6], q01 = f[7], q02 = f[8], q10 = f[9], q11 = f[10], q12 = f[11], q20 = f[12], q21 = f[13],
             q22 = f[14];
  Kokkos::parallel_for(
      "mfsi::coupling::bodyPatch::displacement", RangePolicy(exec, 0, nNodes()), KOKKOS_LAMBDA(lid_t i) {
        const lid_t v = nodes(i);
        const real r0 = X(i, 0) - c00, r1 = X(i, 1) - c01, r2 = X(i, 2) - c02;
        d(v, 0) = c0 + q00 * r0 + q01 * r1 + q02 * r2 - X(i, 0);
        d(v, 1) = c1 + q10 * r0 + q11 * r1 + q12 * r2 - X(i, 1);
        d(v, 2) = c2 + q20 * r0 + q21 * r1 + q22 * r2 - X(i, 2);
      });
}

}  // namespace mfsi::coupling
