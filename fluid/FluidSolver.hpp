#pragma once
/// \file
/// \brief Incompressible Navier-Stokes on a moving hex mesh: cell-centred collocated finite
/// volumes in ALE form, PIMPLE pressure-velocity coupling with Rhie-Chow face fluxes.
///
/// Discretisation (integral form over a moving cell of volume V):
///   rho d(V u)/dt + sum_f rho (phi_f - phi^m_f) u_f - mu sum_f (grad u)_f . S_f = -V grad p + rho V g,
///   sum_f phi_f = 0     (or, with artificial compressibility c: d(V p)/dt / (rho c^2) + sum_f phi_f = 0),
/// phi_f the absolute volumetric face flux and phi^m_f the mesh flux built from face swept volumes
/// (see fluid/MeshFlux.hpp) with the time scheme's own weights, so that
///   (c1 V^{n+1} - c0 V^n + c00 V^{n-1}) / dt = sum_f phi^m_f      (discrete space conservation)
/// holds to round-off and a uniform flow stays uniform on any mesh motion.
///
/// Typical FSI use:
/// \code
///   FluidSolver fluid(mesh, opts);
///   for (step...) {
///     fluid.beginStep(t, dt);
///     for (fsi iteration...) {
///       fluid.moveMesh(newPoints);                    // node positions at t + dt
///       fluid.setWallVelocity("membrane", velocity);  // per baffle face
///       auto r = fluid.solve();                       // PIMPLE for this step, warm-started
///       baffleNetPressure(fluid, "membrane", pNet);   // p_master - p_slave per face
///     }
///   }
/// \endcode
#include "core/MeshGeometry.hpp"
#include "core/parallel/Halo.hpp"
#include "fluid/BoundaryConditions.hpp"
#include "fluid/FluidOptions.hpp"
#include "fluid/FvAssembly.hpp"
#include "fluid/FvFaceData.hpp"
#include "fluid/Gradient.hpp"
#include "fluid/LinearSolve.hpp"

#include <functional>
#include <memory>
#include <string>

namespace mfsi::fluid {

/// Device functor of the phiHbyA face formula (FluidSolver.cpp).
struct PhiHbyAFace;
/// Device functor writing the face fluxes from the solved pressure (FluidSolver.cpp).
struct PressureFaceFlux;
/// The row walker of the fused pressure-matrix passes (FluidSolver.cpp).
struct PressureRow;

/// \brief What one call of `solve()` did.
struct StepResult {
  bool ok = true;          ///< false on NaN/Inf or a linear-solver breakdown
  bool converged = false;  ///< outer loop reached `outerTolerance` (always false when it is 0)
  int outerIterations = 0;
  int momentumIterations = 0;      ///< linear iterations, summed
  int pressureIterations = 0;      ///< linear iterations, summed
  real momentumResidual = 0;       ///< initial (normalised) residual of the first momentum solve
  real pressureResidual = 0;       ///< initial residual of the first pressure solve
  real finalMomentumResidual = 0;  ///< initial residual of the momentum solve of the last outer iteration
  real finalPressureResidual = 0;  ///< initial residual of the first pressure solve of the last outer iteration
  real continuityMax = 0;          ///< max over cells of |sum_f phi_f| / V  [1/s] after the last corrector
                                   ///< (with artificial compressibility: the compression rate, not a residual)
  real continuitySum = 0;          ///< sum over cells of |sum_f phi_f|  [m^3/s]
};

/// \brief Node positions at time t; called by `solveStep` when set with `setMeshMotion`.
using MeshMotion = std::function<void(real time, const Real3View& points)>;

/// \brief The fluid solver. Fields live on the device with labels `mfsi::fluid::*`.
class FluidSolver {
 public:
  /// \brief Allocate fields, resolve boundary conditions and build the matrix sparsity.
  /// `mesh` must outlive the solver; the solver moves its points in `moveMesh`.
  /// On one rank's part of a decomposed mesh (core/parallel/LocalMesh), `domain` names the
  /// other ranks: the solver then owns the rows of its owned cells, keeps its ghost cells' values
  /// those of their owners (halo exchanges after every field a face reads is formed), sums over
  /// ranks and solves the pressure with the distributed AMG (kernels/DistributedAmg).
  FluidSolver(const HexMesh& mesh, const FluidOptions& options, const RankDomain& domain = {});

  // --- time stepping -------------------------------------------------------------------------
  /// \brief Start the step from t to t + dt: the current solution and geometry become the old time
  /// levels; prescribed boundary values are evaluated at t + dt.
  void beginStep(real t, real dt);
  /// \brief Move the mesh to `newPoints` (positions at t + dt). May be called repeatedly within a
  /// step (FSI iterations): swept volumes are always measured from the positions at `beginStep`.
  void moveMesh(const ConstReal3View& newPoints);
  /// \brief Run the PIMPLE (or, steady, SIMPLE) iterations of the current step, starting from the
  /// current fields. May be called repeatedly within a step.
  StepResult solve();
  /// \brief `beginStep(t, dt)`, mesh motion from `setMeshMotion` if set, then `solve()`.
  StepResult solveStep(real t, real dt);
  /// \brief Mesh motion used by `solveStep`.
  void setMeshMotion(MeshMotion motion) { motion_ = std::move(motion); }
  /// \brief Keep the iterate at the start of every step (`beginStep`), so that `restoreStepStart`
  /// can put it back: for a coupling that re-solves a step and wants each solve to depend on its
  /// interface data alone, not on the iterations before it. Off by default (one copy per step).
  void keepStepStart(bool keep) { stepStart_.enabled = keep; }
  /// \brief Put back the velocity, pressure, face fluxes and the solver guesses of the start of the
  /// current step (`keepStepStart(true)` before its `beginStep`); the mesh stays where it is.
  void restoreStepStart();

  // --- checkpoints ---------------------------------------------------------------------------
  /// \brief Write everything the next step reads (fields, old time levels, guesses, the pressure
  /// preconditioner's history, boundary values and the solver's counters), between steps.
  void saveState(io::StateWriter& w) const;
  /// \brief Read what saveState wrote, into a solver built from the same options on the same mesh
  /// whose points are already where they were when it was saved: the run then continues bitwise.
  /// Without "pressureMatrix" (a checkpoint carried to another decomposition) the pressure matrix
  /// and its preconditioner are rebuilt by the first solve: the run continues to solver tolerance.
  void loadState(const io::StateReader& r);

  // --- boundary input ------------------------------------------------------------------------
  /// \brief Per-face wall velocity for a wall patch with `WallMotion::External`, or for both sides
  /// of a baffle when `name` is the baffle name (size: faces of one side). The normal component
  /// is replaced by the mesh's, so walls stay impermeable relative to the mesh.
  void setWallVelocity(const std::string& name, const ConstReal3View& faceVelocity);

  // --- state ---------------------------------------------------------------------------------
  /// \brief Set the velocity field (and reset face fluxes to interpolated values).
  void setVelocity(const ConstReal3View& u);
  /// \brief Set the pressure field.
  void setPressure(const ConstRealView& p);

  const HexMesh& mesh() const { return mesh_; }
  const FluidOptions& options() const { return opt_; }
  const MeshGeometry& geometry() const { return geo_; }
  const FvFaceData& faceData() const { return fd_; }
  const BoundaryConditions& boundaryConditions() const { return bc_; }
  /// Cell velocity [m/s].
  ConstReal3View velocity() const { return U_; }
  /// Cell pressure [Pa].
  ConstRealView pressure() const { return p_; }
  /// Absolute volumetric face flux u.S [m^3/s] (out of the owner), all faces.
  ConstRealView faceFlux() const { return phi_; }
  /// Mesh flux of the current step [m^3/s], all faces.
  ConstRealView meshFlux() const { return meshPhi_; }
  /// Velocity on boundary faces (index f - nInternalFaces).
  ConstReal3View boundaryVelocity() const { return Ub_; }
  /// Pressure on boundary faces (index f - nInternalFaces).
  ConstRealView boundaryPressure() const { return pb_; }
  /// Mesh velocity of the current step on boundary faces (index f - nInternalFaces) [m/s].
  ConstReal3View boundaryMeshVelocity() const { return faceMeshVel_; }
  /// Velocity gradient G(c, i, j) = du_j/dx_i: the one the last outer iteration used, or, where the
  /// discretisation did not need it (orthogonal mesh, linear/upwind convection), computed from the
  /// current velocity on first request.
  ConstTensor3View velocityGradient() const;
  /// Start time of the current step and its size.
  real time() const { return t_; }
  real timeStep() const { return dt_; }
  /// Cells whose rows this solver owns (all of them on one rank; then the ghosts follow).
  lid_t ownedCells() const { return nRows_; }
  /// The ranks' sums and ghost exchanges (no-ops on one rank).
  const SolverComm& comm() const { return comm_; }
  /// \brief Each cell's dynamic viscosity [Pa s] when FluidOptions::regions gives some cells another
  /// fluid; an empty view when every cell has options().viscosity.
  ConstRealView cellViscosity() const { return cellFluid_.mu; }
  /// \brief Each cell's fluid (-1: the options' own, i: FluidOptions::regions[i]); an empty view
  /// without regions.
  ConstIndexView cellFluidIndex() const { return cellFluid_.index; }
  /// \brief Each cell's closed region (addClosedRegion; -1: none); an empty view without them.
  ConstIndexView cellClosedRegion() const { return cellClosedRegion_; }
  /// The ghost cells' halo (null on one rank).
  const Halo* cellHalo() const { return cellHalo_.get(); }
  /// Number of `beginStep` calls so far.
  int stepIndex() const { return nSteps_; }
  /// \brief The weights of the current step's mesh flux, phi^m = (c1 dV^{n+1} - c00 dV^n) / dt
  /// per face (dV the swept volumes of this and of the last step; set by beginStep).
  struct MeshFluxWeights {
    real c1 = 1, c00 = 0, dt = 1;
  };
  MeshFluxWeights meshFluxWeights() const { return {c1_, c00_, dt_}; }
  /// \brief Volume flow into the domain through the prescribed-velocity and flow-rate faces at the
  /// end of the current step [m^3/s], summed over the ranks: what the moving walls of a domain
  /// closed to pressure must make room for.
  real prescribedInflow() const { return prescribedInflow(-1); }
  /// The same through the faces of the cells of closed region `region` (addClosedRegion; -1: all).
  real prescribedInflow(int region) const;
  /// \brief Cells that no pressure boundary reaches, beside cells that one does (a chamber walled
  /// off by a membrane baffle): the pressure level there is pinned at `referenceCell` (a global id
  /// in the region) as in a closed domain, and every solve checks that the region's boundary
  /// fluxes balance. `localCells` flags this rank's cells of the region (one entry per local cell).
  /// Returns the region's index.
  int addClosedRegion(const std::vector<char>& localCells, long long referenceCell);
  /// \brief Raise the pressure of a closed domain (region -1) or closed region by `delta`: its
  /// cells, boundary faces and the level its reference cell is pinned at. Nothing else changes
  /// (the level is free there); a coupling ties it to the multiplier of a volume constraint.
  void shiftPressureLevel(int region, real delta);
  /// The level a closed domain (-1) or region is pinned at [Pa].
  real pressureLevel(int region) const;
  /// True when no boundary face prescribes the pressure and the fluid is incompressible: the
  /// domain is closed, and a reference cell fixes the pressure level.
  bool closedDomain() const { return pinsPressureLevel(); }

 public:
  // --- the steps of solve() ----------------------------------------------------------------
  // Public only because nvcc compiles extended device lambdas (KOKKOS_LAMBDA) solely in public
  // member functions (CUDA Programming Guide, extended-lambda restrictions). They expect the state
  // that beginStep() and solve() set up around them: not API; call the methods above.
  void updateGeometry();
  void computeTimeCoefficients();
  void computeMeshFlux();
  void updateBoundaryVelocity();
  void updateBoundaryPressure();
  void computeVelocityGradient() const;
  void pressureGradient(const ConstIndexView& cells);
  void updatePressureGradient();
  /// updatePressureGradient's boundary pressures and gradient in one pass over the cells (fused
  /// path, Gauss-linear stencil).
  void pressureGradientFused();
  /// What assembleMomentum formed besides the matrix and source (the fused path only).
  struct MomentumAssembly {
    bool b = false;    ///< the momentum solve's right-hand side (b3_)
    bool inv = false;  ///< the Jacobi inverse diagonal (linear_.momentumInverseDiagonal)
  };
  MomentumAssembly assembleMomentum(bool withB, bool withInv);
  void assembleMomentumFused(bool withB, bool withInv);
  /// relaxVelocity < 1: relax the momentum diagonal from max(|a_P|, sum |a_N|).
  bool relaxesDominant() const;
  /// relaxFlux_ from the current face fluxes and velocity (before the momentum solve).
  void storeRelaxationFlux();
  void computeHbyA(bool withRAU);
  /// SIMPLEC: moves the (rAtU - rAU) grad p part into phiHbyA and HbyA (see there).
  void simplecCorrection();
  /// The phiHbyA face formula with this step's fields and coefficients (device functor).
  PhiHbyAFace phiHbyAFace() const;
  /// The pressure-flux face formula with this step's fields (device functor).
  PressureFaceFlux pressureFaceFlux() const;
  /// U = U0 + (dt / dt0) (U0 - U00): the first momentum solve's initial guess (extrapolateGuess).
  void extrapolateVelocity();
  /// Whether U00_ is kept for the extrapolated initial guess of the momentum solve.
  bool extrapolatesVelocity() const;
  /// extrapolateGuess around the final pressure solve: remember p, add dpFinal_; then store the
  /// change the solve made (measured from p without the guess).
  void startFinalPressureSolve();
  void finishFinalPressureSolve();
  void computePhiHbyA();
  /// Pressure equation: the source every corrector, with `matrix` also the matrix.
  void assemblePressure(bool matrix);
  /// The matrix and the source's divergence of fluxP_ in one pass over the cells; with `stored`
  /// the face coefficients come from coefP_.
  void assemblePressureMatrixFused(bool stored);
  /// assemblePressureMatrixFused writing CG's symmetric lattice (diagonal and +x, +y, +z
  /// couplings) instead of the CSR values: one coefficient per face, so symmetric by construction.
  void assemblePressureLatticeFused(SymmetricLatticeMatrix& lattice, bool stored);
  /// The row walker both fused pressure-matrix passes share.
  PressureRow pressureRow(bool stored) const;
  void assemblePressureMatrixFaces();
  void pinPressureLevel();
  /// A closed domain (region -1) or closed region: throws DivergenceError when the boundary fluxes
  /// do not sum to zero.
  void checkClosedDomainBalance(int region);
  /// The pinned rows' diagonals doubled (the whole domain's reference cell, the closed regions').
  bool pinsAnyLevel() const { return pinsPressureLevel() || regionPinRows_.extent(0) > 0; }
  bool fusedPressureSource() const;
  /// The fused per-cell pressure-matrix and end-of-step passes apply (Gather reduction).
  bool fusedCellPasses() const;
  void pressureSourceFlux(bool coefficients);
  void pressureSourceFluxFaces();
  void finishPressureSource();
  bool pinsPressureLevel() const;
  /// Face fluxes from the solved pressure (unless `flux` is false: nothing reads them before the
  /// next corrector rewrites them), relaxation, grad p and U.
  void correctFluxAndVelocity(bool flux);
  bool compressible() const;
  void storeDdtCorrection();
  real continuityMax(real& sum);
  /// The final corrector's face fluxes and the correction fluxes of the step in one face pass.
  void fluxAndDdtCorrection();
  /// The fused end-of-step pass (storeDdtCorrection unless `ddtStored`, continuity, finiteness).
  real finishStep(real& sum, bool& finite, bool ddtStored);
  bool fieldsFinite();
  /// Ghost entries <- their owners' values (no-op on one rank).
  void exchangeGhosts(const RealView& x) const;
  void exchangeGhosts(const Real3View& x) const;
  void exchangeGhosts(const Tensor3View& x) const;
  /// The momentum and pressure matrices as the linear solvers see them: the owned rows.
  const CsrMatrix& momentumMatrix() const { return cellHalo_ ? AuRows_ : Au_; }
  const CsrMatrix& pressureMatrix() const { return cellHalo_ ? ApRows_ : Ap_; }

 private:
  const HexMesh& mesh_;
  FluidOptions opt_;
  ExecSpace exec_;
  lid_t nCells_ = 0, nFaces_ = 0, nIn_ = 0, nB_ = 0;
  /// Owned cells: the rows of the matrices and of every reduction; cells [nRows_, nCells_) are
  /// ghosts whose values arrive from their owners through cellHalo_ (null on one rank).
  lid_t nRows_ = 0;
  std::unique_ptr<Halo> cellHalo_;
  SolverComm comm_;
  /// Local row of the pressure reference cell (pressureReferenceCell, a global id), -1 when another
  /// rank owns it.
  lid_t referenceRow_ = -1;
  /// Closed regions beside open ones (addClosedRegion): each local cell's region (-1: none), their
  /// number, and the reference rows on this rank.
  IndexView cellClosedRegion_;
  int closedRegions_ = 0;
  IndexView regionPinRows_;
  RealView regionPinValues_;            ///< per pinned row: its region's level
  std::vector<int> regionPinRegion_;    ///< per pinned row: its region
  std::vector<real> regionLevel_;       ///< per closed region: the level it is pinned at

  /// Per-cell density and viscosity where FluidOptions::regions gives cells another fluid; empty
  /// views otherwise (the kernels then read opt_.density and opt_.viscosity).
  struct CellFluid {
    RealView rho, mu;
    IndexView index;  ///< which fluid: -1 the options' own, i FluidOptions::regions[i]
    bool perCell() const { return rho.extent(0) > 0; }
  };
  CellFluid cellFluid_;
  void setUpRegions(const RankDomain& domain);

  MeshGeometry geo_;
  FvFaceData fd_;
  FvSparsity sparsity_;
  CsrMatrix Au_, Ap_;
  CsrMatrix AuRows_, ApRows_;  ///< their owned rows (shared arrays), on a decomposed mesh
  FaceCoefficients fcU_, fcP_;  ///< allocated on first use (the fused paths do not need them)
  BoundaryConditions bc_;
  LinearSolver linear_;

  // Cell fields.
  Real3View U_, U0_, U00_;
  RealView p_, pPrev_, p0_, p00_;  ///< p0_, p00_: old time levels (artificial compressibility)
  RealView V0_, V00_;
  Real3View HbyA_, gradP_, rhsU_;
  Tensor3View gradU_;
  RealView rAU_, cellDiag_, rhsP_, b_;
  /// SIMPLEC: V / a_P while rAU_ holds rAtU = V / (a_P - H1); allocated when consistent.
  RealView rAUSimple_;
  /// Under-relaxed momentum (relaxVelocity < 1): 1 - a_P / relaxed a_P per cell, and the face flux
  /// minus the interpolated velocity of the iterate the relaxation pulls towards (storeRelaxationFlux).
  RealView relaxFraction_, relaxFlux_;
  Real3View b3_;
  // Face fields.
  RealView phi_, meshPhi_, phiHbyA_, dphi_, dphi0_, dphi00_, sweptNew_, sweptOld_, fluxP_;
  RealView coefP_;   ///< pressure-matrix face coefficients from pressureSourceFlux (fused path)
  Real3View fluxU_;  ///< like phiHbyA_, allocated by the face path that needs it
  // Boundary-face fields.
  Real3View Ub_, faceMeshVel_;
  RealView pb_;
  IndexView boundaryCells_;      ///< cells owning a boundary face
  GradientStencil gradStencil_;  ///< Gauss-linear gradients (rebuilt with the geometry)
  // Mesh positions at the start of the step.
  Real3View points0_;

  real t_ = 0, dt_ = 1, dt0_ = 1;
  int nSteps_ = 0;
  /// Pressure-matrix assemblies since the preconditioner values were last refreshed, counted
  /// across steps so a one-outer-iteration PISO run does not rebuild the AMG every step.
  long pressureAssemblies_ = 0;
  /// Iterations of the first final pressure solve after the last preconditioner refresh (-1: not
  /// yet seen), and whether a later one has needed so many more that the next assembly refreshes.
  int refreshBaselineIterations_ = -1;
  bool pressureRefreshDue_ = false;
  /// Set when the last pressure-matrix assembly wrote CG's lattice (owned by linear_), not Ap_'s
  /// CSR values (stale until the linear solver fills them for a preconditioner refresh).
  SymmetricLatticeMatrix* pressureLattice_ = nullptr;
  bool bdf2Active_ = false;
  /// gradP_ (and pb_) match the current p_, boundary pressures and geometry: the gradient is the
  /// same in every place that asks for it until one of those changes (see invalidations).
  bool gradPValid_ = false;
  /// Some internal face is non-orthogonal (S not parallel to d): the explicit corrections, and the
  /// velocity gradient they need, are live. False on Cartesian meshes, where they vanish exactly.
  bool nonOrthogonal_ = true;
  bool hasResistance_ = false;
  /// sweptNew_ / sweptOld_ are all zero (no moveMesh in this step / the previous one), so the mesh
  /// flux is exactly zero and need not be read.
  bool sweptNewZero_ = true, sweptOldZero_ = true, meshStatic_ = true;
  /// moveMesh was called since beginStep last copied the positions and volumes (V0_, points0_).
  bool meshMoved_ = false;
  /// extrapolateGuess: no solve() since beginStep yet (the first one extrapolates U); the change
  /// the last final pressure solve made (dpFinal_, valid once one ran), and p at its start.
  bool freshStep_ = false;
  bool dpFinalValid_ = false;
  RealView dpFinal_, pFinalStart_;
  /// meshPhi_ is all zeros (static mesh or steady), so computeMeshFlux need not rewrite it.
  bool meshFluxZero_ = true;
  /// dphi_ holds the latest correction fluxes (written by solve() or setVelocity since the last
  /// beginStep); otherwise they are in dphi0_ and dphi_ is scratch.
  bool dphiLatest_ = true;
  /// Some boundary face takes its velocity from its cell (slip, empty, pressure): the boundary
  /// velocities must follow every change of U. With walls and inlets alone they depend on the
  /// prescribed values only.
  bool boundaryVelocityReadsU_ = true;
  /// gradU_ is what velocityGradient() promises (see there); false when the outer loop skipped it.
  mutable bool gradUCurrent_ = false;  ///< a resistance outlet changes the boundary pressure every corrector
  real c1_ = 0, c0_ = 0, c00_ = 0;     ///< time weights: d(phi)/dt ~ (c1 phi - c0 phi0 + c00 phi00)/dt
  MeshMotion motion_;
  /// \brief The iterate at the start of the step and the solver state a solve reads besides it.
  struct StepStartIterate {
    bool enabled = false;
    bool valid = false;  ///< taken at the last beginStep
    Real3View U;
    Real3View gradP;  ///< the last corrector's pressure gradient, which the first outer iteration reads
    RealView p, phi, dpFinal;
    bool dpFinalValid = false;
    long pressureAssemblies = 0;
    int refreshBaselineIterations = -1;
  };
  StepStartIterate stepStart_;
  void takeStepStart();
};

}  // namespace mfsi::fluid
