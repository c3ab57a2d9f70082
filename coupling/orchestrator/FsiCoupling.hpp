#pragma once
/// \file
/// \brief The FSI orchestrator: the `coupling` section as a module that owns the fluid and the
/// membranes cut from its mesh, and advances them together.
///
/// One time step, implicit scheme (the seed's section 5.1, structure first):
///   fluid.beginStep; f = membrane loads from the fluid at t_n
///   structure: every membrane solves the step on f -> x (the predictor)
///   repeat
///     mesh motion: membrane nodes at x, interior nodes smoothed, quality guarded
///     fluid: PIMPLE on the moved mesh, membrane wall velocities -> f (forceOmega, ramp, pClamp)
///     structure: every membrane solves the step on f (from the step-start state) -> x~ = H(x)
///     converged when at least minFsiIter fluid solves ran and |x~ - x| / |x~| < fsiTol (and,
///       `both`, |f - f_prev| / |f| < fsiTol): commit x~, done
///     acceleration (Aitken / IQN-ILS) on (x, x~): x <- next iterate
/// The predictor is not a value of this step's fixed-point map H (the fluid had not seen t_n+1),
/// so it never enters the acceleration's history. The explicit scheme stops after the first fluid
/// solve, with the predictor as the step's structure. `coupling.iterations` counts fluid solves
/// per step, each followed by a structure solve, as peers count coupling iterations (the
/// predictor makes structure solves = iterations + 1).
///
/// Rigid bodies (`bodyPatches`) take part like membranes: their free coordinates q are a block of
/// the interface vector, their fluid patches move with them (the interior by the mesh motion), and
/// the fluid's force and moment on those patches load them; every iteration re-solves their step
/// from the committed state (RigidBodySystem::solveStep), the step commits once.
///
/// A closed chamber (an incompressible fluid with no pressure boundary, coupling/interface/
/// core/MeshRegions) closed by a membrane patch: the inflow dictates the membrane's swept volume. Each
/// step the target is the volume the fluid's mesh flux needs, c1 dV = dt Q + c00 dV_last (BDF2
/// weights), and the membrane solves with a volume constraint (MembraneVolumeConstraint: a uniform
/// pressure as multiplier); every relaxed iterate is moved back onto the constraint before the
/// fluid sees it, so the pressure equation is consistent in every coupling iteration. After the
/// step the fluid's pressure level in the chamber takes over the multiplier
/// (FluidSolver::shiftPressureLevel), so the fluid's field is the physical pressure. A region
/// bounded by several membranes shares one multiplier: each membrane solves with a share of the
/// target, the shares move by compliance until the multipliers agree (Newton on the split), and a
/// relaxed iterate is moved back onto the region's total only, keeping the acceleration's split.
/// Bodies that bound a region or carry its membrane (mounted on one body) change its volume
/// rigidly: the walls' targets follow the bodies' trial coordinates, and the bodies take the
/// region's multiplier (weighted as the walls' integrator weighs it), which the structure solve
/// iterates by secant until the walls return the multiplier the bodies were solved with.
///
/// Membrane state never leaks from one iteration into the next: a dynamic membrane re-solves the
/// step from its committed state (MembraneSolver::solveStep) and commits once; the fluid re-solves
/// the step from its current iterate on the moved mesh, its time levels set at beginStep.
#include "coupling/FluidModule.hpp"
#include "coupling/MembraneModule.hpp"
#include "coupling/RigidModule.hpp"
#include "coupling/chambers/Chamber.hpp"
#include "coupling/chambers/ChamberGroup.hpp"
#include "coupling/motion/BodyPatchMotion.hpp"
#include "coupling/motion/ParentFrames.hpp"
#include "coupling/motion/RigidBlend.hpp"
#include "coupling/interface/MembraneInterface.hpp"
#include "coupling/interface/SurfaceGather.hpp"
#include "coupling/motion/MeshSmoother.hpp"
#include "coupling/orchestrator/CouplingConfig.hpp"

#include <algorithm>
#include <memory>
#include <vector>

namespace mfsi {

class FsiCoupling final : public Module {
 public:
  /// Couples `fluid` with every membrane in `membranes` (each cut from the fluid mesh) and with the
  /// bodies of `rigid` that options.bodyPatches names (rigid may be null without bodyPatches). The
  /// mesh (the scene's) must outlive the module; the fluid keeps its geometry. Throws InputError
  /// naming the section for membranes that are not on the fluid mesh, unknown bodies or patches, or
  /// fluid walls that cannot follow them.
  ///
  /// On several ranks `mesh` is this rank's part and `domain` names the others; every rank holds
  /// the same membranes (each cut by the rank that holds it: structure/membrane/MembraneOnRanks)
  /// and bodies, on the same gathered loads (coupling/interface/SurfaceGather), so the interface
  /// vectors, residuals and accelerations are the same on every rank without further messages;
  /// the mesh motion and the fluid run on the parts.
  FsiCoupling(const CouplingOptions& options, const SceneConfig& section, HexMesh& mesh, Timers& timers,
              std::unique_ptr<FluidModule> fluid, std::vector<std::unique_ptr<MembraneModule>> membranes,
              std::unique_ptr<RigidModule> rigid = nullptr, const RankDomain* domain = nullptr);

  void advance(const TimeState& t) override;

  void saveState(io::StateWriter& w) const override;

  void loadState(const io::StateReader& r) override;
  void addMetrics(std::map<std::string, double>& metrics) const override;
  std::vector<std::string> stepColumns() const override;
  void appendStepValues(std::vector<double>& values) const override;
  std::vector<Module*> parts() override;
  /// A mounted membrane's grid (its module wrote it: reference + relative displacement) moved to
  /// where the membrane is: the fluid nodes it carries (its `displacement` stays frame-relative).
  void addOutputFields(io::FieldFrame& frame) override;

  FluidModule& fluid() { return *fluid_; }
  MembraneModule& membrane(std::size_t i) { return *panels_[i].module; }
  std::size_t membraneCount() const { return panels_.size(); }

  /// \brief What the last step did.
  struct StepReport {
    int iterations = 0;        ///< fluid solves
    int structureSolves = 0;
    bool converged = false;
    double displacementResidual = 0;  ///< relative, of the last check
    double forceResidual = 0;         ///< relative, of the last check
    double omega = 1;                 ///< last relaxation factor (quasi-Newton: 1)
    int columns = 0;                  ///< quasi-Newton columns of the last update
    double minScaledJacobian = 1;
    int cutBacks = 0;  ///< iterates the mesh could not follow, cut back towards the last good one
    int motionIterations = 0;  ///< CG iterations (or Jacobi sweeps) of the step's mesh motions
    int limited = 0;           ///< updates shortened by maxDeltaDispFrac / maxMeshVelocity
  };
  const StepReport& lastStep() const { return last_; }

 public:
  // --- the steps of advance() -----------------------------------------------------------------
  // Public only because nvcc compiles extended device lambdas (KOKKOS_LAMBDA) solely in public
  // member functions. They expect the state advance() sets up around them: not API.
  struct Panel {
    MembraneModule* module = nullptr;
    coupling::SurfaceGather surface;  ///< the fluid's values on the membrane's faces, gathered
    coupling::MembraneInterface iface;  ///< on the gathered slots (surface.gatheredInterface())
    bool dynamic = false;
    bool wallVelocity = false;  ///< the fluid takes the membrane velocity (External walls)
    RealView load, loadPrevious;  ///< element pressure in use, and of the previous iteration
    Real3View force, forcePrevious;  ///< viscous nodal forces in use, and of the previous iteration
    Real3View forceFrame;    ///< mounted: `force` rotated into the frames (what its FEM receives)
    Real3View nodePosition;  ///< mounted: the nodes' current positions (the viscous forces' moments)
    Real3View inertia;       ///< mounted, dynamic: the frames' acceleration on the nodes' masses (world axes)
    Real3View framePosition;  ///< mounted, dynamic: the nodes' positions at the step's start (inertia's lever)
    Real3View nodeLoad;      ///< mounted, dynamic, viscous traction: viscous force + inertia (world axes)
    Real3View reaction;      ///< mounted, dynamic: the inertia of the motion relative to the frames (world axes), on the bodies
    Real3View faceVelocity;
    RealView iterate;  ///< this panel's slice of an interface iterate on the device (3 per node)
    Eigen::Index offset = 0;
    coupling::ElementGraph graph;  ///< pNetSmoothIter
    RealView smoothWork;
    RealView filtered;             ///< pNetFilterTau: the filtered load of the last step
    bool haveFiltered = false;
    RealView loadLastStep;  ///< extrapolatedPredictor: the load at the previous step's start (t_n-1)
    bool haveLastStep = false;
    bool mounted = false;            ///< on moving bodies (parentBodyPatches): FEM relative to them
    coupling::ParentFrames parents;  ///< mounted: each node's body and the bodies' motions
    /// On several ranks: the rank that solves the membrane (the owner of its faces), which sends
    /// its answer to the others; -1: every rank solves it (one rank, or its faces spread).
    int owner = -1;
    /// Mesh motion by columns: `iface` with each node's row of the smoother's columnFeet() for its
    /// fluid node (every node, on every rank); no nodes without columns.
    coupling::MembraneInterface feet;
    MembraneSolveReport report;  ///< of the last structure solve
  };
  /// A rigid body of the coupling and the fluid patches it carries.
  struct CoupledBody {
    int index = -1;
    std::string name;
    std::vector<std::string> patches;
    coupling::BodyPatchMotion motion;
    Eigen::Vector3d com0 = Eigen::Vector3d::Zero();      ///< centre of mass at the start (the mesh's configuration)
    Eigen::Matrix3d rotation0 = Eigen::Matrix3d::Identity();
    /// The load of updateBodyLoads (fluid, mounted membranes) and the point its moment is about;
    /// applyBodyLoads adds the chambers' multipliers.
    Eigen::Vector3d loadCentre = Eigen::Vector3d::Zero(), loadForce = Eigen::Vector3d::Zero(),
                    loadMoment = Eigen::Vector3d::Zero();
  };
  /// Membrane loads from the fluid (times `scale`); with `relax`, forceOmega-blended with the
  /// previous ones. Sets the load residual. `stepStart`: the loads of t_n, before the step's first
  /// structure solve (the bodies' share from the committed state).
  void updateLoads(double scale, bool relax, double dt, bool stepStart = false);
  /// The filter state of pNetFilterTau advances to the step's last load.
  void advanceLoadFilter();
  /// The fluid's force and moment on each coupled body's patches (times `scale`) and its mounted
  /// membranes' loads and relative inertia become its external load.
  void updateBodyLoads(double scale, bool stepStart);
  /// The bodies' external loads: updateBodyLoads's plus each chamber's bodyLambda on the bodies'
  /// faces that bound it and on the mounted walls they carry.
  void applyBodyLoads();
  /// Mounted dynamic membranes: the inertial force of their mass carried by the bodies' current
  /// accelerations (Panel::inertia), and the FEM's nodal load in the frames (viscous + inertia).
  /// extrapolatedPredictor: each panel's load becomes 2 p_n - p_n-1 (p_n kept for the next step).
  void extrapolateLoads();
  void updateFrameInertia();
  void solveStructure(double t1, double dt);
  /// Every membrane solves the step once (on several ranks: its owner, then shareSolve), the walls
  /// of a chamber with several again on moved shares until their multipliers agree.
  void solveMembranes(double t1, double dt);
  /// Every rank but the panel's owner receives the owner's answer to the last solve (collective).
  void shareSolve(Panel& p, double t1, double dt);
  void gatherTrial(coupling::InterfaceVector& xt) const;
  /// The membranes (and bodies) to the iterate x; a membrane that closes a chamber first moves x
  /// onto its volume constraint (x is updated).
  void setTrial(coupling::InterfaceVector& x);
  /// Closed chambers: each step's volume target from the prescribed inflow and the fluid's
  /// mesh-flux weights.
  void beginChamberStep();
  /// |volume change - target| of each chamber's membrane at its slice of x, into the step's report.
  void checkChamberVolume(const coupling::InterfaceVector& x);
  void commitStructure();
  /// maxDeltaDispFrac and maxMeshVelocity: x's move from `previous` is shortened where it exceeds
  /// them (per membrane node; per body, its whole coordinate update). Returns true when it was.
  bool limitUpdate(coupling::InterfaceVector& x, const coupling::InterfaceVector& previous, double dt) const;
  /// Coupled bodies' patch nodes to the poses of the coordinates in x (the mesh motion's prescribed displacements).
  void placeBodies(const coupling::InterfaceVector& x);
  void moveMesh(const coupling::InterfaceVector& x);
  /// moveMesh(x), or, when the mesh cannot follow x (a cell would invert), the largest step from
  /// `good` towards x that it can follow (halved up to 6 times; x is overwritten); then `good` = x.
  /// Returns false when x was cut back. Throws DivergenceError when not even 1/64 of it works.
  bool moveMeshGuarded(coupling::InterfaceVector& x, coupling::InterfaceVector& good);
  void solveFluid(const TimeState& t);
  double loadScale(double t1) const;

 private:
  void setUpBodies(const SceneConfig& section, std::vector<coupling::InterfaceBlock>& layout);
  void setUpParents(const SceneConfig& section);
  void setUpChamber(const SceneConfig& section);
  void setUpLumpedChamber(const SceneConfig& section);
  /// The panels of `walls` (each with its MembraneVolumeConstraint::sign) close a new chamber
  /// (fluidRegion: the fluid's closed region, -1 for the whole domain or a lumped chamber): their
  /// constraints are switched on at the volumes they have now.
  void addChamber(const std::vector<std::pair<int, real>>& walls, int fluidRegion, bool lumped);
  /// The slot of a mounted panel's one parent body (every node's weight 1 for it), or -1.
  int singleParent(const Panel& p) const;
  /// The chamber panel `panel` closes (one of its walls), or -1.
  int chamberOf(int panel) const;
  /// A chamber's column or metric name: `name` alone with one chamber, `name` + "." + the name of
  /// its first membrane that names no earlier chamber, with several.
  std::string chamberName(std::size_t chamber, const std::string& name) const;
  /// The coupled membranes' names as the scene spells them ("<name>" of module "membrane.<name>").
  std::vector<std::string> membraneNames() const;

  CouplingOptions options_;
  HexMesh& mesh_;
  RankDomain domain_;  ///< several ranks: the ranks (comm) and this rank's halo plans; one rank: none
  int rank_ = 0;  ///< this rank in domain_.comm (0 on one rank)
  Timers& timers_;
  ExecSpace exec_;
  std::unique_ptr<FluidModule> fluid_;
  std::vector<std::unique_ptr<MembraneModule>> ownedMembranes_;
  std::vector<Panel> panels_;
  std::unique_ptr<RigidModule> rigid_;
  std::vector<CoupledBody> bodies_;
  Eigen::Index bodyOffset_ = 0;  ///< the free coordinates of the rigid system in the interface vector
  std::vector<RigidPlacement> transforms_;  ///< per coupled body: its motion at the iterate being placed
  std::unique_ptr<coupling::MeshSmoother> smoother_;
  lid_t columns_ = 0, columnFeet_ = 0;  ///< meshMotion.columns: the columns found, the membrane nodes offered
  /// meshMotion.bodies: the bodies' distance-weighted rigid motion in the mesh (the smoother's base),
  /// the coupled-body slot of each of its bodies, and the field.
  struct Reach {
    coupling::RigidBlend blend;
    std::vector<int> slot;
    Real3View base;
    std::vector<RigidPlacement> transforms;
  };
  Reach reach_;
  std::unique_ptr<coupling::Acceleration> acceleration_;
  Eigen::Index size_ = 0;
  double stepEnd_ = 0;  ///< t_n+1 of the step being solved
  double forceResidual_ = 0;
  StepReport last_;
  long long steps_ = 0, iterationsTotal_ = 0, unconvergedSteps_ = 0, unconvergedInARow_ = 0, cutBacksTotal_ = 0,
            limitedTotal_ = 0;
  int maxIterations_ = 0;
  double minJacobian_ = 1;
  // --- closed chambers (FsiChambers.cpp) ------------------------------------------------------
  using Chamber = coupling::Chamber;
  using ChamberWall = coupling::ChamberWall;
  using ChamberBody = coupling::ChamberBody;
  using ChamberGroup = coupling::ChamberGroup;
  /// Groups the chambers by their shared walls. Throws InputError (naming `where`) for a group whose
  /// pressures its walls cannot fix: closed regions bounded only by membranes between them (their
  /// inflows would fix one volume twice).
  void groupChambers(const SourceLocation& where);
  /// The walls' weights for sharing a volume: their compliances, or before every wall has one
  /// their reference areas.
  Eigen::VectorXd wallWeights(const ChamberGroup& g) const;
  /// The new chamber's moving walls: its mounted walls' parents, and every coupled body's faces
  /// on the fluid region `region` (cellRegion: the region of each local cell).
  void addMovingWalls(Chamber& c, const std::vector<int>& cellRegion, int region);
  /// The bodies' rigid motions at coordinates q (the placements placeBodies applies).
  std::vector<RigidPlacement> placementsOf(const Eigen::VectorXd& q) const;
  /// A chamber's volume change by its bodies' rigid motions `t` (collective on several ranks):
  /// their faces, the walls mounted on one body carried undeformed, and for a wall blended between
  /// bodies what its placement at its frame-relative displacement (x's, or with x null its
  /// solver's trial) adds to that displacement's frame-relative volume.
  double rigidVolume(Chamber& c, const std::vector<RigidPlacement>& t, const coupling::InterfaceVector* x);
  /// The chamber's bodies at coordinates q (empty: no bodies): rigidVolume, 0 without moving walls.
  double rigidVolumeAt(Chamber& c, const Eigen::VectorXd& q, const coupling::InterfaceVector* x = nullptr);
  /// A wall's displacement now: its trial of this step if it has one, else its committed one.
  RealView wallDisplacement(const Panel& p) const;
  /// A chamber's volume change with its bodies at q and its walls at x (null: wallDisplacement).
  double chamberVolume(Chamber& c, const Eigen::VectorXd& q, const coupling::InterfaceVector* x);
  /// Chambers with blended walls: the largest miss of their volume at x (null: the walls' trials)
  /// over the walls' volume tolerance.
  double blendedMiss(const coupling::InterfaceVector* x);
  /// Every chamber's walls' volume targets for the iterate x (the groups' totals at x's bodies,
  /// shared by compliance); `saved` receives the targets replaced (when not null).
  void targetsFor(const coupling::InterfaceVector& x,
                  std::vector<std::pair<MembraneVolumeConstraint*, real>>* saved);
  /// x's block of the bodies' coordinates (empty without bodies).
  Eigen::VectorXd bodyCoordinates(const coupling::InterfaceVector& x) const;
  /// Chambers with moving walls: the walls' targets follow the bodies' trial coordinates (the
  /// shares keep their split).
  void followBodies();
  /// The pressure a chamber's walls carry: the largest of their multipliers and element loads.
  double pressureScale(const Chamber& c) const;
  /// The chamber's multiplier from its walls' last solve: its one wall's, or with several walls in
  /// its group the agreed one (moveShares).
  double chamberMultiplier(const Chamber& c) const;
  /// Some wall of the chamber took a Newton iteration in its last solve (else its target moved by
  /// less than its volume tolerance resolves).
  bool wallsIterated(const Chamber& c) const;
  /// The volume targets' split into the walls' shares at the step's start (wallWeights).
  void splitTarget(const ChamberGroup& g);
  /// Several walls, after every wall solved on its share: the chambers' multipliers Lambda that
  /// the walls' multipliers agree with best (E C E^T Lambda = E C lambda, C the compliances), and
  /// each share moved by C_i ((E^T Lambda)_i - lambda_i) (the chambers' volumes stay). Returns
  /// true when the multipliers agreed to kShareAgreement x fsiTol before the move (nothing moved
  /// then), or when `resolved` (a solve on moved shares) and no wall took a Newton iteration.
  bool moveShares(const ChamberGroup& g, bool resolved);
  /// A chamber's multiplier on coupled body `slot`: on its faces that bound the chamber and on the
  /// mounted walls it carries, as those walls receive it (added to force and moment about the
  /// body's loadCentre).
  void addChamberLoads(std::size_t slot, Eigen::Vector3d& force, Eigen::Vector3d& moment);
  /// The step's end, before the structure commits: each chamber's start volumes for the next step
  /// where the fluid mesh ends the step (`good`, the last iterate moved to), what it swept, its
  /// multiplier and pressure.
  void endChamberStep(const coupling::InterfaceVector& good);
  /// After the commit: the fluid's pressure level in each meshed chamber takes over the
  /// multiplier (the walls' and bodies' multipliers and the walls' loads shift alike).
  void shiftChamberLevels();
  /// A wall's membrane solver (the panels hold their modules by pointer).
  MembraneSolver& memberSolver(const ChamberWall& w) const {
    return panels_[static_cast<std::size_t>(w.panel)].module->solver();
  }
  std::vector<Chamber> chambers_;
  std::vector<ChamberGroup> groups_;
  bool blended_ = false;  ///< a chamber wall is blended between bodies
};

/// Catalogue entry of the `coupling` section (needs the `fluid` section and at least one membrane
/// cut from the mesh).
ModuleEntry couplingModuleEntry();

}  // namespace mfsi
