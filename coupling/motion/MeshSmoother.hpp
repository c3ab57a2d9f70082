#pragma once
/// \file
/// \brief Interior mesh motion by Jacobi point-Laplacian smoothing of the displacement from the
/// reference mesh (the seed's section 3.3), with a quality guard.
///
/// The orchestrator writes the displacement of every boundary node (membrane nodes from the
/// structure, frame and wall nodes from their bodies or zero) into `displacement()`, then calls
/// `move`: the interior nodes' displacement is smoothed from its last value (warm start), the
/// points become reference + displacement, and the minimum scaled Jacobian is checked. Smoothing
/// the displacement, not the positions, keeps a graded mesh whose boundary does not move
/// bit-identical (zero stays exactly zero), and a warm start needs few sweeps per FSI iteration.
#include "core/io/Checkpoint.hpp"
#include "core/MeshGeometry.hpp"
#include "kernels/JacobiSmoothing.hpp"
#include "kernels/LaplacianCg.hpp"

#include "core/parallel/Halo.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace mfsi::coupling {

/// How the point-Laplacian of the displacement is treated.
enum class MeshMotionMethod {
  Jacobi,             ///< `sweeps` Jacobi sweeps from the last displacement (the seed's smoother)
  /// Solved to `relTol` by Jacobi-preconditioned CG from the last displacement, with the edge
  /// weights 1 / L^2 of the stiffened smoother (no retries: a solved field is what it is).
  ConjugateGradient,
};

struct MeshSmootherOptions {
  int sweeps = 50;  ///< Jacobi sweeps per motion
  /// Quality guard: below this minimum scaled Jacobian the motion is retried (more sweeps, then the
  /// stiffened smoother); an inverted cell (<= 0) after every retry stops the run.
  double minScaledJacobian = 0.05;
  /// Retries: the first ones double the sweeps each time; the last uses the stiffened smoother,
  /// whose edge weights 1 / L^2 (L the reference edge length) make small cells move more rigidly.
  int retries = 3;
  MeshMotionMethod method = MeshMotionMethod::Jacobi;
  double relTol = 1e-5;      ///< CG: residual per motion, relative to the larger of the warm start's residual and the field's scale
  int maxIterations = 2000;  ///< CG: iterations per motion
  /// CG: the preconditioner (Jacobi: O(N) cheap iterations; AMG: a few V-cycles per component).
  LaplacianPreconditioner preconditioner = LaplacianPreconditioner::Amg;
  /// CG: edge weights 1 / L^2 times 1 / d^q, d the reference distance of the edge's midpoint from
  /// the nearest moving node (setMovingNodes); 0: off.
  double distanceExponent = 0;
  /// Patches whose nodes slide along them (in the plane of the patch where it is flat) instead of
  /// staying put: walls next to a deflecting membrane, so the corner cells shear less.
  std::vector<std::string> slidingPatches;
  /// Columns (setColumnFeet): the interior nodes of each line of cell edges that leaves a membrane
  /// node and runs layer by layer to another boundary node move with that node, by a factor falling
  /// linearly in reference arc length from 1 at the membrane to 0 at the far wall; the others are
  /// solved as before, the column nodes prescribed (coupling/motion/MeshColumns).
  bool columns = false;
};

/// \brief What one `move` did.
struct MotionReport {
  int sweeps = 0;  ///< sweeps (Jacobi) or iterations (CG) of the accepted motion
  int retries = 0;
  bool stiffened = false;
  double minScaledJacobian = 0;
};

class MeshSmoother {
 public:
  /// Every node of a boundary face (walls, inlets, baffle sides, ...) is prescribed, except on
  /// empty patches (2D front and back) and sliding patches (nodes slide in the patch plane); the
  /// others are smoothed. Throws InputError for an unknown sliding patch. The mesh must outlive the smoother; `move` moves its points.
  MeshSmoother(const HexMesh& mesh, const MeshSmootherOptions& options);
  /// \brief The same on one rank's part of a decomposed mesh (`domain` distributed). Each rank
  /// finds the prescribed and sliding nodes on its part and the copies of a shared node agree
  /// (core/parallel/SharedNodes), so a node on the mesh's boundary is prescribed on every rank that
  /// holds it, whichever of its faces the rank has. The owned nodes are smoothed, the ghosts follow
  /// their owners through the node halo, and the quality guard takes the minimum over all ranks.
  /// Throws InputError on every rank when an owned node's edges are not all on its rank
  /// (`domain.incompleteNode`: a mesh whose cells meet a rank's cells at a node alone).
  MeshSmoother(const HexMesh& mesh, const MeshSmootherOptions& options, const RankDomain& domain);

  /// Displacement of every node from the reference mesh [m]: set the prescribed (boundary) entries
  /// before `move`; interior entries hold the last smoothed values.
  Real3View displacement() const { return d_; }
  /// 1 for prescribed nodes.
  Kokkos::View<const std::uint8_t*, MemSpace> prescribed() const { return fixed_; }

  /// The reference positions of the nodes the coupling moves (membranes, bodies): with
  /// options.distanceExponent > 0 the CG's edge weights grow near them. Call before the first move.
  void setMovingNodes(const std::vector<std::array<real, 3>>& points);

  /// \brief With options.columns: find the columns of nodes above `feet` (global node ids, the
  /// same list on every rank: the membranes' nodes on a boundary patch of an extruded, layered mesh,
  /// or on a baffle, a column on each side; coupling/motion/MeshColumns) and prescribe their interior
  /// nodes, which then move with their foot's row of `columnFeet()`. Returns the number of columns
  /// on all ranks. Call before the first move. Collective on a decomposed mesh.
  lid_t setColumnFeet(const std::vector<gid_t>& feet);
  /// The feet's displacement, one row per foot in the order `setColumnFeet` was given: set it with
  /// `displacement()` before each move (on every rank, a foot's row whether or not its node is on
  /// the rank's part). Empty without columns.
  Real3View columnFeet() const { return columns_.feet; }
  /// The columns (of `setColumnFeet`'s count) whose nodes more than one rank owns.
  lid_t columnsAcrossRanks() const { return columns_.acrossRanks; }

  /// Smooth and move the mesh points; the quality guard (the minimum scaled Jacobian, from the
  /// points alone) retries as the options say. The caller recomputes whatever geometry it keeps
  /// (the fluid does, once per motion). Throws DivergenceError when a cell is still inverted, with
  /// the mesh (points, displacement) restored to the last accepted motion.
  MotionReport move(const ExecSpace& exec);

  /// The displacement of the last motion (the next one's warm start) and of the last accepted one,
  /// for a checkpoint.
  void saveState(io::StateWriter& w) const;
  void loadState(const io::StateReader& r);

  /// \brief A displacement field the Laplacian does not smooth (the bodies' distance-weighted
  /// rigid motion, RigidBlend), refreshed by the caller before each `move`: the motion smooths
  /// d - base with the prescribed values less base, and the mesh takes base plus the result. The
  /// prescribed entries of `displacement()` stay totals; sliding nodes keep their total normal
  /// component (zero). Empty (the default): no base.
  void setBase(const Real3View& base) { base_ = base; }

  /// Points = reference + d (one kernel; no fence).
  void place(const ExecSpace& exec, const ConstReal3View& d) const;
  /// d(node) = weight columnFeet(foot) on every column node, ghost copies too (one kernel; no fence).
  void applyColumns(const ExecSpace& exec) const;
  /// With a base: d -= base on prescribed nodes; the free ones start from the last remainder.
  void subtractBase(const ExecSpace& exec) const;

 private:
  const HexMesh& mesh_;
  MeshSmootherOptions options_;
  Kokkos::View<std::uint8_t*, MemSpace> fixed_;
  SmoothingGraph graph_, stiff_;
  Real3View d_, work_, start_, good_;
  Real3View base_;      ///< setBase; empty: none
  Real3View lastBase_;  ///< the base of the last accepted motion (zero before the first)
  Real3View slide_;  ///< unit normal of sliding nodes (zero elsewhere); empty without sliding patches
  /// Columns: node, its foot, its factor (setColumnFeet); empty without columns.
  struct Columns {
    IndexView node, foot;  ///< every local copy of a column node, and its foot's row of `feet`
    RealView weight;
    Real3View feet;  ///< columnFeet()
    lid_t acrossRanks = 0;
  };
  Columns columns_;
  LaplacianCgWork cg_;
  std::unique_ptr<Halo> nodeHalo_;  ///< decomposed mesh: the ghosts of the displacement
  HaloPlan nodePlan_;                ///< decomposed mesh: its plan (set-up exchanges on the host)
  MPI_Comm nodeComm_ = MPI_COMM_NULL;
  SolverComm comm_;
};

}  // namespace mfsi::coupling
