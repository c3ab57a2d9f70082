#pragma once
/// \file
/// \brief The fluid's values on a membrane's surface, in the membrane's element order, on every
/// rank: what lets the membrane be solved from the same loads whatever the rank count.
///
/// Every rank holds the same membrane (cut by the rank that holds it). On a decomposed
/// mesh each of its faces is owned by the rank that owns the face's cell; that rank writes the
/// face's values (pressure, vector area, area, centroid, and the tractions when asked) into the
/// face's slot and the others write zeros, and one sum over the ranks completes every slot. Each
/// sum adds one value to zeros, so every rank gets the owner's values bit for bit: the membrane's
/// loads do not depend on the rank count. The rank that owns all of a membrane's faces
/// (`ownerRank`) solves it and sends its answer to the others (FsiCoupling). On one rank the sum
/// is a copy.
///
/// Slots: front faces (the patch, or a baffle's master side) in [0, n), a baffle's slave faces in
/// [n, 2n). `gatheredInterface()` indexes them (front(e) = e, back(e) = n + e, no internal
/// faces), so the interface kernels run on the gathered arrays unchanged.
#include "coupling/interface/MembraneInterface.hpp"
#include "fluid/FluidSolver.hpp"

#include <mpi.h>

#include <string>

namespace mfsi::coupling {

class SurfaceGather {
 public:
  SurfaceGather() = default;
  /// `surface` names its nodes and faces by global ids (membraneMeshFromBaffle, cutMembraneOnRanks);
  /// `part` is this rank's mesh (the whole mesh on one rank) and `comm` the ranks (MPI_COMM_NULL:
  /// one rank). Throws InputError when a face of the surface is owned by no rank, or by several.
  SurfaceGather(const HexMesh& part, MPI_Comm comm, const FluidSurfaceMembraneInput& surface, const std::string& name,
                InterfaceSide side);

  /// The interface on the gathered slots, with the membrane nodes' indices in `part` (-1 for a
  /// node the rank does not hold).
  const MembraneInterface& gatheredInterface() const { return iface_; }

  /// Per element, the cell of this rank's part that owns its face on `side` (0: the front, 1: a
  /// baffle's slave side) when this rank owns that cell, else -1: each element's cell is owned by
  /// one rank.
  const std::vector<lid_t>& ownedCells(int side) const { return sides_[side].ownedCell; }
  /// 2 on a baffle, else 1.
  int sides() const { return nSides_; }

  /// The rank that owns every face of the surface (its cells' rank; 0 on one rank), or -1 when
  /// its faces are spread over ranks.
  int ownerRank() const { return owner_; }

  /// Pressure, vector area, area and centroid of every slot from `fluid` (collective).
  void gather(const ExecSpace& exec, const fluid::FluidSolver& fluid);
  /// The pressure and viscous traction of every slot (fluid::boundaryTraction; collective).
  void gatherTraction(const ExecSpace& exec, const fluid::FluidSolver& fluid);

  ConstRealView pressure() const { return pressure_; }
  ConstReal3View faceArea() const { return area_; }
  ConstRealView faceAreaMag() const { return areaMag_; }
  ConstReal3View faceCentroid() const { return centroid_; }
  /// The viscous traction of the front slots, and of the back slots (baffle; empty otherwise).
  ConstReal3View viscousTractionFront() const { return viscousFront_; }
  ConstReal3View viscousTractionBack() const { return viscousBack_; }

  /// Per-element wall velocities (element order) into the fluid's walls on this rank's faces of
  /// the surface (both sides of a baffle).
  void setWallVelocity(const ExecSpace& exec, fluid::FluidSolver& fluid, const ConstReal3View& elementVelocity) const;

  /// Public only because nvcc compiles extended device lambdas solely in public members.
  /// The first `count` entries of `buffer` summed over the ranks (in place).
  void sumOverRanks(const ExecSpace& exec, const RealView& buffer, std::size_t count) const;

  /// The fluid patches of the surface's sides on this rank and, per face of each, its element.
  struct Side {
    std::string patch;
    lid_t patchStart = 0;       ///< first face of the patch on this rank
    IndexView patchElement;     ///< per face of the patch here: its element
    IndexView ownedFace;        ///< per element: its face here if this rank owns it, else -1
    Real3View velocity;         ///< per face of the patch here: wall velocity (work)
    Real3View tractionP, tractionV;  ///< per face of the patch here: boundaryTraction (work)
    std::vector<lid_t> ownedCell;    ///< ownedCells()
  };

 private:
  MPI_Comm comm_ = MPI_COMM_NULL;
  InterfaceSide side_ = InterfaceSide::Patch;
  lid_t nElements_ = 0;
  Side sides_[2];
  int nSides_ = 1;
  int owner_ = -1;
  MembraneInterface iface_;
  RealView pressure_, areaMag_, buffer_;
  Real3View area_, centroid_, viscousFront_, viscousBack_;
};

}  // namespace mfsi::coupling
