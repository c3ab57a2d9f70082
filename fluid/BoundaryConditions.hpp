#pragma once
/// \file
/// \brief Fluid boundary conditions: resolves the per-patch options against the mesh patches and
/// keeps the per-face prescribed values (velocity, pressure) on the device.
#include "core/io/Checkpoint.hpp"
#include "core/MeshGeometry.hpp"
#include "fluid/FluidOptions.hpp"
#include "kernels/Blas.hpp"

#include <string>
#include <vector>

namespace mfsi::fluid {

/// \brief What a boundary face imposes, as stored per face on the device.
enum FaceKind : int {
  kFaceVelocity = 0,  ///< prescribed velocity and flux (FixedVelocity, FlowRate)
  kFaceWall = 1,      ///< impermeable: flux = mesh flux, tangential velocity prescribed
  kFaceSlip = 2,      ///< impermeable, free tangential velocity
  kFaceEmpty = 3,     ///< no flux of anything (2D front/back)
  kFacePressure = 4,  ///< prescribed pressure, zero-gradient velocity (FixedPressure, Resistance)
};

/// \brief A patch with its resolved boundary condition.
struct ResolvedPatch {
  std::string name;
  int index = -1;   ///< index in mesh.patches()
  lid_t start = 0;  ///< first face (mesh face index)
  lid_t size = 0;
  BoundaryType type = BoundaryType::Wall;
  PatchBC bc;
  Vec3 boxMin{0, 0, 0};  ///< patch bounding box (reference nodes), for parabolic profiles
  Vec3 boxMax{0, 0, 0};
  real currentPressure = 0;  ///< FixedPressure / Resistance: value last imposed
  real currentFlowRate = 0;  ///< outflow rate through the patch used for the resistance law
  bool open = true;          ///< a valve's state at the last update (its faces walls when closed)
};

/// \brief Per-face boundary data of the fluid (labels `mfsi::fluid::bc::*`). Arrays are indexed by
/// boundary face b = f - nInternalFaces.
class BoundaryConditions {
 public:
  BoundaryConditions() = default;
  /// \brief Resolve `opt.boundaries` against the patches of `mesh`. Throws InputError for unknown
  /// patch names, plain patches without a condition, and inconsistent options.
  /// On a decomposed mesh `comm` spans the ranks: a patch's bounding box (the extent of its
  /// profiles) is then that of all its faces, not this rank's.
  BoundaryConditions(const HexMesh& mesh, const FluidOptions& opt, const SolverComm& comm = {});

  /// \brief Evaluate prescribed values at time t on the current geometry. `faceMeshVelocity`
  /// (per boundary face) feeds walls with `WallMotion::MeshVelocity`.
  void update(const ExecSpace& exec, real t, const MeshGeometry& geo, const ConstReal3View& faceMeshVelocity);
  /// \brief Resistance outlets: p = C_r q + p0 f(t), q = sum of the face fluxes `phi` over the patch.
  void updateResistance(const ExecSpace& exec, const ConstRealView& phi);
  /// \brief Per-face wall velocity (size of the patch) for a patch with `WallMotion::External`, or
  /// for both sides of a baffle when `name` is the baffle's name.
  void setWallVelocity(const std::string& name, const ConstReal3View& v);

  /// Kind of each boundary face (`FaceKind`).
  ConstIndexView kind() const { return kind_; }
  /// Prescribed velocity of velocity and wall faces (walls: before the normal part is set to the mesh's).
  ConstReal3View velocity() const { return velocity_; }
  /// Prescribed pressure of pressure faces.
  ConstRealView pressure() const { return pressure_; }
  /// True when some face prescribes the pressure (otherwise a reference cell fixes its level).
  bool fixesPressureLevel() const { return fixesPressure_; }
  /// True when a pressure patch has a valve: its faces switch between the pressure condition and
  /// a wall (their kind changes with time).
  bool hasValves() const { return hasValves_; }
  const std::vector<ResolvedPatch>& patches() const { return patches_; }
  /// Indices (into patches()) of the patches that `name` designates: a patch, or both baffle sides.
  std::vector<int> find(const std::string& name) const;
  /// The values a later step reads (face values, external wall velocities, each patch's last
  /// pressure and flow rate), for a checkpoint.
  void saveState(io::StateWriter& w) const;
  void loadState(const io::StateReader& r);

 private:
  const HexMesh* mesh_ = nullptr;
  SolverComm comm_;  ///< sums over a patch span the ranks
  lid_t nIn_ = 0;
  lid_t nOwned_ = 0;  ///< a boundary face of a ghost cell is its owner rank's: left out of the sums
  std::vector<bool> ghostFace_;  ///< per boundary face: its owner cell is a ghost
  real time_ = 0;
  bool fixesPressure_ = false;
  bool hasValves_ = false;
  IndexView::HostMirror hKind_;
  std::vector<ResolvedPatch> patches_;
  IndexView kind_;
  Real3View velocity_;
  RealView pressure_;
  Real3View external_;
  Real3View::HostMirror hVelocity_;
  RealView::HostMirror hPressure_;
};

const char* toString(FaceKind k);

}  // namespace mfsi::fluid
