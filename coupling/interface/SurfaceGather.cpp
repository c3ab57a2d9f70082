#include "coupling/interface/SurfaceGather.hpp"

#include "core/Error.hpp"
#include "fluid/Loads.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

namespace mfsi::coupling {

namespace {

using FaceKey = std::array<gid_t, 4>;

/// A face named by its nodes' global ids, sorted: the same on the whole mesh and on every part.
template <class FaceNodes, class Gid>
FaceKey faceKey(const FaceNodes& fn, const Gid& gid, lid_t f) {
  FaceKey k;
  for (int a = 0; a < 4; ++a) k[a] = gid(fn(f, a));
  std::sort(k.begin(), k.end());
  return k;
}

FaceKey sorted(FaceKey k) {
  std::sort(k.begin(), k.end());
  return k;
}

/// Slot values packed per slot: pressure, vector area (3), area, centroid (3).
constexpr int kGeometryWidth = 8;

}  // namespace

SurfaceGather::SurfaceGather(const HexMesh& part, MPI_Comm comm, const FluidSurfaceMembraneInput& surface,
                             const std::string& name, InterfaceSide side)
    : comm_(comm), side_(side), nElements_(surface.nElements()) {
  const lid_t n = nElements_;
  nSides_ = side == InterfaceSide::Baffle ? 2 : 1;
  MFSI_CHECK(nSides_ == 1 || surface.slaveFaceNodes.size() == surface.masterFaceNodes.size(),
             "coupling: baffle interface '" << name << "' needs one slave face per master face");
  auto pfn = Kokkos::create_mirror_view_and_copy(HostSpace(), part.faceNodes());
  auto pown = Kokkos::create_mirror_view_and_copy(HostSpace(), part.faceOwner());
  auto pgid = Kokkos::create_mirror_view_and_copy(HostSpace(), part.nodeGlobalIds());
  const lid_t nIn = part.nInternalFaces();
  std::vector<int> owners(static_cast<std::size_t>(nSides_ * n), 0);
  for (int s = 0; s < nSides_; ++s) {
    Side& sd = sides_[s];
    sd.patch = side == InterfaceSide::Patch ? name : name + (s == 0 ? "_master" : "_slave");
    const std::vector<FaceKey>& faces = s == 0 ? surface.masterFaceNodes : surface.slaveFaceNodes;
    std::map<FaceKey, lid_t> element;
    for (lid_t e = 0; e < n; ++e) element[sorted(faces[e])] = e;
    const int pi = part.findPatch(sd.patch);
    std::vector<lid_t> patchElement, ownedFace(static_cast<std::size_t>(n), -1);
    sd.ownedCell.assign(static_cast<std::size_t>(n), -1);
    if (pi >= 0) {
      const Patch& p = part.patches()[pi];
      sd.patchStart = p.start;
      for (lid_t f = p.start; f < p.start + p.size; ++f) {
        const auto it = element.find(faceKey(pfn, pgid, f));
        MFSI_CHECK(it != element.end(), "coupling: a face of patch '" << sd.patch << "' on this rank is not on " << name);
        patchElement.push_back(it->second);
        if (pown(f) < part.nOwnedCells()) {
          ownedFace[it->second] = f - nIn;
          sd.ownedCell[it->second] = pown(f);
          ++owners[static_cast<std::size_t>(s * n + it->second)];
        }
      }
    }
    sd.patchElement = toDevice(patchElement, "mfsi::coupling::surface::patchElement");
    sd.ownedFace = toDevice(ownedFace, "mfsi::coupling::surface::ownedFace");
    const std::size_t m = patchElement.size();
    sd.velocity = Real3View("mfsi::coupling::surface::wallVelocity", m);
    sd.tractionP = Real3View("mfsi::coupling::surface::pressureTraction", m);
    sd.tractionV = Real3View("mfsi::coupling::surface::viscousTraction", m);
  }
  // The rank that owns every face of the surface (a decomposition keeps a membrane's cells on one
  // rank), if one does.
  long long mine = 0;
  for (int o : owners) mine += o;
  int rank = 0;
  if (comm_ != MPI_COMM_NULL) MPI_Comm_rank(comm_, &rank);
  owner_ = mine == static_cast<long long>(owners.size()) ? rank : -1;
  if (comm_ != MPI_COMM_NULL) {
    MPI_Allreduce(MPI_IN_PLACE, &owner_, 1, MPI_INT, MPI_MAX, comm_);
    MPI_Allreduce(MPI_IN_PLACE, owners.data(), static_cast<int>(owners.size()), MPI_INT, MPI_SUM, comm_);
  }
  for (std::size_t k = 0; k < owners.size(); ++k)
    if (owners[k] != 1)
      throw InputError("coupling: face " + std::to_string(k % static_cast<std::size_t>(n)) + " of " + name +
                       (k >= static_cast<std::size_t>(n) ? " (slave side)" : "") + " is owned by " +
                       std::to_string(owners[k]) +
                       " ranks instead of one (a baffle split between ranks whose cells do not neighbour)");

  // The membrane nodes on this rank's part.
  std::unordered_map<gid_t, lid_t> local;
  for (lid_t i = 0; i < part.nNodes(); ++i) local.emplace(pgid(i), i);
  std::vector<lid_t> node;
  for (gid_t v : surface.fluidNode) {
    const auto it = local.find(v);
    node.push_back(it != local.end() ? it->second : -1);
  }
  std::vector<lid_t> front(static_cast<std::size_t>(n)), back;
  for (lid_t e = 0; e < n; ++e) front[e] = e;
  if (nSides_ == 2)
    for (lid_t e = 0; e < n; ++e) back.push_back(n + e);
  iface_.surface = name;
  iface_.side = side;
  iface_.fluidNode = toDevice(node, "mfsi::coupling::surface::node");
  iface_.front = toDevice(front, "mfsi::coupling::surface::front");
  iface_.back = toDevice(back, "mfsi::coupling::surface::back");

  buffer_ = RealView("mfsi::coupling::surface::buffer", static_cast<std::size_t>(2 * n * kGeometryWidth));
  pressure_ = RealView("mfsi::coupling::surface::pressure", 2 * n);
  areaMag_ = RealView("mfsi::coupling::surface::areaMag", 2 * n);
  area_ = Real3View("mfsi::coupling::surface::area", 2 * n);
  centroid_ = Real3View("mfsi::coupling::surface::centroid", 2 * n);
  viscousFront_ = Real3View("mfsi::coupling::surface::viscousFront", n);
  viscousBack_ = Real3View("mfsi::coupling::surface::viscousBack", nSides_ == 2 ? n : 0);
}

void SurfaceGather::sumOverRanks(const ExecSpace& exec, const RealView& buffer, std::size_t count) const {
  if (comm_ == MPI_COMM_NULL) return;
  exec.fence();
  auto h = Kokkos::create_mirror_view(buffer);
  Kokkos::deep_copy(h, buffer);
  // One contribution per slot, zeros elsewhere: the sum is the owner's value exactly, in any order.
  MPI_Allreduce(MPI_IN_PLACE, h.data(), static_cast<int>(count), MPI_DOUBLE, MPI_SUM, comm_);
  Kokkos::deep_copy(buffer, h);
}

void SurfaceGather::gather(const ExecSpace& exec, const fluid::FluidSolver& fluid) {
  const RealView buf = buffer_;
  Kokkos::deep_copy(exec, buf, 0.0);
  const ConstRealView pb = fluid.boundaryPressure();
  const ConstReal3View S = fluid.geometry().faceArea, C = fluid.geometry().faceCentroid;
  const ConstRealView A = fluid.geometry().faceAreaMag;
  const lid_t n = nElements_, nIn = fluid.mesh().nInternalFaces();
  for (int s = 0; s < nSides_; ++s) {
    const ConstIndexView owned = sides_[s].ownedFace;
    const lid_t base = s * n;
    Kokkos::parallel_for(
        "mfsi::coupling::surface::pack", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t e) {
          const lid_t b = owned(e);
          if (b < 0) return;
          real* v = &buf((base + e) * kGeometryWidth);
          const lid_t f = b + nIn;
          v[0] = pb(b);
          for (int c = 0; c < 3; ++c) v[1 + c] = S(f, c);
          v[4] = A(f);
          for (int c = 0; c < 3; ++c) v[5 + c] = C(f, c);
        });
  }
  sumOverRanks(exec, buf, static_cast<std::size_t>(nSides_ * n * kGeometryWidth));  // a patch has no back slots
  const RealView p = pressure_, am = areaMag_;
  const Real3View a = area_, ce = centroid_;
  Kokkos::parallel_for(
      "mfsi::coupling::surface::unpack", RangePolicy(exec, 0, 2 * n), KOKKOS_LAMBDA(lid_t k) {
        const real* v = &buf(k * kGeometryWidth);
        p(k) = v[0];
        for (int c = 0; c < 3; ++c) a(k, c) = v[1 + c];
        am(k) = v[4];
        for (int c = 0; c < 3; ++c) ce(k, c) = v[5 + c];
      });
}

void SurfaceGather::gatherTraction(const ExecSpace& exec, const fluid::FluidSolver& fluid) {
  (void)fluid.velocityGradient();  // formed on every rank (it exchanges ghosts), with or without faces here
  const RealView buf = buffer_;  // 3 values per slot
  Kokkos::deep_copy(exec, buf, 0.0);
  const lid_t n = nElements_, nIn = fluid.mesh().nInternalFaces();
  for (int s = 0; s < nSides_; ++s) {
    const Side& sd = sides_[s];
    const lid_t m = static_cast<lid_t>(sd.patchElement.extent(0));
    if (m == 0) continue;
    exec.fence();
    fluid::boundaryTraction(fluid, sd.patch, sd.tractionP, sd.tractionV);
    const ConstIndexView element = sd.patchElement, owned = sd.ownedFace;
    const ConstReal3View tv = sd.tractionV;
    const lid_t base = s * n, first = sd.patchStart - nIn;
    Kokkos::parallel_for(
        "mfsi::coupling::surface::packTraction", RangePolicy(exec, 0, m), KOKKOS_LAMBDA(lid_t k) {
          const lid_t e = element(k);
          if (owned(e) != first + k) return;  // a ghost cell's face: its owner sends it
          for (int c = 0; c < 3; ++c) buf(3 * (base + e) + c) = tv(k, c);
        });
  }
  sumOverRanks(exec, buf, static_cast<std::size_t>(3 * nSides_ * n));  // 3 per slot of the sides there are
  const Real3View front = viscousFront_, back = viscousBack_;
  const bool baffle = nSides_ == 2;
  Kokkos::parallel_for(
      "mfsi::coupling::surface::unpackTraction", RangePolicy(exec, 0, n), KOKKOS_LAMBDA(lid_t e) {
        for (int c = 0; c < 3; ++c) {
          front(e, c) = buf(3 * e + c);
          if (baffle) back(e, c) = buf(3 * (n + e) + c);
        }
      });
}

void SurfaceGather::setWallVelocity(const ExecSpace& exec, fluid::FluidSolver& fluid,
                                    const ConstReal3View& elementVelocity) const {
  for (int s = 0; s < nSides_; ++s) {
    const Side& sd = sides_[s];
    const ConstIndexView element = sd.patchElement;
    const Real3View v = sd.velocity;
    Kokkos::parallel_for(
        "mfsi::coupling::surface::wallVelocity", RangePolicy(exec, 0, static_cast<lid_t>(element.extent(0))),
        KOKKOS_LAMBDA(lid_t k) {
          for (int c = 0; c < 3; ++c) v(k, c) = elementVelocity(element(k), c);
        });
    exec.fence();
    fluid.setWallVelocity(sd.patch, v);
  }
}

}  // namespace mfsi::coupling
