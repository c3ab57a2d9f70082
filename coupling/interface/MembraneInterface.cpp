#include "coupling/interface/MembraneInterface.hpp"

#include "core/Error.hpp"
#include "kernels/Blas.hpp"

#include <algorithm>
#include <map>
#include <utility>

namespace mfsi::coupling {

namespace {
/// A device copy of `v`, each value less `shift` (boundary face ids to patch-local ones).
IndexView toDeviceShifted(const std::vector<lid_t>& v, const std::string& label, lid_t shift) {
  IndexView d(label, v.size());
  auto h = Kokkos::create_mirror_view(d);
  for (std::size_t i = 0; i < v.size(); ++i) h(i) = v[i] - shift;
  Kokkos::deep_copy(d, h);
  return d;
}
}  // namespace

MembraneInterface makeMembraneInterface(const HexMesh& mesh, const FluidSurfaceMembraneInput& surface,
                                        const std::string& name, InterfaceSide side) {
  MFSI_CHECK(side == InterfaceSide::Patch || surface.slaveFace.size() == surface.masterFace.size(),
             "coupling: baffle interface '" << name << "' needs one slave face per master face");
  const lid_t nIn = mesh.nInternalFaces();
  for (lid_t f : surface.masterFace)
    MFSI_CHECK(f >= nIn && f < mesh.nFaces(), "coupling: interface face " << f << " is not a boundary face");
  MembraneInterface m;
  m.surface = name;
  m.side = side;
  std::vector<lid_t> node;  // on one mesh: a node's global id is its index
  for (gid_t g : surface.fluidNode) node.push_back(static_cast<lid_t>(g));
  m.fluidNode = toDevice(node, "mfsi::coupling::interface::fluidNode");
  m.front = toDeviceShifted(surface.masterFace, "mfsi::coupling::interface::front", nIn);
  m.back = side == InterfaceSide::Baffle ? toDeviceShifted(surface.slaveFace, "mfsi::coupling::interface::back", nIn)
                                         : IndexView("mfsi::coupling::interface::back", 0);
  return m;
}

void interfacePressure(const ExecSpace& exec, const MembraneInterface& iface, const ConstRealView& pb, real outside,
                       real scale, real pClamp, const RealView& elementPressure) {
  const ConstIndexView front = iface.front, back = iface.back;
  const bool baffle = iface.side == InterfaceSide::Baffle;
  Kokkos::parallel_for(
      "mfsi::coupling::interface::pressure", RangePolicy(exec, 0, iface.nElements()), KOKKOS_LAMBDA(lid_t e) {
        real p = scale * (pb(front(e)) - (baffle ? pb(back(e)) : outside));
        if (pClamp > 0) p = p > pClamp ? pClamp : (p < -pClamp ? -pClamp : p);
        elementPressure(e) = p;
      });
}

std::array<double, 3> interfaceForce(const ExecSpace& exec, const MembraneInterface& iface, lid_t nInternalFaces,
                                     const ConstReal3View& faceArea, const ConstRealView& elementPressure) {
  const ConstIndexView front = iface.front;
  return blas::reduce<3>(exec, SolverComm{}, "mfsi::coupling::interface::force", iface.nElements(),
                         KOKKOS_LAMBDA(lid_t e, blas::Sums<3> & acc) {
                           for (int k = 0; k < 3; ++k)
                             acc[k] += elementPressure(e) * faceArea(front(e) + nInternalFaces, k);
                         });
}

void interfaceViscousForce(const ExecSpace& exec, const MembraneInterface& iface, const NodeItemMap& nodeElements,
                           lid_t nInternalFaces, const ConstRealView& faceAreaMag, const ConstReal3View& tvFront,
                           const ConstReal3View& tvBack, real scale, const Real3View& nodeForce) {
  const ConstIndexView front = iface.front, back = iface.back, off = nodeElements.offsets,
                       entries = nodeElements.entries;
  const bool baffle = iface.side == InterfaceSide::Baffle;
  const lid_t nIn = nInternalFaces;
  Kokkos::parallel_for(
      "mfsi::coupling::interface::viscousForce", RangePolicy(exec, 0, iface.nNodes()), KOKKOS_LAMBDA(lid_t n) {
        real f[3] = {0, 0, 0};
        for (lid_t k = off(n); k < off(n + 1); ++k) {
          const lid_t e = entries(k) / kMaxItemNodes;
          const real af = 0.25 * scale * faceAreaMag(front(e) + nIn);
          const real ab = baffle ? 0.25 * scale * faceAreaMag(back(e) + nIn) : real(0);
          for (int c = 0; c < 3; ++c) f[c] += af * tvFront(e, c) + (baffle ? ab * tvBack(e, c) : real(0));
        }
        for (int c = 0; c < 3; ++c) nodeForce(n, c) = f[c];
      });
}

ElementGraph elementGraph(const std::vector<std::array<lid_t, 4>>& elements, const std::vector<real>& areas) {
  // Edge -> the elements on it; an interior edge has two.
  std::map<std::pair<lid_t, lid_t>, std::vector<lid_t>> edges;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const int n = elements[e][3] < 0 ? 3 : 4;
    for (int a = 0; a < n; ++a) {
      lid_t i = elements[e][a], j = elements[e][(a + 1) % n];
      if (i > j) std::swap(i, j);
      edges[{i, j}].push_back(static_cast<lid_t>(e));
    }
  }
  std::vector<std::vector<lid_t>> nb(elements.size());
  for (const auto& [edge, els] : edges)
    if (els.size() == 2) {
      nb[els[0]].push_back(els[1]);
      nb[els[1]].push_back(els[0]);
    }
  std::vector<lid_t> off(elements.size() + 1, 0), list;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    std::sort(nb[e].begin(), nb[e].end());
    list.insert(list.end(), nb[e].begin(), nb[e].end());
    off[e + 1] = static_cast<lid_t>(list.size());
  }
  ElementGraph g;
  g.offsets = toDevice(off, "mfsi::coupling::interface::elementOffsets");
  g.neighbours = toDevice(list, "mfsi::coupling::interface::elementNeighbours");
  g.area = RealView("mfsi::coupling::interface::elementArea", areas.size());
  auto ha = Kokkos::create_mirror_view(g.area);
  for (std::size_t e = 0; e < areas.size(); ++e) ha(e) = areas[e];
  Kokkos::deep_copy(g.area, ha);
  return g;
}

void smoothInterfacePressure(const ExecSpace& exec, const ElementGraph& g, const RealView& p, const RealView& work,
                             int iterations) {
  const ConstIndexView off = g.offsets, nb = g.neighbours;
  const ConstRealView area = g.area;
  for (int it = 0; it < iterations; ++it) {
    Kokkos::deep_copy(exec, work, p);
    const ConstRealView in = work;
    Kokkos::parallel_for(
        "mfsi::coupling::interface::smoothPressure", RangePolicy(exec, 0, static_cast<lid_t>(p.extent(0))),
        KOKKOS_LAMBDA(lid_t e) {
          real s = 0;
          for (lid_t k = off(e); k < off(e + 1); ++k) {
            const lid_t n = nb(k);
            const real m = area(e) < area(n) ? area(e) : area(n);
            s += m * (in(n) - in(e));
          }
          p(e) = in(e) + s / (8 * area(e));
        });
  }
}

void interfaceDisplacement(const ExecSpace& exec, const MembraneInterface& iface, const ConstRealView& u,
                           const Real3View& meshDisplacement) {
  const ConstIndexView node = iface.fluidNode;
  Kokkos::parallel_for(
      "mfsi::coupling::interface::displacement", RangePolicy(exec, 0, iface.nNodes()), KOKKOS_LAMBDA(lid_t i) {
        if (node(i) < 0) return;  // not on this rank's part of the mesh
        for (int k = 0; k < 3; ++k) meshDisplacement(node(i), k) = u(3 * i + k);
      });
}

void interfaceFaceVelocity(const ExecSpace& exec, const MembraneInterface& iface, const ConstQuad4View& elements,
                           const ConstRealView& v, const Real3View& faceVelocity) {
  Kokkos::parallel_for(
      "mfsi::coupling::interface::faceVelocity", RangePolicy(exec, 0, iface.nElements()), KOKKOS_LAMBDA(lid_t e) {
        int n = 0;
        real s[3] = {0, 0, 0};
        for (int a = 0; a < 4; ++a) {
          const lid_t node = elements(e, a);
          if (node < 0) continue;
          ++n;
          for (int k = 0; k < 3; ++k) s[k] += v(3 * node + k);
        }
        for (int k = 0; k < 3; ++k) faceVelocity(e, k) = s[k] / n;
      });
}

}  // namespace mfsi::coupling
