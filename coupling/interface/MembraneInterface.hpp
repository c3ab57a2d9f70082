#pragma once
/// \file
/// \brief The matching interface between one membrane and the fluid mesh it was cut from, and
/// the transfers across it.
///
/// A membrane taken from the fluid mesh (a baffle inside the flow, or a one-sided boundary patch
/// such as a cavity bottom or a tube wall) shares its nodes with the fluid mesh, and each membrane
/// element is one fluid face (a baffle: one face on each side). The transfers are then exact:
/// - loads: the element pressure is the face pressure difference across the membrane
///   (p_master - p_slave on a baffle, p_wall - p_outside on a patch), applied by the membrane as a
///   follower pressure on its own (deformed) element; a bilinear quad's vector area is the fluid
///   face's vector area, so the total force equals sum_f p_f S_f to round-off;
/// - motion: membrane node displacements are the fluid nodes' displacements; the membrane's nodal
///   velocities, averaged over a face's four nodes, are the wall velocities on every side.
/// The map is its own small type so that a non-matching map (interpolation between different
/// surface meshes) can stand beside it with the same three transfers.
#include "core/MeshGeometry.hpp"
#include "kernels/CsrAssembly.hpp"
#include "structure/membrane/MembraneMeshImport.hpp"

#include <array>
#include <string>
#include <vector>

namespace mfsi::coupling {

enum class InterfaceSide { Baffle, Patch };

/// \brief Membrane <-> fluid mesh map (device Views).
struct MembraneInterface {
  std::string surface;  ///< the baffle name (both sides) or the patch name: what the fluid calls it
  InterfaceSide side = InterfaceSide::Patch;
  IndexView fluidNode;  ///< membrane node -> fluid node (-1: not on this rank's part of the mesh)
  IndexView front;      ///< membrane element -> boundary face index (f - nInternalFaces) of the master / patch face
  IndexView back;       ///< baffle: element -> boundary face index of the slave face; patch: size 0
  lid_t nNodes() const { return static_cast<lid_t>(fluidNode.extent(0)); }
  lid_t nElements() const { return static_cast<lid_t>(front.extent(0)); }
};

/// \brief The interface of a membrane built by membraneMeshFromBaffle / membraneMeshFromPatch on
/// `mesh`.
MembraneInterface makeMembraneInterface(const HexMesh& mesh, const FluidSurfaceMembraneInput& surface,
                                        const std::string& name, InterfaceSide side);

/// \brief Element pressure from the fluid's boundary-face pressures `pb` (index f - nInternalFaces):
/// scale * (pb(front) - pb(back)) on a baffle, scale * (pb(front) - outside) on a patch, each
/// clamped to [-pClamp, pClamp] when pClamp > 0.
void interfacePressure(const ExecSpace& exec, const MembraneInterface& iface, const ConstRealView& pb, real outside,
                       real scale, real pClamp, const RealView& elementPressure);

/// \brief Total force sum_e p_e S_e with the fluid faces' vector areas `faceArea` (all faces,
/// the current geometry), front side: what the membrane receives.
std::array<double, 3> interfaceForce(const ExecSpace& exec, const MembraneInterface& iface, lid_t nInternalFaces,
                                     const ConstReal3View& faceArea, const ConstRealView& elementPressure);

/// \brief Nodal forces of the fluid's viscous traction: each face's force t |S| (front, plus back
/// on a baffle: the fluid on both sides drags the membrane) times `scale`, a quarter to each of its
/// nodes, gathered per node through the membrane's node -> element map (deterministic). The sum
/// over nodes is the sum over faces: conservative. `tvFront`/`tvBack`: traction per element
/// (fluid::boundaryTraction of the patch / of each baffle side, in face order).
void interfaceViscousForce(const ExecSpace& exec, const MembraneInterface& iface, const NodeItemMap& nodeElements,
                           lid_t nInternalFaces, const ConstRealView& faceAreaMag, const ConstReal3View& tvFront,
                           const ConstReal3View& tvBack, real scale, const Real3View& nodeForce);

/// \brief Elements sharing an edge with each element (CSR), and the reference element areas: what
/// the load smoothing walks.
struct ElementGraph {
  IndexView offsets, neighbours;
  RealView area;
};
ElementGraph elementGraph(const std::vector<std::array<lid_t, 4>>& elements, const std::vector<real>& areas);

/// \brief `iterations` explicit steps of conservative diffusion of the element pressure over the
/// surface (the seed's pNetSmoothIter): p_e += (1 / (8 A_e)) sum_n min(A_e, A_n) (p_n - p_e). The
/// exchange is antisymmetric, so sum_e A_e p_e is kept to round-off; 1/8 keeps it stable for up to
/// four neighbours. `work` has the size of p.
void smoothInterfacePressure(const ExecSpace& exec, const ElementGraph& g, const RealView& p, const RealView& work,
                             int iterations);

/// \brief meshDisplacement(fluidNode(i)) = u(3 i .. 3 i + 2) for every membrane node (a node
/// with fluidNode -1, not on this rank's part of the mesh, is skipped).
void interfaceDisplacement(const ExecSpace& exec, const MembraneInterface& iface, const ConstRealView& u,
                           const Real3View& meshDisplacement);

/// \brief faceVelocity(e) = mean of v over the four nodes of element e (size nElements; the
/// fluid's per-face wall velocity of the patch or of both baffle sides, in face order).
void interfaceFaceVelocity(const ExecSpace& exec, const MembraneInterface& iface, const ConstQuad4View& elements,
                           const ConstRealView& v, const Real3View& faceVelocity);

}  // namespace mfsi::coupling
