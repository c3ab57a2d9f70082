#pragma once
/// \file
/// \brief Membranes mounted on moving rigid bodies (`coupling.parentBodyPatches`, the seed's
/// hierarchical motion): each membrane node follows its parent bodies' frames, and its FEM
/// displacement is relative to them.
///
/// The FEM solves the membrane clamped at zero displacement relative to its frame; a node at
/// reference position X with relative displacement u sits at
///   x = sum_b w_b (c_b + Q_b (X + u - c0_b))
/// (each body's rigid motion from the start, a RigidPlacement), with weights w_b proportional to
/// 1 / d_b^2, d_b the distance from X to the nearest node of body b's listed patches (w = 1 for
/// the body a node lies on; one parent: w = 1 everywhere). A clamped node (u = 0) on a frame is
/// where that body puts the frame's own nodes, so frame and membrane never gap or overlap, and the
/// blend keeps a membrane spanning two independently moving bodies continuous (nearest-body
/// frames would tear it where the nearest body changes). The fluid's load on a mounted membrane is
/// passed on to its parents, each element's share by its nodes' weights; nodal forces (the viscous
/// traction, the inertia of the membrane's mass carried by the accelerating frames, the reaction
/// of its motion relative to them) likewise, each
/// node's by its weights, and they reach the frame-relative FEM rotated into the frames
/// (sum_b w_b Q_b^T f).
#include "core/Types.hpp"
#include "coupling/motion/BodyPatchMotion.hpp"

#include <array>
#include <vector>

namespace mfsi::coupling {

class ParentFrames {
 public:
  ParentFrames() = default;
  /// `nodes`: the membrane's reference node positions; `candidates` and `candidateBody`: the
  /// reference positions of the listed parent patches' nodes and the body slot (0 .. nBodies - 1)
  /// each belongs to. Bodies with no candidate get weight 0.
  ParentFrames(const std::vector<std::array<real, 3>>& nodes, const std::vector<std::array<real, 3>>& candidates,
               const std::vector<int>& candidateBody, int nBodies);

  int nBodies() const { return nBodies_; }
  /// Weight of body `slot` at membrane node i (host).
  double weight(std::size_t i, int slot) const { return hostWeights_[i * static_cast<std::size_t>(nBodies_) + slot]; }

  /// The bodies' current rigid motions (one per slot).
  void setTransforms(const std::vector<RigidPlacement>& transforms);

  /// displacement(fluidNode(i)) = sum_b w_ib (c_b + Q_b (X_i + u_i - c0_b)) - X_i for the
  /// membrane's nodes, with u the relative displacement (3 per node) and X the reference positions.
  /// A node with fluidNode -1 (not on this rank's part of the mesh) is skipped.
  void displacement(const ExecSpace& exec, const ConstReal3View& reference, const ConstRealView& relative,
                    const ConstIndexView& fluidNode, const Real3View& meshDisplacement) const;

  /// x(i) = sum_b w_ib (c_b + Q_b (X_i + u_i - c0_b)): the nodes' current positions.
  void positions(const ExecSpace& exec, const ConstReal3View& reference, const ConstRealView& relative,
                 const Real3View& x) const;

  /// \brief The bodies' accelerations (one per slot, world axes): the centre of mass's c, its
  /// acceleration a, the angular velocity omega and the angular acceleration alpha.
  struct BodyAcceleration {
    std::array<double, 3> centre{0, 0, 0}, acceleration{0, 0, 0}, omega{0, 0, 0}, alpha{0, 0, 0};
  };
  void setAccelerations(const std::vector<BodyAcceleration>& accelerations);
  bool hasAccelerations() const { return accelerations_.extent(0) == static_cast<std::size_t>(nBodies_) && nBodies_ > 0; }
  /// f(i) = -m_i sum_b w_ib (a_b + alpha_b x r + omega_b x (omega_b x r) + 2 omega_b x Q_b v_i),
  /// r = x_i - c_b: the inertial force of node i (lumped mass m_i, position x_i, velocity v_i
  /// relative to its frames, in frame axes, 3 per node) carried along by its frames, with the
  /// Coriolis term of its motion relative to them. The FEM, solved relative to the frames, takes
  /// it as a load; the bodies carry the nodes' masses (their rigid motion's share).
  void inertialForce(const ExecSpace& exec, const ConstReal3View& x, const ConstRealView& relativeVelocity,
                     const ConstRealView& mass, const Real3View& f) const;
  /// f(i) = -m_i sum_b w_ib (Q_b a_i + 2 omega_b x Q_b v_i) (world axes): the inertia of node i's
  /// motion relative to its frames (a_i, v_i its relative acceleration and velocity in frame
  /// axes, 3 per node), what the bodies receive from the membrane on top of the mass they carry:
  /// a panel that swings in its frame pushes the frame back.
  void relativeInertia(const ExecSpace& exec, const ConstRealView& relativeVelocity,
                       const ConstRealView& relativeAcceleration, const ConstRealView& mass, const Real3View& f) const;
  /// Both: `relativeAcceleration` empty gives inertialForce's terms, else relativeInertia's (x unused).
  void frameInertia(const ExecSpace& exec, const ConstReal3View& x, const ConstRealView& relativeVelocity,
                    const ConstRealView& relativeAcceleration, const ConstRealView& mass, const Real3View& f) const;

  /// relative(i) = sum_b w_ib Q_b^T global(i): nodal forces into the frames the FEM is solved in.
  void toFrames(const ExecSpace& exec, const ConstReal3View& global, const Real3View& relative) const;

  /// Force and moment (about `centre`) on body `slot` of nodal forces f at positions x, each
  /// node's share by its weight for the body. Returns {Fx, Fy, Fz, Mx, My, Mz}.
  std::array<double, 6> nodeLoad(const ExecSpace& exec, int slot, const std::array<double, 3>& centre,
                                 const ConstReal3View& x, const ConstReal3View& f) const;

  /// Force and moment (about `centre`) on body `slot` of the element loads F_e = p_e S_f (S_f the
  /// area vector of the element's fluid face f = front(e) + nInternalFaces, what the membrane
  /// receives), each element's share being the mean of its nodes' weights for the body.
  /// Returns {Fx, Fy, Fz, Mx, My, Mz}.
  std::array<double, 6> bodyLoad(const ExecSpace& exec, int slot, const std::array<double, 3>& centre,
                                 const ConstQuad4View& elementNodes, const ConstRealView& elementPressure,
                                 const ConstIndexView& front, lid_t nInternalFaces, const ConstReal3View& faceArea,
                                 const ConstReal3View& faceCentroid) const;

 private:
  Kokkos::View<double**, MemSpace> weights_;  ///< node x body slot
  std::vector<double> hostWeights_;
  Kokkos::View<double* [15], MemSpace> frames_;  ///< per slot: c0 (3), c (3), Q row-major (9)
  Kokkos::View<double* [12], MemSpace> accelerations_;  ///< per slot: c, a, omega, alpha
  int nBodies_ = 0;
};

}  // namespace mfsi::coupling
