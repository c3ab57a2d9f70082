#include "fluid/FluidSolver.hpp"

#include "core/Error.hpp"
#include "core/MeshRegions.hpp"
#include "fluid/MeshFlux.hpp"
#include "kernels/CsrBuild.hpp"
#include "kernels/DistributedAmg.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>

namespace mfsi::fluid {

namespace {

// TVD limiters in r-form (OpenFOAM's r = 2 d.grad(phi_C) / (phi_D - phi_C) - 1).
KOKKOS_INLINE_FUNCTION real limiter(ConvectionScheme s, real r) {
  if (s == ConvectionScheme::LimitedLinear) {
    const real v = 2.0 * r;
    return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
  }
  const real ar = kmath::fabs(r);
  return (r + ar) / (1.0 + ar);  // van Leer
}

/// Rhie-Chow correction flux of internal face f (owner o, neighbour n) stored for the next step:
/// phi_f minus the flux of the linearly interpolated cell velocities. storeDdtCorrection and the
/// fused finishStep share it.
KOKKOS_INLINE_FUNCTION real ddtCorrectionFlux(lid_t f, lid_t o, lid_t n, const ConstRealView& w, real phi,
                                              const ConstReal3View& U, const ConstReal3View& sf) {
  real s = 0;
  for (int k = 0; k < 3; ++k) s += (w(f) * U(o, k) + (1.0 - w(f)) * U(n, k)) * sf(f, k);
  return phi - s;
}

/// Pressure on boundary face b (face f, owner o with pressure po and gradient go): prescribed on
/// fixed-pressure faces, the owner's value on empty faces (and everywhere without extrapolation),
/// otherwise extrapolated from the owner with its gradient. updateBoundaryPressure and the fused
/// gradient pass share it.
KOKKOS_INLINE_FUNCTION real boundaryFacePressure(lid_t b, lid_t f, lid_t o, real po, const real go[3], bool extrapolate,
                                                 const ConstIndexView& kind, const ConstRealView& bp,
                                                 const ConstReal3View& fc, const ConstReal3View& cc) {
  const int kd = kind(b);
  if (kd == kFacePressure) return bp(b);
  if (kd == kFaceEmpty || !extrapolate) return po;
  real s = po;
  for (int k = 0; k < 3; ++k) s += go[k] * (fc(f, k) - cc(o, k));
  return s;
}

/// One cell of the fused FluidSolver::updatePressureGradient: the pressures of the cell's boundary
/// faces and its Gauss-linear gradient through the stencil (the formula of the gaussStencil kernel).
///
/// Why one pass is exact: a boundary face's pressure depends on its owner's p and gradient alone,
/// and a cell's gradient reads the pressures of its own boundary faces alone. So the sequence of
/// updatePressureGradient (boundary pressures from the previous gradient, gradient, with
/// extrapolated wall pressures boundary pressures again from that gradient and the gradient of
/// the boundary cells again) is, per cell, a second sweep over the cell's own stencil right after
/// the first (its data still in cache), with the same operations in the same order: the same bits
/// without the separate boundary-pressure kernels and the pass over the scattered boundary cells.
/// (Forming U = HbyA - rAU grad p in this pass too was measured no faster than the separate
/// streaming correction pass, which finds grad p still in cache.)
struct PressureGradientKernel {
  lid_t nIn = 0;
  bool extrapolate = false;  ///< extrapolated wall pressures (see updatePressureGradient)
  ConstIndexView off, other, kind;
  ConstReal3View self, coef, fc, cc;
  ConstRealView p, bp;
  RealView pb;
  Real3View gp;

  /// Gradient g of p at cell c, its boundary faces extrapolating with gradient `gb` (stored in pb
  /// with `store`). Returns whether c has a boundary face.
  KOKKOS_FORCEINLINE_FUNCTION bool gradient(lid_t c, real pc, const real gb[3], real g[3], bool store) const {
    bool boundary = false;
    for (int d = 0; d < 3; ++d) g[d] = self(c, d) * pc;
    for (lid_t e = off(c); e < off(c + 1); ++e) {
      const lid_t o = other(e);
      real v;
      if (o >= 0) {
        v = p(o);
      } else {
        const lid_t b = -o - 1;
        v = boundaryFacePressure(b, b + nIn, c, pc, gb, extrapolate, kind, bp, fc, cc);
        if (store) pb(b) = v;
        boundary = true;
      }
      for (int d = 0; d < 3; ++d) g[d] += coef(e, d) * v;
    }
    return boundary;
  }

  KOKKOS_FORCEINLINE_FUNCTION void operator()(lid_t c) const {
    const real pc = p(c);
    const real g0[3] = {gp(c, 0), gp(c, 1), gp(c, 2)};
    real g[3];
    if (gradient(c, pc, g0, g, /*store=*/!extrapolate) && extrapolate) {
      const real g1[3] = {g[0], g[1], g[2]};
      gradient(c, pc, g1, g, /*store=*/true);
    }
    for (int d = 0; d < 3; ++d) gp(c, d) = g[d];
  }
};

/// Sum of |U| and |p| of a cell: summed over the cells it is finite iff every field value is.
KOKKOS_INLINE_FUNCTION real fieldMagnitude(lid_t c, const ConstReal3View& U, const ConstRealView& p) {
  return kmath::fabs(U(c, 0)) + kmath::fabs(U(c, 1)) + kmath::fabs(U(c, 2)) + kmath::fabs(p(c));
}

/// The non-orthogonal part of the face-normal pressure gradient of internal face f (times its
/// area): (S - deltaCoeff d) . grad p interpolated to the face (the explicit correction).
KOKKOS_INLINE_FUNCTION real nonOrthogonalPart(lid_t f, lid_t o, lid_t n, real wf, const ConstReal3View& kv,
                                              const ConstReal3View& gp) {
  real corr = 0;
  for (int i = 0; i < 3; ++i) corr += kv(f, i) * (wf * gp(o, i) + (1.0 - wf) * gp(n, i));
  return corr;
}

/// The limit psi / (1 - psi) of OpenFOAM's `limited psi` scheme; negative when psi = 1 (no limit).
inline real nonOrthogonalLimitFactor(real psi) { return psi >= 1.0 ? -1.0 : psi / (1.0 - psi); }

/// The explicit correction `corr` of a face limited to `lim` times the orthogonal part `orth`
/// (OpenFOAM's limiter corr * min(lim |orth| / |corr|, 1)); lim < 0: unlimited.
KOKKOS_INLINE_FUNCTION real limitedCorrection(real corr, real orth, real lim) {
  if (lim < 0) return corr;
  const real m = lim * kmath::fabs(orth);
  return corr > m ? m : (corr < -m ? -m : corr);
}

/// Pressure-equation coefficient of internal face f: the face-interpolated rAU over the distance.
KOKKOS_INLINE_FUNCTION real pressureFaceCoefficient(lid_t f, lid_t o, lid_t n, const ConstRealView& w,
                                                    const ConstRealView& rAU, const ConstRealView& dc) {
  const real wf = w(f);
  return (wf * rAU(o) + (1.0 - wf) * rAU(n)) * dc(f);
}

/// The under-relaxed momentum diagonal a_P / alpha; the source gets (that - a_P) u_prev and the
/// face fluxes the matching Rhie-Chow term (storeRelaxationFlux), so the converged solution does not
/// depend on it. `dominant` (relaxVelocity < 1) relaxes max(|a_P|, sum_N |a_PN|) instead, as
/// OpenFOAM's fvMatrix::relax does: where central convection makes a row lose diagonal dominance
/// (cell Peclet number above 2, or a Courant number well above 1) the relaxed row keeps it. Without
/// it SIMPLE broke down on a graded Gmsh cylinder mesh and stalled on the fine block mesh.
KOKKOS_INLINE_FUNCTION real relaxedDiagonal(real diag, real sumMagOff, real alpha, bool dominant) {
  if (!dominant) return diag / alpha;
  const real d = kmath::fabs(diag);
  return (d > sumMagOff ? d : sumMagOff) / alpha;
}

/// One row of FluidSolver::assembleMomentumFused (see there). A named functor rather than a
/// lambda: the compiler then inlines the call into the launch loop (a lambda this size was called
/// per cell).
struct MomentumRowKernel {
  real rhoUniform = 0, muUniform = 0, rdt = 0, c1 = 0, c0 = 0, c00 = 0, alpha = 1;
  bool perCell = false;     ///< rhoC and muC per cell instead of rhoUniform and muUniform
  ConstRealView rhoC, muC;
  real g[3] = {0, 0, 0};
  bool implicitLinear = true, steady = false, moving = true, old2 = true;
  bool dominant = false;  ///< relax from max(|a_P|, sum |a_N|) (see relaxedDiagonal)
  RealView frac;          ///< when not empty: 1 - a_P / (relaxed a_P), for the Rhie-Chow relaxation term
  lid_t nIn = 0;
  ConstIndexView off, cf, own, cfp, rowPtr, di, kind;
  ConstRealView phi, mp, w, dc, V, V0, V00;
  ConstReal3View U, U0, U00, Ub;
  RealView vals;
  Real3View rhs;
  bool withB = false;  ///< also the momentum solve's right-hand side b = rhs - V grad p
  ConstReal3View gp;
  Real3View b3;
  /// When not empty: also the Jacobi inverse diagonal 1 / a_P of the momentum solve, with
  /// invertDiagonal's formula and check (0 where a_P is zero or not finite; firstBad: the first
  /// such row).
  RealView inv;

  KOKKOS_FORCEINLINE_FUNCTION void operator()(lid_t c, lid_t& firstBad) const {
    for (lid_t k = rowPtr(c); k < rowPtr(c + 1); ++k) vals(k) = 0.0;
    // Another fluid's cells (FluidOptions::regions): every face of the row is the same fluid's.
    const real rho = perCell ? rhoC(c) : rhoUniform, mu = perCell ? muC(c) : muUniform;
    real diag = steady ? 0.0 : rho * c1 * V(c) * rdt;
    real src[3], bsum[3] = {0.0, 0.0, 0.0}, sumOff = 0.0;
    for (int j = 0; j < 3; ++j) {
      src[j] = rho * V(c) * g[j];
      // c00 = 0: c0 V0 U0 - 0 is c0 V0 U0 (up to the sign of a zero).
      if (!steady)
        src[j] += rho * (old2 ? c0 * V0(c) * U0(c, j) - c00 * V00(c) * U00(c, j) : c0 * V0(c) * U0(c, j)) * rdt;
    }
    for (lid_t e = off(c); e < off(c + 1); ++e) {
      const lid_t f = cf(e);
      const real F = rho * (phi(f) - (moving ? mp(f) : 0.0));  // mass flux relative to the moving face
      const real D = mu * dc(f);
      if (f < nIn) {
        const bool isOwner = own(f) == c;
        const real wf = w(f);
        real dg, od;
        if (implicitLinear) {
          dg = isOwner ? F * wf + D : -F * (1.0 - wf) + D;
          od = isOwner ? F * (1.0 - wf) - D : -F * wf - D;
        } else {
          const real Fp = F > 0 ? F : 0.0, Fm = F < 0 ? F : 0.0;
          dg = isOwner ? Fp + D : -Fm + D;
          od = isOwner ? Fm - D : -Fp - D;
        }
        diag += dg;
        sumOff += kmath::fabs(od);
        vals(cfp(e)) += od;
      } else {
        // A boundary face's owner is this cell: its flux enters the divergence with +1.
        const lid_t b = f - nIn;
        switch (kind(b)) {
          case kFaceVelocity:
          case kFaceWall:
            diag += D;
            for (int j = 0; j < 3; ++j) bsum[j] += (F - D) * Ub(b, j);
            break;
          case kFaceSlip:
            diag += D;
            for (int j = 0; j < 3; ++j) bsum[j] += -D * Ub(b, j);
            break;
          case kFaceEmpty:
            diag += 0.0;
            break;
          default: {  // pressure outlet: zero-gradient, outflow implicit, backflow lagged
            diag += F > 0 ? F : 0.0;
            const real Fm = F < 0 ? F : 0.0;
            for (int j = 0; j < 3; ++j) bsum[j] += Fm * Ub(b, j);
            break;
          }
        }
      }
    }
    // Implicit under-relaxation: a_P -> a_P / alpha, source += (a_P / alpha - a_P) u_prev.
    const real ar = relaxedDiagonal(diag, sumOff, alpha, dominant);
    vals(di(c)) = ar;
    if (frac.extent(0) > 0) frac(c) = ar != 0.0 ? 1.0 - diag / ar : 0.0;
    if (inv.extent(0) > 0) {
      const real v = 1.0 / ar;
      const bool ok = ar != 0.0 && v - v == 0.0;  // v - v != 0 for inf and NaN
      inv(c) = ok ? v : 0.0;
      if (!ok && c < firstBad) firstBad = c;
    }
    for (int j = 0; j < 3; ++j) {
      const real r = (src[j] + -1.0 * bsum[j]) + (ar - diag) * U(c, j);
      rhs(c, j) = r;
      if (withB) b3(c, j) = r - V(c) * gp(c, j);
    }
  }
};

}  // namespace

/// Face fluxes from the solved pressure: the source flux `fl` minus the implicit part of the
/// pressure-gradient flux, on internal and fixed-pressure faces (the other boundary faces keep the
/// flux their condition sets). The pressure::flux kernel and the end-of-step flux pass share it.
struct PressureFaceFlux {
  lid_t nIn = 0;
  ConstIndexView own, nei, kind;
  ConstRealView w, dc, rAU, fl, p;
  RealView phi;

  /// The flux of internal face f (owner o, neighbour n).
  KOKKOS_INLINE_FUNCTION real internal(lid_t f, lid_t o, lid_t n) const {
    const real rAUf = w(f) * rAU(o) + (1.0 - w(f)) * rAU(n);
    return fl(f) - rAUf * dc(f) * (p(n) - p(o));
  }

  /// The flux of boundary face f (owner o), stored on a fixed-pressure face.
  KOKKOS_INLINE_FUNCTION void boundary(lid_t f, lid_t o) const {
    if (kind(f - nIn) == kFacePressure) phi(f) = fl(f) + rAU(o) * dc(f) * p(o);
  }

  KOKKOS_INLINE_FUNCTION void operator()(lid_t f) const {
    const lid_t o = own(f);
    if (f < nIn)
      phi(f) = internal(f, o, nei(f));
    else
      boundary(f, o);
  }
};

// The constructor's kernels: nvcc takes no device lambda in a constructor (its address cannot be
// taken), so they are free functions.
namespace {

/// Boundary faces whose velocity is taken from their cell (slip, empty, pressure).
lid_t countVelocityFromCells(const ExecSpace& exec, const ConstIndexView& kind, lid_t nB) {
  lid_t n = 0;
  Kokkos::parallel_reduce(
      "mfsi::fluid::bc::countVelocityFromCells", RangePolicy(exec, 0, nB),
      KOKKOS_LAMBDA(lid_t b, lid_t & acc) {
        const int kd = kind(b);
        acc += (kd == kFaceSlip || kd == kFaceEmpty || kd == kFacePressure) ? 1 : 0;
      },
      n);
  return n;
}

/// The first `nRows` rows of A: the same arrays, the row pointer and diagonal cut (the solvers'
/// view of a decomposed mesh's matrix, whose ghost rows are assembled but not solved for), with
/// row runs of their own and, with `ghostSplit` (a solve that overlaps its exchanges), their split
/// by ghost columns.
CsrMatrix ownedRows(const CsrMatrix& A, lid_t nRows, bool ghostSplit) {
  CsrMatrix R = A;
  R.nRows = nRows;
  R.nCols = A.nCols;
  R.rowPtr = Kokkos::subview(A.rowPtr, Kokkos::make_pair(lid_t(0), nRows + 1));
  R.diagIdx = Kokkos::subview(A.diagIdx, Kokkos::make_pair(lid_t(0), nRows));
  // A's runs cover its ghost rows too, and one may run across the last owned row.
  const auto ptr = Kokkos::create_mirror_view_and_copy(HostSpace(), R.rowPtr);
  const auto col = Kokkos::create_mirror_view_and_copy(HostSpace(), A.colIdx);
  R.runs = buildRowRuns(nRows, std::vector<lid_t>(ptr.data(), ptr.data() + nRows + 1),
                        std::vector<lid_t>(col.data(), col.data() + ptr(nRows)), A.values.label());
  if (ghostSplit) R.ghostSplit = buildGhostSplit(nRows, nRows, R.rowPtr, R.colIdx, R.runs, A.values.label());
  return R;
}

/// U = u0 in every cell.
void fillVelocity(const ExecSpace& exec, const Real3View& U, const Vec3& u0) {
  const real u0x = u0[0], u0y = u0[1], u0z = u0[2];
  Kokkos::parallel_for(
      "mfsi::fluid::init", RangePolicy(exec, 0, static_cast<lid_t>(U.extent(0))), KOKKOS_LAMBDA(lid_t c) {
        U(c, 0) = u0x;
        U(c, 1) = u0y;
        U(c, 2) = u0z;
      });
}

}  // namespace

FluidSolver::FluidSolver(const HexMesh& mesh, const FluidOptions& options, const RankDomain& domain)
    : mesh_(mesh),
      opt_(options),
      nCells_(mesh.nCells()),
      nFaces_(mesh.nFaces()),
      nIn_(mesh.nInternalFaces()),
      nB_(mesh.nBoundaryFaces()),
      nRows_(mesh.nOwnedCells()) {
  MFSI_CHECK(domain.distributed() || nRows_ == nCells_,
             "fluid: the mesh has ghost cells but no ranks to take their values from");
  if (domain.distributed()) {
    MFSI_CHECK(domain.cells.nOwned == nRows_ && domain.cells.nLocal == nCells_,
               "fluid: the halo plan (" << domain.cells.nOwned << " owned, " << domain.cells.nLocal
                                        << " local cells) is not the mesh's (" << nRows_ << ", " << nCells_ << ")");
    cellHalo_ = std::make_unique<Halo>(domain.comm, domain.cells);
    comm_ = SolverComm(domain.comm, cellHalo_.get());
    comm_.setOverlap(opt_.overlapHalo);
  }
  MFSI_CHECK(opt_.density > 0, "fluid: density must be positive (key fluid.density)");
  MFSI_CHECK(opt_.viscosity >= 0, "fluid: viscosity must be non-negative (key fluid.viscosity)");
  MFSI_CHECK(opt_.pimple.nOuterCorrectors >= 1, "fluid: nOuterCorrectors must be >= 1");
  MFSI_CHECK(opt_.pimple.nCorrectors >= 1, "fluid: nCorrectors must be >= 1");
  MFSI_CHECK(opt_.pimple.nNonOrthogonalCorrectors >= 0, "fluid: nNonOrthogonalCorrectors must be >= 0");
  MFSI_CHECK(opt_.pimple.relaxVelocity > 0 && opt_.pimple.relaxVelocity <= 1, "fluid: relaxVelocity must be in (0, 1]");
  MFSI_CHECK(opt_.pimple.relaxPressure > 0 && opt_.pimple.relaxPressure <= 1, "fluid: relaxPressure must be in (0, 1]");
  MFSI_CHECK(!opt_.pimple.consistent || (opt_.timeScheme == TimeScheme::Steady && opt_.pimple.relaxVelocity < 1),
             "fluid: SIMPLEC (consistent) needs timeScheme steady and relaxVelocity < 1");
  {
    // The reference cell is a global id: found among the owned cells of whichever rank has it.
    auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.cellGlobalIds());
    lid_t found = 0;
    for (lid_t c = 0; c < nRows_; ++c)
      if (static_cast<long long>(gid(c)) == static_cast<long long>(opt_.pressureReferenceCell)) {
        referenceRow_ = c;
        found = 1;
      }
    MFSI_CHECK(comm_.globalSum(static_cast<double>(found)) == 1.0,
               "fluid: pressureReferenceCell " << opt_.pressureReferenceCell << " is not a cell of the mesh");
  }
  MFSI_CHECK(opt_.artificialCompressibility.soundSpeed >= 0,
             "fluid: artificialCompressibility.soundSpeed must be >= 0 (0: off), got "
                 << opt_.artificialCompressibility.soundSpeed);
  ScopedRegion region("mfsi::fluid::setup");

  geo_ = allocateGeometry(mesh);
  fd_ = allocateFaceData(mesh);
  if (opt_.gradient == GradientScheme::GaussLinear) gradStencil_ = allocateGradientStencil(mesh);
  sparsity_ = buildSparsity(mesh);
  Au_ = makeMatrix(sparsity_, "mfsi::fluid::momentum::matrix");
  Ap_ = makeMatrix(sparsity_, "mfsi::fluid::pressure::matrix");
  bc_ = BoundaryConditions(mesh, opt_, comm_);
  boundaryCells_ = boundaryCells(mesh);
  for (const auto& rp : bc_.patches()) hasResistance_ = hasResistance_ || rp.type == BoundaryType::Resistance;
  // A valve's faces read their cell's velocity while it is open.
  boundaryVelocityReadsU_ = countVelocityFromCells(exec_, bc_.kind(), nB_) > 0 || bc_.hasValves();
  linear_ = LinearSolver(nCells_, opt_.pressurePreconditioner);
  if (cellHalo_) {
    // Only the pressure solve overlaps its exchanges (FluidOptions::overlapHalo).
    AuRows_ = ownedRows(Au_, nRows_, false);
    ApRows_ = ownedRows(Ap_, nRows_, opt_.overlapHalo);
    std::unique_ptr<Preconditioner> pressure;
    if (opt_.pressurePreconditioner == PressurePreconditioner::Amg) {
      auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.cellGlobalIds());
      std::vector<gid_t> ids(gid.data(), gid.data() + nCells_);
      DistributedAmgOptions amg;
      amg.overlapExchange = opt_.overlapHalo;
      pressure = std::make_unique<DistributedAmg>(domain.comm, domain.cells, std::move(ids), amg);
    }
    linear_.distribute(comm_, std::move(pressure));
  }

  if (!opt_.regions.empty()) setUpRegions(domain);

  U_ = Real3View("mfsi::fluid::U", nCells_);
  U0_ = Real3View("mfsi::fluid::U0", nCells_);
  U00_ = Real3View("mfsi::fluid::U00", nCells_);
  p_ = RealView("mfsi::fluid::p", nCells_);
  pPrev_ = RealView("mfsi::fluid::pPrevIter", nCells_);
  p0_ = RealView("mfsi::fluid::p0", nCells_);
  p00_ = RealView("mfsi::fluid::p00", nCells_);
  V0_ = RealView("mfsi::fluid::V0", nCells_);
  V00_ = RealView("mfsi::fluid::V00", nCells_);
  HbyA_ = Real3View("mfsi::fluid::HbyA", nCells_);
  gradP_ = Real3View("mfsi::fluid::gradP", nCells_);
  rhsU_ = Real3View("mfsi::fluid::momentum::rhs", nCells_);
  gradU_ = Tensor3View("mfsi::fluid::gradU", nCells_);
  rAU_ = RealView("mfsi::fluid::rAU", nCells_);
  if (opt_.pimple.consistent) rAUSimple_ = RealView("mfsi::fluid::rAUSimple", nCells_);
  if (opt_.pimple.relaxVelocity < 1.0) {
    relaxFraction_ = RealView("mfsi::fluid::relaxFraction", nCells_);
    relaxFlux_ = RealView("mfsi::fluid::relaxFlux", nFaces_);
  }
  cellDiag_ = RealView("mfsi::fluid::cellDiag", nCells_);
  rhsP_ = RealView("mfsi::fluid::pressure::rhs", nCells_);
  b_ = RealView("mfsi::fluid::solveB", nCells_);
  b3_ = Real3View("mfsi::fluid::momentum::solveB", nCells_);
  phi_ = RealView("mfsi::fluid::phi", nFaces_);
  meshPhi_ = RealView("mfsi::fluid::meshPhi", nFaces_);
  dphi_ = RealView("mfsi::fluid::ddtCorr::dphi", nFaces_);
  dphi0_ = RealView("mfsi::fluid::ddtCorr::dphi0", nFaces_);
  dphi00_ = RealView("mfsi::fluid::ddtCorr::dphi00", nFaces_);
  sweptNew_ = RealView("mfsi::fluid::sweptVolume", nFaces_);
  sweptOld_ = RealView("mfsi::fluid::sweptVolume0", nFaces_);
  fluxP_ = RealView("mfsi::fluid::pressure::faceFlux", nFaces_);
  Ub_ = Real3View("mfsi::fluid::Ub", nB_);
  faceMeshVel_ = Real3View("mfsi::fluid::faceMeshVelocity", nB_);
  pb_ = RealView("mfsi::fluid::pb", nB_);
  points0_ = Real3View("mfsi::fluid::points0", mesh.nNodes());

  updateGeometry();
  Kokkos::deep_copy(exec_, points0_, mesh.points());
  Kokkos::deep_copy(exec_, V0_, geo_.cellVolume);
  Kokkos::deep_copy(exec_, V00_, geo_.cellVolume);

  fillVelocity(exec_, U_, opt_.initialVelocity);
  Kokkos::deep_copy(exec_, p_, opt_.initialPressure);
  Kokkos::deep_copy(exec_, p0_, opt_.initialPressure);
  Kokkos::deep_copy(exec_, p00_, opt_.initialPressure);
  computeTimeCoefficients();
  bc_.update(exec_, 0.0, geo_, faceMeshVel_);
  setVelocity(U_);
  updatePressureGradient();
  exec_.fence();
}

// ------------------------------------------------------------------------------------------------
// Time levels and mesh motion
// ------------------------------------------------------------------------------------------------

void FluidSolver::updateGeometry() {
  computeGeometry(exec_, mesh_, geo_);
  computeFaceData(exec_, mesh_, geo_, fd_);
  if (opt_.gradient == GradientScheme::GaussLinear) computeGradientStencil(exec_, mesh_, geo_, fd_, gradStencil_);
  gradPValid_ = false;
  // Largest |k_f| / |S_f| of the non-orthogonal part of the internal face area vectors.
  ConstReal3View k = fd_.nonOrth;
  ConstRealView sm = geo_.faceAreaMag;
  real kmax = 0;
  Kokkos::parallel_reduce(
      "mfsi::fluid::faceData::nonOrthMax", RangePolicy(exec_, 0, nIn_),
      KOKKOS_LAMBDA(lid_t f, real & m) {
        const real r = (kmath::fabs(k(f, 0)) + kmath::fabs(k(f, 1)) + kmath::fabs(k(f, 2))) / sm(f);
        m = r > m ? r : m;
      },
      Kokkos::Max<real>(kmax));
  // Round-off of a Cartesian mesh is ~1e-16; a face tilted by 1e-8 rad already counts.
  // A limit of 0 is the uncorrected scheme: the mesh is then treated as orthogonal.
  kmax = comm_.globalMax(kmax);
  nonOrthogonal_ = !(kmax <= 1e-12) && opt_.nonOrthogonalLimit > 0;
}

void FluidSolver::computeTimeCoefficients() {
  switch (opt_.timeScheme) {
    case TimeScheme::Steady:
      c1_ = c0_ = c00_ = 0.0;
      break;
    case TimeScheme::Euler:
      c1_ = c0_ = 1.0;
      c00_ = 0.0;
      break;
    case TimeScheme::BDF2:
      if (bdf2Active_) {
        // Variable-step BDF2: d/dt ~ (c1 y^{n+1} - c0 y^n + c00 y^{n-1}) / dt.
        c1_ = 1.0 + dt_ / (dt_ + dt0_);
        c00_ = dt_ * dt_ / (dt0_ * (dt_ + dt0_));
        c0_ = c1_ + c00_;
      } else {
        c1_ = c0_ = 1.0;
        c00_ = 0.0;
      }
      break;
  }
}

void FluidSolver::computeMeshFlux() {
  meshStatic_ = sweptNewZero_ && sweptOldZero_;
  // phi^m = (c1 dV^{n+1} - c00 dV^n) / dt: summed over a cell's faces this is exactly the discrete
  // time derivative of its volume with the same weights as the momentum time term.
  const real c1 = c1_, c00 = c00_, rdt = 1.0 / dt_;
  const bool steady = opt_.timeScheme == TimeScheme::Steady;
  // No swept volumes: the flux is zero, and need not be written again if it is zero already.
  const bool zero = steady || meshStatic_;
  if (zero && meshFluxZero_) return;
  meshFluxZero_ = zero;
  auto mp = meshPhi_;
  ConstRealView sn = sweptNew_, so = sweptOld_;
  Kokkos::parallel_for(
      "mfsi::fluid::meshFlux", RangePolicy(exec_, 0, nFaces_),
      KOKKOS_LAMBDA(lid_t f) { mp(f) = steady ? 0.0 : (c1 * sn(f) - c00 * so(f)) * rdt; });
}

void FluidSolver::beginStep(real t, real dt) {
  MFSI_CHECK(dt > 0, "fluid: time step must be positive, got " << dt);
  ScopedRegion region("mfsi::fluid::beginStep");
  // Time levels are copied only where something reads them: the second old levels by BDF2 alone
  // (their weight c00 is 0 otherwise), the old pressures by artificial compressibility alone, and
  // volumes, swept volumes and positions only if the mesh moved since they were last copied
  // (otherwise the copy would not change them).
  const bool bdf2 = opt_.timeScheme == TimeScheme::BDF2;
  const bool ac = compressible();
  if (nSteps_ > 0) {
    dt0_ = dt_;
    // U00 <- U0 by handing the arrays on (U0_ is rewritten in full just below): one n x 3 copy
    // per step fewer. Kernels take these handles at launch, so none holds the old ones.
    if (bdf2 || extrapolatesVelocity()) std::swap(U00_, U0_);
    if (bdf2) Kokkos::deep_copy(exec_, V00_, V0_);
    if (ac) Kokkos::deep_copy(exec_, p00_, p0_);
    if (!(sweptNewZero_ && sweptOldZero_)) Kokkos::deep_copy(exec_, sweptOld_, sweptNew_);
    sweptOldZero_ = sweptNewZero_;
    bdf2Active_ = bdf2;
  }
  Kokkos::deep_copy(exec_, U0_, U_);
  if (meshMoved_) Kokkos::deep_copy(exec_, V0_, geo_.cellVolume);
  // dphi00 <- dphi0 (BDF2 alone reads it), dphi0 <- dphi. dphi_ is rewritten in full by every
  // solve() (and setVelocity), so when it holds the latest values the arrays are handed on
  // instead of copied; afterwards the latest values are in dphi0_ and dphi_ is scratch.
  const bool shift2 = bdf2 && nSteps_ > 0;
  if (dphiLatest_) {
    RealView spare = shift2 ? dphi00_ : dphi0_;
    if (shift2) dphi00_ = dphi0_;
    dphi0_ = dphi_;
    dphi_ = spare;
    dphiLatest_ = false;
  } else if (shift2) {
    Kokkos::deep_copy(exec_, dphi00_, dphi0_);  // dphi0_ already holds the latest values
  }
  if (ac) Kokkos::deep_copy(exec_, p0_, p_);
  if (!sweptNewZero_) Kokkos::deep_copy(exec_, sweptNew_, 0.0);
  sweptNewZero_ = true;
  Kokkos::deep_copy(exec_, faceMeshVel_, 0.0);
  if (meshMoved_) Kokkos::deep_copy(exec_, points0_, mesh_.points());
  meshMoved_ = false;
  t_ = t;
  dt_ = dt;
  ++nSteps_;
  freshStep_ = true;
  computeTimeCoefficients();
  computeMeshFlux();
  bc_.update(exec_, t_ + dt_, geo_, faceMeshVel_);
  // New prescribed pressures (time functions) change the boundary values the gradient sees.
  if (bc_.fixesPressureLevel()) gradPValid_ = false;
  updateBoundaryVelocity();
  if (stepStart_.enabled) takeStepStart();
}

void FluidSolver::saveState(io::StateWriter& w) const {
  exec_.fence();
  // Fields a step reads before it writes them; the scratch of an outer iteration (HbyA, the
  // right-hand sides, the face coefficients and fluxes of one corrector) is not kept.
  w.putView("U", U_, io::Entity::Cells);
  w.putView("U0", U0_, io::Entity::Cells);
  w.putView("U00", U00_, io::Entity::Cells);
  w.putView("p", p_, io::Entity::Cells);
  w.putView("pPrevIter", pPrev_, io::Entity::Cells);
  w.putView("p0", p0_, io::Entity::Cells);
  w.putView("p00", p00_, io::Entity::Cells);
  w.putView("V0", V0_, io::Entity::Cells);
  w.putView("V00", V00_, io::Entity::Cells);
  w.putView("gradP", gradP_, io::Entity::Cells);
  w.putView("rAU", rAU_, io::Entity::Cells);
  w.putBool("gradUCurrent", gradUCurrent_);
  if (gradUCurrent_) w.putView("gradU", gradU_, io::Entity::Cells);
  w.putView("phi", phi_, io::Entity::FaceFluxes);
  w.putView("meshPhi", meshPhi_, io::Entity::FaceFluxes);
  w.putView("dphi", dphi_, io::Entity::FaceFluxes);
  w.putView("dphi0", dphi0_, io::Entity::FaceFluxes);
  w.putView("dphi00", dphi00_, io::Entity::FaceFluxes);
  w.putView("sweptNew", sweptNew_, io::Entity::FaceFluxes);
  w.putView("sweptOld", sweptOld_, io::Entity::FaceFluxes);
  w.putView("Ub", Ub_, io::Entity::BoundaryFaces);
  w.putView("faceMeshVelocity", faceMeshVel_, io::Entity::BoundaryFaces);
  w.putView("pb", pb_, io::Entity::BoundaryFaces);
  w.putView("points0", points0_, io::Entity::Nodes);
  w.putView("dpFinal", dpFinal_, io::Entity::Cells);
  w.putView("pressureMatrix", Ap_.values, io::Entity::Part);
  w.put("time", std::vector<double>{t_, dt_, dt0_, c1_, c0_, c00_});
  w.putInt("steps", nSteps_);
  // The levels a closed domain and closed regions are pinned at (a coupling moves them).
  std::vector<double> levels{opt_.pressureReferenceValue};
  levels.insert(levels.end(), regionLevel_.begin(), regionLevel_.end());
  w.put("pressureLevels", levels);
  w.putInt("pressureAssemblies", pressureAssemblies_);
  w.putInt("refreshBaselineIterations", refreshBaselineIterations_);
  const bool flags[] = {pressureRefreshDue_, bdf2Active_, gradPValid_, sweptNewZero_, sweptOldZero_, meshStatic_,
                        meshMoved_, freshStep_, dpFinalValid_, meshFluxZero_, dphiLatest_};
  std::vector<std::int64_t> f;
  for (bool b : flags) f.push_back(b ? 1 : 0);
  w.put("flags", f);
  io::StateWriter bc = w.sub("boundaryConditions");
  bc_.saveState(bc);
  io::StateWriter pp = w.sub("pressurePreconditioner");
  linear_.savePressurePreconditioner(pp);
}

void FluidSolver::loadState(const io::StateReader& r) {
  // The geometry of the points the mesh is at now (restored by the caller), as moveMesh made it.
  updateGeometry();
  if (r.has("pressureLevels")) {
    const auto levels = r.doubles("pressureLevels", 1 + static_cast<long long>(regionLevel_.size()));
    opt_.pressureReferenceValue = levels[0];
    for (std::size_t k = 0; k < regionLevel_.size(); ++k) regionLevel_[k] = levels[k + 1];
    if (!regionLevel_.empty()) shiftPressureLevel(0, 0);  // the pinned values
  }
  r.getView("U", U_);
  r.getView("U0", U0_);
  r.getView("U00", U00_);
  r.getView("p", p_);
  r.getView("pPrevIter", pPrev_);
  r.getView("p0", p0_);
  r.getView("p00", p00_);
  r.getView("V0", V0_);
  r.getView("V00", V00_);
  r.getView("gradP", gradP_);
  r.getView("rAU", rAU_);
  gradUCurrent_ = r.boolean("gradUCurrent");
  if (gradUCurrent_) r.getView("gradU", gradU_);
  r.getView("phi", phi_);
  r.getView("meshPhi", meshPhi_);
  r.getView("dphi", dphi_);
  r.getView("dphi0", dphi0_);
  r.getView("dphi00", dphi00_);
  r.getView("sweptNew", sweptNew_);
  r.getView("sweptOld", sweptOld_);
  r.getView("Ub", Ub_);
  r.getView("faceMeshVelocity", faceMeshVel_);
  r.getView("pb", pb_);
  r.getView("points0", points0_);
  const auto dpShape = r.shape("dpFinal");
  if (!dpShape.empty() && dpShape[0] > 0 && dpFinal_.extent(0) == 0) {  // as startFinalPressureSolve allocates them
    dpFinal_ = RealView("mfsi::fluid::pressure::finalChange", nCells_);
    pFinalStart_ =
        RealView(Kokkos::view_alloc(Kokkos::WithoutInitializing, "mfsi::fluid::pressure::finalStart"), nCells_);
  }
  r.getView("dpFinal", dpFinal_);
  const auto tv = r.doubles("time", 6);
  t_ = tv[0];
  dt_ = tv[1];
  dt0_ = tv[2];
  c1_ = tv[3];
  c0_ = tv[4];
  c00_ = tv[5];
  nSteps_ = static_cast<int>(r.integer("steps"));
  pressureAssemblies_ = static_cast<long>(r.integer("pressureAssemblies"));
  refreshBaselineIterations_ = static_cast<int>(r.integer("refreshBaselineIterations"));
  bool* flags[] = {&pressureRefreshDue_, &bdf2Active_, &gradPValid_, &sweptNewZero_, &sweptOldZero_, &meshStatic_,
                   &meshMoved_, &freshStep_, &dpFinalValid_, &meshFluxZero_, &dphiLatest_};
  const auto f = r.ints("flags", static_cast<long long>(std::size(flags)));
  for (std::size_t i = 0; i < f.size(); ++i) *flags[i] = f[i] != 0;
  bc_.loadState(r.sub("boundaryConditions"));
  // The preconditioner's replay writes Ap_'s values: they are read back after it.
  pressureLattice_ = nullptr;
  if (r.has("pressureMatrix")) {
    linear_.loadPressurePreconditioner(r.sub("pressurePreconditioner"), exec_, pressureMatrix());
    r.getView("pressureMatrix", Ap_.values);
  } else {
    // A checkpoint carried to another decomposition (core/io/Redistribute) has no matrix: the
    // first pressure solve assembles it and sets its preconditioner up afresh.
    pressureRefreshDue_ = true;
  }
  stepStart_.valid = false;
  exec_.fence();
}

namespace {
/// dst <- src, (re)allocating dst to src's size first.
template <class V>
void keepCopy(const ExecSpace& exec, V& dst, const V& src, const char* label) {
  if (dst.extent(0) != src.extent(0)) dst = V(std::string(label), src.extent(0));
  if (src.extent(0) > 0) Kokkos::deep_copy(exec, dst, src);
}
}  // namespace

void FluidSolver::takeStepStart() {
  StepStartIterate& s = stepStart_;
  keepCopy(exec_, s.U, U_, "mfsi::fluid::stepStart::U");
  keepCopy(exec_, s.p, p_, "mfsi::fluid::stepStart::p");
  keepCopy(exec_, s.phi, phi_, "mfsi::fluid::stepStart::phi");
  keepCopy(exec_, s.gradP, gradP_, "mfsi::fluid::stepStart::gradP");
  keepCopy(exec_, s.dpFinal, dpFinal_, "mfsi::fluid::stepStart::dpFinal");
  s.dpFinalValid = dpFinalValid_;
  s.pressureAssemblies = pressureAssemblies_;
  s.refreshBaselineIterations = refreshBaselineIterations_;
  // Every solve from the step's start refreshes the pressure preconditioner at its first assembly,
  // so that it does not depend on the meshes solved on before (a coupling moves the mesh between
  // solves anyway, which changes the matrix).
  pressureRefreshDue_ = true;
  s.valid = true;
}

void FluidSolver::restoreStepStart() {
  const StepStartIterate& s = stepStart_;
  MFSI_CHECK(s.valid, "fluid: restoreStepStart without keepStepStart(true) before beginStep");
  Kokkos::deep_copy(exec_, U_, s.U);
  Kokkos::deep_copy(exec_, p_, s.p);
  Kokkos::deep_copy(exec_, phi_, s.phi);
  Kokkos::deep_copy(exec_, gradP_, s.gradP);
  // dpFinal_ is allocated by the first final pressure solve: a snapshot taken before it has none.
  const bool hadGuess = s.dpFinal.extent(0) > 0 && s.dpFinal.extent(0) == dpFinal_.extent(0);
  if (hadGuess) Kokkos::deep_copy(exec_, dpFinal_, s.dpFinal);
  dpFinalValid_ = s.dpFinalValid && hadGuess;
  pressureAssemblies_ = s.pressureAssemblies;
  refreshBaselineIterations_ = s.refreshBaselineIterations;
  pressureRefreshDue_ = true;  // as at the step's start (takeStepStart)
  // What solve() derives from the iterate: recomputed from the restored fields.
  freshStep_ = true;
  dphiLatest_ = false;
  gradPValid_ = false;
  gradUCurrent_ = false;
  updateBoundaryVelocity();
}

void FluidSolver::moveMesh(const ConstReal3View& newPoints) {
  ScopedRegion region("mfsi::fluid::moveMesh");
  MFSI_CHECK(static_cast<lid_t>(newPoints.extent(0)) == mesh_.nNodes(),
             "fluid: moveMesh: got " << newPoints.extent(0) << " points for a mesh of " << mesh_.nNodes());
  Real3View pts = mesh_.points();
  if (pts.data() != newPoints.data()) Kokkos::deep_copy(exec_, pts, newPoints);
  sweptVolumes(exec_, mesh_, points0_, pts, sweptNew_);
  sweptNewZero_ = false;
  meshMoved_ = true;
  boundaryFaceMeshVelocity(exec_, mesh_, points0_, pts, dt_, faceMeshVel_);
  updateGeometry();
  computeMeshFlux();
  bc_.update(exec_, t_ + dt_, geo_, faceMeshVel_);
  updateBoundaryVelocity();
}

void FluidSolver::setWallVelocity(const std::string& name, const ConstReal3View& faceVelocity) {
  bc_.setWallVelocity(name, faceVelocity);
  updateBoundaryVelocity();
}

void FluidSolver::setVelocity(const ConstReal3View& u) {
  if (u.data() != U_.data()) Kokkos::deep_copy(exec_, U_, u);
  gradUCurrent_ = false;
  updateBoundaryVelocity();
  // Fluxes consistent with the new field: interpolated on internal faces, u_b . S on the boundary.
  ConstIndexView own = mesh_.faceOwner(), nei = mesh_.faceNeighbour();
  ConstReal3View sf = geo_.faceArea;
  ConstRealView w = fd_.weight;
  ConstReal3View U = U_, Ub = Ub_;
  ConstIndexView kind = bc_.kind();
  auto phi = phi_;
  auto mp = meshPhi_;
  const lid_t nIn = nIn_;
  Kokkos::parallel_for(
      "mfsi::fluid::initFlux", RangePolicy(exec_, 0, nFaces_), KOKKOS_LAMBDA(lid_t f) {
        real s = 0;
        if (f < nIn) {
          for (int k = 0; k < 3; ++k) s += (w(f) * U(own(f), k) + (1.0 - w(f)) * U(nei(f), k)) * sf(f, k);
        } else {
          const int kd = kind(f - nIn);
          if (kd == kFaceWall || kd == kFaceSlip || kd == kFaceEmpty) {
            s = mp(f);
          } else {
            for (int k = 0; k < 3; ++k) s += Ub(f - nIn, k) * sf(f, k);
          }
        }
        phi(f) = s;
      });
  Kokkos::deep_copy(exec_, dphi_, 0.0);
  dphiLatest_ = true;
}

void FluidSolver::setPressure(const ConstRealView& p) {
  if (p.data() != p_.data()) Kokkos::deep_copy(exec_, p_, p);
  gradPValid_ = false;
  updatePressureGradient();
}

// ------------------------------------------------------------------------------------------------
// Boundary values
// ------------------------------------------------------------------------------------------------

void FluidSolver::updateBoundaryVelocity() {
  ConstIndexView own = mesh_.faceOwner();
  ConstIndexView kind = bc_.kind();
  ConstReal3View bv = bc_.velocity();
  ConstReal3View sf = geo_.faceArea;
  ConstRealView sm = geo_.faceAreaMag;
  ConstReal3View U = U_;
  ConstRealView mp = meshPhi_;
  auto Ub = Ub_;
  auto phi = phi_;
  const lid_t nIn = nIn_;
  Kokkos::parallel_for(
      "mfsi::fluid::bc::velocity", RangePolicy(exec_, 0, nB_), KOKKOS_LAMBDA(lid_t b) {
        const lid_t f = b + nIn;
        const lid_t o = own(f);
        const real mag = sm(f);
        const real n[3] = {sf(f, 0) / mag, sf(f, 1) / mag, sf(f, 2) / mag};
        switch (kind(b)) {
          case kFaceVelocity: {
            real s = 0;
            for (int k = 0; k < 3; ++k) {
              Ub(b, k) = bv(b, k);
              s += bv(b, k) * sf(f, k);
            }
            phi(f) = s;
            break;
          }
          case kFaceWall: {
            // Tangential velocity as prescribed, normal velocity that of the mesh: no flow through.
            const real un = mp(f) / mag;
            const real uwn = bv(b, 0) * n[0] + bv(b, 1) * n[1] + bv(b, 2) * n[2];
            for (int k = 0; k < 3; ++k) Ub(b, k) = bv(b, k) + n[k] * (un - uwn);
            phi(f) = mp(f);
            break;
          }
          case kFaceSlip: {
            const real un = mp(f) / mag;
            const real upn = U(o, 0) * n[0] + U(o, 1) * n[1] + U(o, 2) * n[2];
            for (int k = 0; k < 3; ++k) Ub(b, k) = U(o, k) + n[k] * (un - upn);
            phi(f) = mp(f);
            break;
          }
          case kFaceEmpty:
            for (int k = 0; k < 3; ++k) Ub(b, k) = U(o, k);
            phi(f) = mp(f);
            break;
          default:  // pressure: zero-gradient velocity, flux from the pressure equation
            for (int k = 0; k < 3; ++k) Ub(b, k) = U(o, k);
            break;
        }
      });
}

void FluidSolver::updateBoundaryPressure() {
  ConstIndexView own = mesh_.faceOwner();
  ConstIndexView kind = bc_.kind();
  ConstRealView bp = bc_.pressure();
  ConstRealView p = p_;
  ConstReal3View gp = gradP_, fc = geo_.faceCentroid, cc = geo_.cellCentroid;
  const bool extrapolate = opt_.wallPressure == WallPressure::Extrapolated;
  auto pb = pb_;
  const lid_t nIn = nIn_;
  Kokkos::parallel_for(
      "mfsi::fluid::bc::pressure", RangePolicy(exec_, 0, nB_), KOKKOS_LAMBDA(lid_t b) {
        const lid_t f = b + nIn, o = own(f);
        const real go[3] = {gp(o, 0), gp(o, 1), gp(o, 2)};
        pb(b) = boundaryFacePressure(b, f, o, p(o), go, extrapolate, kind, bp, fc, cc);
      });
}

void FluidSolver::updatePressureGradient() {
  if (gradPValid_) return;
  if (fusedCellPasses() && opt_.gradient == GradientScheme::GaussLinear) {
    pressureGradientFused();
    exchangeGhosts(gradP_);
    gradPValid_ = true;
    return;
  }
  // The extrapolated wall values depend on the gradient they feed; two passes contract the lag by
  // a factor of four (each pass halves it) and the outer iterations converge it. Boundary values
  // that do not depend on the gradient need one pass.
  // Only the cells next to the boundary see the boundary values, so the second pass updates
  // those alone.
  updateBoundaryPressure();
  pressureGradient({});
  if (opt_.wallPressure == WallPressure::Extrapolated) {
    updateBoundaryPressure();
    pressureGradient(boundaryCells_);
  }
  exchangeGhosts(gradP_);
  gradPValid_ = true;
}

void FluidSolver::pressureGradientFused() {
  // The boundary pressures and the gradient (with extrapolated wall pressures both twice) in one
  // pass over the cells: see PressureGradientKernel.
  PressureGradientKernel k;
  k.nIn = nIn_;
  k.extrapolate = opt_.wallPressure == WallPressure::Extrapolated;
  k.off = mesh_.cellFaceOffsets();
  k.other = gradStencil_.other;
  k.kind = bc_.kind();
  k.self = gradStencil_.self;
  k.coef = gradStencil_.coef;
  k.fc = geo_.faceCentroid;
  k.cc = geo_.cellCentroid;
  k.p = p_;
  k.bp = bc_.pressure();
  k.pb = pb_;
  k.gp = gradP_;
  Kokkos::parallel_for("mfsi::fluid::pressure::gradient", RangePolicy(exec_, 0, nCells_), k);
}

void FluidSolver::pressureGradient(const ConstIndexView& cells) {
  if (opt_.gradient == GradientScheme::GaussLinear)
    cellGradient(exec_, mesh_, gradStencil_, p_, pb_, gradP_, cells);
  else
    cellGradient(exec_, opt_.gradient, mesh_, geo_, fd_, p_, pb_, gradP_, cells);
}

void FluidSolver::computeVelocityGradient() const {
  // const: velocityGradient() fills the (mutable through its View handle) gradU_ on request.
  if (opt_.gradient == GradientScheme::GaussLinear)
    cellGradient(exec_, mesh_, gradStencil_, U_, Ub_, gradU_);
  else
    cellGradient(exec_, opt_.gradient, mesh_, geo_, fd_, U_, Ub_, gradU_);
  exchangeGhosts(gradU_);
}

ConstTensor3View FluidSolver::velocityGradient() const {
  if (!gradUCurrent_) {
    computeVelocityGradient();
    gradUCurrent_ = true;
  }
  return gradU_;
}

void FluidSolver::setUpRegions(const RankDomain& domain) {
  const MeshRegions regions = findMeshRegions(mesh_, {}, domain);
  const std::size_t nRegions = static_cast<std::size_t>(regions.count), nFluids = opt_.regions.size();
  // reached[i * nRegions + r] > 0: a face of entry i's patch lies in region r (on some rank: the
  // regions are the whole mesh's, numbered alike on every rank).
  std::vector<double> reached(nFluids * nRegions, 0.0);
  auto own = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.faceOwner());
  for (std::size_t i = 0; i < nFluids; ++i)
    for (const Patch& p : mesh_.patches())
      if (p.name == opt_.regions[i].patch)
        for (lid_t f = p.start; f < p.start + p.size; ++f)
          reached[i * nRegions + static_cast<std::size_t>(regions.cellRegion[static_cast<std::size_t>(own(f))])] = 1;
  comm_.globalSum(reached.data(), static_cast<int>(reached.size()));
  // Each region's fluid: the entry whose patch has a face in it.
  std::vector<int> fluidOf(nRegions, -1);
  for (std::size_t i = 0; i < nFluids; ++i)
    for (std::size_t r = 0; r < nRegions; ++r) {
      if (reached[i * nRegions + r] == 0) continue;
      MFSI_CHECK(fluidOf[r] < 0, "fluid: patches '" << opt_.regions[static_cast<std::size_t>(fluidOf[r])].patch
                                                    << "' and '" << opt_.regions[i].patch
                                                    << "' (fluid.regions) lie in one region");
      fluidOf[r] = static_cast<int>(i);
    }
  std::vector<real> rho(static_cast<std::size_t>(nCells_)), mu(rho.size());
  std::vector<lid_t> index(rho.size());
  for (std::size_t c = 0; c < rho.size(); ++c) {
    const int f = fluidOf[static_cast<std::size_t>(regions.cellRegion[c])];
    rho[c] = f < 0 ? opt_.density : opt_.regions[static_cast<std::size_t>(f)].density;
    mu[c] = f < 0 ? opt_.viscosity : opt_.regions[static_cast<std::size_t>(f)].viscosity;
    index[c] = f;
  }
  cellFluid_.rho = toDevice(rho, "mfsi::fluid::cellDensity");
  cellFluid_.mu = toDevice(mu, "mfsi::fluid::cellViscosity");
  cellFluid_.index = toDevice(index, "mfsi::fluid::cellFluid");
}

// ------------------------------------------------------------------------------------------------
// Momentum
// ------------------------------------------------------------------------------------------------

FluidSolver::MomentumAssembly FluidSolver::assembleMomentum(bool withB, bool withInv) {
  ScopedRegion region("mfsi::fluid::momentum::assemble");
  const real rho = opt_.density, mu = opt_.viscosity;
  const ConvectionScheme scheme = opt_.convection;
  const bool implicitLinear = scheme == ConvectionScheme::Linear;
  const bool limited = scheme == ConvectionScheme::LimitedLinear || scheme == ConvectionScheme::VanLeer;
  if (opt_.fusedMomentumAssembly && !limited && !nonOrthogonal_ && opt_.reduction == ReductionMode::Gather) {
    assembleMomentumFused(withB, withInv);
    return {withB, withInv};
  }
  // The per-face arrays of this path (~11 doubles per face) are allocated on first use: the
  // fused assembly, the usual one on orthogonal meshes, never reads them.
  if (fcU_.ownerDiag.extent(0) == 0) {
    fcU_ = allocateFaceCoefficients(mesh_, "mfsi::fluid::momentum::face");
    fluxU_ = Real3View("mfsi::fluid::momentum::faceFlux", nFaces_);
  }
  const lid_t nIn = nIn_;
  const bool nonOrth = nonOrthogonal_;
  const real lim = nonOrthogonalLimitFactor(opt_.nonOrthogonalLimit);
  ConstIndexView own = mesh_.faceOwner(), nei = mesh_.faceNeighbour();
  ConstIndexView kind = bc_.kind();
  ConstRealView phi = phi_, mp = meshPhi_, w = fd_.weight, dc = fd_.deltaCoeff;
  ConstReal3View kv = fd_.nonOrth, cc = geo_.cellCentroid, U = U_, Ub = Ub_;
  ConstTensor3View G = gradU_;
  auto od = fcU_.ownerDiag, nd = fcU_.neighbourDiag, up = fcU_.upper, lo = fcU_.lower;
  auto flux = fluxU_;
  // Another fluid's cells (FluidOptions::regions): no face joins two fluids, so the owner's serves.
  const bool perCell = cellFluid_.perCell();
  ConstRealView rhoC = cellFluid_.rho, muC = cellFluid_.mu;
  Kokkos::parallel_for(
      "mfsi::fluid::momentum::faceCoefficients", RangePolicy(exec_, 0, nFaces_), KOKKOS_LAMBDA(lid_t f) {
        const lid_t o = own(f);
        const real rhoF = perCell ? rhoC(o) : rho, muF = perCell ? muC(o) : mu;
        const real F = rhoF * (phi(f) - mp(f));  // mass flux relative to the moving face
        if (f < nIn) {
          const lid_t n = nei(f);
          const real wf = w(f), D = muF * dc(f);
          if (implicitLinear) {
            od(f) = F * wf + D;
            up(f) = F * (1.0 - wf) - D;
            nd(f) = -F * (1.0 - wf) + D;
            lo(f) = -F * wf - D;
          } else {
            const real Fp = F > 0 ? F : 0.0, Fm = F < 0 ? F : 0.0;
            od(f) = Fp + D;
            up(f) = Fm - D;
            nd(f) = -Fm + D;
            lo(f) = -Fp - D;
          }
          const lid_t C = F >= 0 ? o : n, Dn = F >= 0 ? n : o;
          for (int j = 0; j < 3; ++j) {
            // Explicit non-orthogonal part of the diffusive flux.
            real fl = 0;
            if (nonOrth) {
              real corr = 0;
              for (int i = 0; i < 3; ++i) corr += kv(f, i) * (wf * G(o, i, j) + (1.0 - wf) * G(n, i, j));
              fl = -muF * limitedCorrection(corr, dc(f) * (U(n, j) - U(o, j)), lim);
            }
            if (limited) {
              // Deferred correction: implicit upwind plus F (phi_TVD - phi_upwind) lagged.
              const real phiC = U(C, j), phiD = U(Dn, j);
              const real lin = wf * U(o, j) + (1.0 - wf) * U(n, j);
              const real diff = phiD - phiC;
              real psi = 1.0;
              if (kmath::fabs(diff) > 1e-300) {
                real dg = 0;
                for (int i = 0; i < 3; ++i) dg += (cc(Dn, i) - cc(C, i)) * G(C, i, j);
                psi = limiter(scheme, 2.0 * dg / diff - 1.0);
              }
              fl += F * psi * (lin - phiC);
            }
            flux(f, j) = fl;
          }
        } else {
          const lid_t b = f - nIn;
          up(f) = lo(f) = nd(f) = 0.0;
          const real D = muF * dc(f);
          switch (kind(b)) {
            case kFaceVelocity:
            case kFaceWall:
              od(f) = D;
              for (int j = 0; j < 3; ++j) flux(f, j) = (F - D) * Ub(b, j);
              break;
            case kFaceSlip:
              od(f) = D;
              for (int j = 0; j < 3; ++j) flux(f, j) = -D * Ub(b, j);
              break;
            case kFaceEmpty:
              od(f) = 0.0;
              for (int j = 0; j < 3; ++j) flux(f, j) = 0.0;
              break;
            default: {  // pressure outlet: zero-gradient, outflow implicit, backflow lagged
              od(f) = F > 0 ? F : 0.0;
              const real Fm = F < 0 ? F : 0.0;
              for (int j = 0; j < 3; ++j) flux(f, j) = Fm * Ub(b, j);
              break;
            }
          }
        }
      });

  // Time term and body force per cell.
  const bool steady = opt_.timeScheme == TimeScheme::Steady;
  const real rdt = 1.0 / dt_, c1 = c1_, c0 = c0_, c00 = c00_;
  const real gx = opt_.bodyForce[0], gy = opt_.bodyForce[1], gz = opt_.bodyForce[2];
  ConstRealView V = geo_.cellVolume, V0 = V0_, V00 = V00_;
  ConstReal3View U0 = U0_, U00 = U00_;
  auto cd = cellDiag_;
  auto rhs = rhsU_;
  Kokkos::parallel_for(
      "mfsi::fluid::momentum::cellTerms", RangePolicy(exec_, 0, nRows_), KOKKOS_LAMBDA(lid_t c) {
        const real rhoP = perCell ? rhoC(c) : rho;
        cd(c) = steady ? 0.0 : rhoP * c1 * V(c) * rdt;
        const real g[3] = {gx, gy, gz};
        for (int j = 0; j < 3; ++j) {
          real s = rhoP * V(c) * g[j];
          if (!steady) s += rhoP * (c0 * V0(c) * U0(c, j) - c00 * V00(c) * U00(c, j)) * rdt;
          rhs(c, j) = s;
        }
      });
  divergence<3>(exec_, mesh_, fluxU_, rhsU_, opt_.reduction, /*accumulate=*/true, /*sign=*/-1.0);
  assembleMatrix(exec_, mesh_, sparsity_, fcU_, cellDiag_, Au_, opt_.reduction);

  // Implicit under-relaxation: a_P -> a_P / alpha, source += (a_P / alpha - a_P) u_prev.
  const real alpha = opt_.pimple.relaxVelocity;
  ConstIndexView di = Au_.diagIdx;
  auto vals = Au_.values;
  const bool dominant = relaxesDominant();
  ConstIndexView rp = Au_.rowPtr;
  const RealView frac = relaxFraction_;
  Kokkos::parallel_for(
      "mfsi::fluid::momentum::relax", RangePolicy(exec_, 0, nRows_), KOKKOS_LAMBDA(lid_t c) {
        const lid_t dk = di(c);
        const real a = vals(dk);
        real sumOff = 0;
        if (dominant)
          for (lid_t k = rp(c); k < rp(c + 1); ++k) sumOff += k == dk ? 0.0 : kmath::fabs(vals(k));
        const real ar = relaxedDiagonal(a, sumOff, alpha, dominant);
        vals(dk) = ar;
        if (frac.extent(0) > 0) frac(c) = ar != 0.0 ? 1.0 - a / ar : 0.0;
        for (int j = 0; j < 3; ++j) rhs(c, j) += (ar - a) * U(c, j);
      });
  if (frac.extent(0) > 0) exchangeGhosts(frac);  // interpolated to the faces by PhiHbyAFace
  return {};
}

void FluidSolver::storeRelaxationFlux() {
  // The iterate the relaxation pulls towards (u_prev in the source (a_P / alpha - a_P) u_prev): its
  // face fluxes minus its interpolated velocity, read by the Rhie-Chow interpolation of HbyA
  // (PhiHbyAFace) with the weight 1 - a_P / (relaxed a_P), as the time term's old fluxes are. At a
  // converged iterate the relaxation then drops out of the fluxes as it does out of the cell
  // velocities: the steady cylinder's c_D and fields at relaxVelocity 0.7 and 0.9 agree to 1e-10,
  // a transient cavity's steps with U 0.7 / p 0.5 and unrelaxed to 2e-9 (6e-2 without it).
  // On a fixed-pressure boundary face (whose flux is H . S of the owner) the owner's velocity
  // stands for the interpolated one.
  ConstIndexView own = mesh_.faceOwner(), nei = mesh_.faceNeighbour(), kind = bc_.kind();
  ConstRealView w = fd_.weight, phi = phi_;
  ConstReal3View U = U_, sf = geo_.faceArea;
  auto d = relaxFlux_;
  const lid_t nIn = nIn_;
  Kokkos::parallel_for(
      "mfsi::fluid::momentum::relaxFlux", RangePolicy(exec_, 0, nFaces_), KOKKOS_LAMBDA(lid_t f) {
        const lid_t o = own(f);
        if (f < nIn) {
          d(f) = ddtCorrectionFlux(f, o, nei(f), w, phi(f), U, sf);
        } else if (kind(f - nIn) == kFacePressure) {
          real s = 0;
          for (int k = 0; k < 3; ++k) s += U(o, k) * sf(f, k);
          d(f) = phi(f) - s;
        } else {
          d(f) = 0.0;
        }
      });
}

bool FluidSolver::relaxesDominant() const {
  return opt_.pimple.relaxVelocity < 1.0;
}

void FluidSolver::assembleMomentumFused(bool withB, bool withInv) {
  // One thread per cell assembles its row, its source and the relaxation in one pass over its
  // faces: no per-face coefficient arrays, no separate gather, divergence, cell and relaxation
  // kernels (~2.5x less memory traffic). Only valid where internal faces carry no explicit flux
  // (no non-orthogonal correction, no deferred-correction convection). Every sum runs in the order
  // of the face-coefficient path (cell term first, then the cell's faces in cellFaces() order), so
  // both give the same bits.
  MomentumRowKernel k;
  k.rhoUniform = opt_.density;
  k.muUniform = opt_.viscosity;
  k.perCell = cellFluid_.perCell();
  k.rhoC = cellFluid_.rho;
  k.muC = cellFluid_.mu;
  k.implicitLinear = opt_.convection == ConvectionScheme::Linear;
  k.steady = opt_.timeScheme == TimeScheme::Steady;
  // Skipped reads of exact zeros: the mesh flux of a mesh that has not moved for two steps, and
  // the second old time level when its weight is 0 (Euler, BDF2's first step).
  k.moving = !k.steady && !meshStatic_;
  k.old2 = !k.steady && c00_ != 0.0;
  k.rdt = 1.0 / dt_;
  k.c1 = c1_;
  k.c0 = c0_;
  k.c00 = c00_;
  k.g[0] = opt_.bodyForce[0];
  k.g[1] = opt_.bodyForce[1];
  k.g[2] = opt_.bodyForce[2];
  k.alpha = opt_.pimple.relaxVelocity;
  k.dominant = relaxesDominant();
  k.frac = relaxFraction_;
  k.nIn = nIn_;
  k.off = mesh_.cellFaceOffsets();
  k.cf = mesh_.cellFaces();
  k.own = mesh_.faceOwner();
  k.cfp = sparsity_.cellFacePos;
  k.rowPtr = Au_.rowPtr;
  k.di = Au_.diagIdx;
  k.kind = bc_.kind();
  k.phi = phi_;
  k.mp = meshPhi_;
  k.w = fd_.weight;
  k.dc = fd_.deltaCoeff;
  k.V = geo_.cellVolume;
  k.V0 = V0_;
  k.V00 = V00_;
  k.U = U_;
  k.U0 = U0_;
  k.U00 = U00_;
  k.Ub = Ub_;
  k.vals = Au_.values;
  k.rhs = rhsU_;
  k.withB = withB;
  k.gp = gradP_;
  k.b3 = b3_;
  // The relaxed diagonal is in a register here: its inverse costs a store, not invertDiagonal's
  // pass over the matrix (64^3 cavity, 1 thread: ~1 ms per step).
  if (withInv) k.inv = linear_.momentumInverseDiagonal(nCells_);
  lid_t bad = nRows_;
  Kokkos::parallel_reduce("mfsi::fluid::momentum::assembleFused", RangePolicy(exec_, 0, nRows_), k,
                          Kokkos::Min<lid_t>(bad));
  if (relaxFraction_.extent(0) > 0) exchangeGhosts(relaxFraction_);
  MFSI_CHECK(bad >= nRows_, "linear solver: diagonal entry of row " << bad << " is missing, zero or not finite");
}

void FluidSolver::computeHbyA(bool withRAU) {
  // H = b - sum_N a_PN u_N (all but the pressure gradient); u = HbyA - rAU grad p, rAU = V / a_P.
  // a_P is read from the row being traversed (both assembly paths store the relaxed diagonal
  // there). rAU depends on a_P alone: the same for every corrector of an outer iteration, so only
  // the first one writes it. SIMPLEC (consistent) also writes rAtU = V / (a_P - H1), H1 the
  // negated sum of the off-diagonal coefficients, into rAU_ and V / a_P into rAUSimple_. Its
  // denominator is a_P (1 - alpha) plus the wall terms plus the continuity error of the face
  // fluxes; it is kept above half of a_P (1 - alpha), its value for a conservative interior row,
  // so that a transient continuity error cannot make it small or negative.
  ConstIndexView rp = Au_.rowPtr, ci = Au_.colIdx, di = Au_.diagIdx;
  ConstRealView vals = Au_.values, V = geo_.cellVolume;
  ConstReal3View U = U_, rhs = rhsU_;
  auto H = HbyA_;
  auto rAU = rAU_;
  const bool simplec = opt_.pimple.consistent && withRAU;
  auto rAUs = rAUSimple_;
  const real floorFactor = 0.5 * (1.0 - opt_.pimple.relaxVelocity);
  Kokkos::parallel_for(
      "mfsi::fluid::momentum::HbyA", RangePolicy(exec_, 0, nRows_), KOKKOS_LAMBDA(lid_t c) {
        real h[3] = {rhs(c, 0), rhs(c, 1), rhs(c, 2)};
        real offSum = 0;
        const lid_t dk = di(c);
        for (lid_t k = rp(c); k < rp(c + 1); ++k) {
          if (k == dk) continue;
          const lid_t n = ci(k);
          offSum += vals(k);
          for (int j = 0; j < 3; ++j) h[j] -= vals(k) * U(n, j);
        }
        const real diag = vals(dk);
        for (int j = 0; j < 3; ++j) H(c, j) = h[j] / diag;
        if (simplec) {
          const real d = diag + offSum, lo = floorFactor * diag;
          rAUs(c) = V(c) / diag;
          rAU(c) = V(c) / (d > lo ? d : lo);
        } else if (withRAU) {
          rAU(c) = V(c) / diag;
        }
      });
  // The faces interpolate both: the ghosts take their owners' rows.
  exchangeGhosts(HbyA_);
  if (withRAU) exchangeGhosts(rAU_);
  if (simplec) exchangeGhosts(rAUSimple_);
}

void FluidSolver::simplecCorrection() {
  // SIMPLEC's pressure equation uses rAtU (in rAU_), so the pressure gradient's share that
  // rAtU - rAU carries moves into HbyA and phiHbyA, with the old pressure: phiHbyA gets
  // (rAtU - rAU)_f times the face-normal pressure gradient (the matrix's own discretisation:
  // deltaCoeff times the difference, plus the non-orthogonal part from the cell gradients);
  // HbyA gets (rAtU - rAU) times the cell gradient. At convergence the fluxes and velocities are
  // then exactly SIMPLE's (with rAU), so the solution does not depend on the switch.
  updatePressureGradient();
  const lid_t nIn = nIn_;
  ConstIndexView own = mesh_.faceOwner(), nei = mesh_.faceNeighbour(), kind = bc_.kind();
  ConstRealView w = fd_.weight, dc = fd_.deltaCoeff, rAtU = rAU_, rAUs = rAUSimple_, p = p_, pb = pb_;
  ConstReal3View kv = fd_.nonOrth, gp = gradP_;
  const bool nonOrth = nonOrthogonal_;
  const real lim = nonOrthogonalLimitFactor(opt_.nonOrthogonalLimit);
  auto phiH = phiHbyA_;
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::simplecFlux", RangePolicy(exec_, 0, nFaces_), KOKKOS_LAMBDA(lid_t f) {
        const lid_t o = own(f);
        if (f < nIn) {
          const lid_t n = nei(f);
          const real wf = w(f);
          const real dr = wf * (rAtU(o) - rAUs(o)) + (1.0 - wf) * (rAtU(n) - rAUs(n));
          const real orth = dc(f) * (p(n) - p(o));
          const real sn = orth + (nonOrth ? limitedCorrection(nonOrthogonalPart(f, o, n, wf, kv, gp), orth, lim) : 0.0);
          phiH(f) += dr * sn;
        } else if (kind(f - nIn) == kFacePressure) {
          phiH(f) += (rAtU(o) - rAUs(o)) * dc(f) * (pb(f - nIn) - p(o));
        }
      });
  auto H = HbyA_;
  Kokkos::parallel_for(
      "mfsi::fluid::momentum::simplecHbyA", RangePolicy(exec_, 0, nCells_), KOKKOS_LAMBDA(lid_t c) {
        const real dr = rAtU(c) - rAUs(c);
        for (int j = 0; j < 3; ++j) H(c, j) += dr * gp(c, j);
      });
}

// ------------------------------------------------------------------------------------------------
// Pressure
// ------------------------------------------------------------------------------------------------

/// phiHbyA of one face: the face flux of HbyA, linearly interpolated, plus the Rhie-Chow
/// correction of the time term on internal faces; H.S on fixed-pressure boundary faces; the
/// prescribed flux on the other boundary faces. One formula for the phiHbyA kernel and the fused
/// source-flux kernel.
struct PhiHbyAFace {
  lid_t nIn = 0;
  ConstIndexView own, nei, kind;
  ConstRealView w, rAU, phi, d0, d00;
  ConstReal3View sf, H;
  real rho = 0, rdt = 0, c0 = 0, c00 = 0;
  bool perCell = false;  ///< rhoC per cell instead of rho (FluidOptions::regions)
  ConstRealView rhoC;
  bool ddt = false, old2 = false;
  /// Rhie-Chow consistent with the under-relaxation: (1 - a_P / relaxed a_P) interpolated, times
  /// the previous iterate's face flux minus its interpolated velocity (relaxFlux).
  bool relax = false;
  ConstRealView frac, dRelax;
  KOKKOS_INLINE_FUNCTION real operator()(lid_t f) const {
    const lid_t o = own(f);
    if (f < nIn) {
      const lid_t n = nei(f);
      const real wf = w(f);
      real s = 0;
      for (int k = 0; k < 3; ++k) s += (wf * H(o, k) + (1.0 - wf) * H(n, k)) * sf(f, k);
      if (relax) s += (wf * frac(o) + (1.0 - wf) * frac(n)) * dRelax(f);
      if (ddt) {
        // Rhie-Chow consistent with the time term: the old-time part of H enters through the old
        // face fluxes rather than the interpolated old cell velocities.
        const real rAUf = wf * rAU(o) + (1.0 - wf) * rAU(n);
        s += rAUf * (perCell ? rhoC(o) : rho) * (old2 ? c0 * d0(f) - c00 * d00(f) : c0 * d0(f)) * rdt;
      }
      return s;
    }
    if (kind(f - nIn) != kFacePressure) return phi(f);  // prescribed flux
    real hs = 0;
    for (int k = 0; k < 3; ++k) hs += H(o, k) * sf(f, k);
    if (relax) hs += frac(o) * dRelax(f);
    return hs;
  }
};

PhiHbyAFace FluidSolver::phiHbyAFace() const {
  PhiHbyAFace F;
  F.nIn = nIn_;
  F.own = mesh_.faceOwner();
  F.nei = mesh_.faceNeighbour();
  F.kind = bc_.kind();
  F.w = fd_.weight;
  F.rAU = rAU_;
  F.phi = phi_;
  F.d0 = dphi0_;
  F.d00 = dphi00_;
  F.sf = geo_.faceArea;
  F.H = HbyA_;
  F.rho = opt_.density;
  F.perCell = cellFluid_.perCell();
  F.rhoC = cellFluid_.rho;
  F.rdt = 1.0 / dt_;
  F.c0 = c0_;
  F.c00 = c00_;
  F.ddt = opt_.pimple.ddtCorrection && opt_.timeScheme != TimeScheme::Steady;
  // Euler (and BDF2's first step) has c00 = 0: the second old level adds an exact zero.
  F.old2 = c00_ != 0.0;
  F.relax = relaxFraction_.extent(0) > 0;
  F.frac = relaxFraction_;
  F.dRelax = relaxFlux_;
  return F;
}

void FluidSolver::computePhiHbyA() {
  // Allocated on first use: the orthogonal-mesh path writes the source flux directly.
  if (phiHbyA_.extent(0) == 0) phiHbyA_ = RealView("mfsi::fluid::phiHbyA", nFaces_);
  const PhiHbyAFace face = phiHbyAFace();
  auto phiH = phiHbyA_;
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::phiHbyA", RangePolicy(exec_, 0, nFaces_), KOKKOS_LAMBDA(lid_t f) { phiH(f) = face(f); });
}

void FluidSolver::pinPressureLevel() {
  // No boundary sets the level: doubling one diagonal entry (and adding the matching source in
  // finishPressureSource) pins p at the reference cell without changing the other equations.
  // Closed regions beside open ones: one reference row each, at level 0.
  ConstIndexView di = Ap_.diagIdx;
  auto vals = Ap_.values;
  RealView d = pressureLattice_ != nullptr ? pressureLattice_->diagonal() : RealView();
  ConstIndexView rows = regionPinRows_;
  const lid_t ref = pinsPressureLevel() ? referenceRow_ : -1;  // -1: another rank's cell, or none
  const lid_t n = static_cast<lid_t>(rows.extent(0)) + 1;
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::reference", RangePolicy(exec_, 0, n), KOKKOS_LAMBDA(lid_t i) {
        const lid_t r = i == 0 ? ref : rows(i - 1);
        if (r < 0) return;
        if (d.extent(0) > 0)
          d(r) *= 2.0;
        else
          vals(di(r)) *= 2.0;
      });
}

/// One row of the fused pressure matrix: the diagonal and the source's divergence of the face
/// fluxes of a cell, in one walk over its faces, calling coupling(e, n, -coef) for each internal
/// face (cell-face entry e, neighbour n). Shared by the CSR and lattice assemblies.
struct PressureRow {
  lid_t nIn = 0;
  bool comp = false, stored = false;
  real k = 0, c1 = 0;
  ConstIndexView off, cf, own, nei, kind;
  ConstRealView w, dc, rAU, V, flux, cp;

  template <class Coupling>
  KOKKOS_FORCEINLINE_FUNCTION void operator()(lid_t cell, real& diag, real& div, const Coupling& coupling) const {
    diag = comp ? k * c1 * V(cell) : 0.0;
    div = 0.0;
    for (lid_t e = off(cell); e < off(cell + 1); ++e) {
      const lid_t f = cf(e);
      const lid_t o = own(f);
      div += (o == cell ? 1.0 : -1.0) * flux(f);
      if (f < nIn) {
        const real coef = stored ? cp(f) : pressureFaceCoefficient(f, o, nei(f), w, rAU, dc);
        diag += coef;
        coupling(e, o == cell ? nei(f) : o, -coef);
      } else if (stored) {
        diag += cp(f);
      } else {
        diag += kind(f - nIn) == kFacePressure ? rAU(cell) * dc(f) : 0.0;
      }
    }
  }
};

PressureRow FluidSolver::pressureRow(bool stored) const {
  PressureRow row;
  row.nIn = nIn_;
  row.comp = compressible();
  row.stored = stored;
  const real c = opt_.artificialCompressibility.soundSpeed;
  row.k = row.comp ? 1.0 / (opt_.density * c * c * dt_) : 0.0;
  row.c1 = c1_;
  row.off = mesh_.cellFaceOffsets();
  row.cf = mesh_.cellFaces();
  row.own = mesh_.faceOwner();
  row.nei = mesh_.faceNeighbour();
  row.kind = bc_.kind();
  row.w = fd_.weight;
  row.dc = fd_.deltaCoeff;
  row.rAU = rAU_;
  row.V = geo_.cellVolume;
  row.flux = fluxP_;
  row.cp = coefP_;
  return row;
}

void FluidSolver::assemblePressureMatrixFused(bool stored) {
  // One thread per row, as assembleMatrix's gather, but computing each face coefficient where it
  // is needed instead of storing four per-face arrays and reading them back: the same values
  // added in the same order (cell term, then the cell's faces in cellFaces() order). The same
  // pass forms the source's divergence of the face fluxes (the divergence kernel's sum), sharing
  // the walk over the cell's faces. With `stored` the face coefficients are read from coefP_
  // (written by the source-flux pass, which has the interpolated rAU at hand) instead of formed
  // from four face and two cell values: the same numbers.
  const PressureRow row = pressureRow(stored);
  ConstIndexView cfp = sparsity_.cellFacePos, rowPtr = Ap_.rowPtr, di = Ap_.diagIdx;
  auto vals = Ap_.values;
  auto rhs = rhsP_;
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::assembleFused", RangePolicy(exec_, 0, nRows_), KOKKOS_LAMBDA(lid_t cell) {
        for (lid_t e = rowPtr(cell); e < rowPtr(cell + 1); ++e) vals(e) = 0.0;
        real diag, div;
        row(cell, diag, div, [&](lid_t e, lid_t, real a) { vals(cfp(e)) += a; });
        vals(di(cell)) += diag;
        rhs(cell) = -1.0 * div;
      });
}

void FluidSolver::assemblePressureLatticeFused(SymmetricLatticeMatrix& lattice, bool stored) {
  // assemblePressureMatrixFused's row, written to the lattice: the diagonal (the same sum in the
  // same order) and the couplings to the +x, +y, +z neighbours (0 where the lattice ends). The
  // lower couplings are the neighbours' upper ones: the one coefficient of a face serves both
  // rows (symmetric by construction).
  const PressureRow row = pressureRow(stored);
  const lid_t sy = lattice.nx(), sz = lattice.nx() * lattice.ny();
  const bool hasZ = lattice.nz() > 1;
  const RealView d = lattice.diagonal(), ux = lattice.upperX(), uy = lattice.upperY(), uz = lattice.upperZ();
  auto rhs = rhsP_;
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::assembleLattice", RangePolicy(exec_, 0, nRows_), KOKKOS_LAMBDA(lid_t cell) {
        real diag, div, cx = 0.0, cy = 0.0, cz = 0.0;
        row(cell, diag, div, [&](lid_t, lid_t n, real a) {
          if (n == cell + 1)
            cx = a;
          else if (n == cell + sy)
            cy = a;
          else if (n == cell + sz)
            cz = a;
        });
        d(cell) = diag;
        ux(cell) = cx;
        uy(cell) = cy;
        if (hasZ) uz(cell) = cz;
        rhs(cell) = -1.0 * div;
      });
}

void FluidSolver::assemblePressureMatrixFaces() {
  if (fcP_.ownerDiag.extent(0) == 0) fcP_ = allocateFaceCoefficients(mesh_, "mfsi::fluid::pressure::face");
  const lid_t nIn = nIn_;
  ConstIndexView own = mesh_.faceOwner(), nei = mesh_.faceNeighbour();
  ConstIndexView kind = bc_.kind();
  ConstRealView w = fd_.weight, dc = fd_.deltaCoeff, rAU = rAU_;
  auto od = fcP_.ownerDiag, nd = fcP_.neighbourDiag, up = fcP_.upper, lo = fcP_.lower;
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::faceCoefficients", RangePolicy(exec_, 0, nFaces_), KOKKOS_LAMBDA(lid_t f) {
        const lid_t o = own(f);
        if (f < nIn) {
          const real coef = pressureFaceCoefficient(f, o, nei(f), w, rAU, dc);
          od(f) = nd(f) = coef;
          up(f) = lo(f) = -coef;
        } else {
          up(f) = lo(f) = nd(f) = 0.0;
          od(f) = kind(f - nIn) == kFacePressure ? rAU(o) * dc(f) : 0.0;
        }
      });
  if (compressible()) {
    // Artificial compressibility: the linearised mass balance of a fluid with density
    // rho + p / c^2 in a moving cell, d(V p)/dt / (rho c^2) + sum_f phi_f = 0 (the rho part cancels
    // against the mesh fluxes by space conservation). The time derivative uses the momentum
    // scheme's volume-weighted weights, so a closed box conserves sum(V p) / (rho c^2) + V exactly.
    // The solve is for p itself (not a correction), so the old levels go to the right-hand side.
    const real c = opt_.artificialCompressibility.soundSpeed;
    const real k = 1.0 / (opt_.density * c * c * dt_), c1 = c1_;
    ConstRealView V = geo_.cellVolume;
    auto cd = cellDiag_;
    Kokkos::parallel_for(
        "mfsi::fluid::pressure::compressibilityDiag", RangePolicy(exec_, 0, nRows_),
        KOKKOS_LAMBDA(lid_t c) { cd(c) = k * c1 * V(c); });
  } else {
    Kokkos::deep_copy(exec_, cellDiag_, 0.0);
  }
  assembleMatrix(exec_, mesh_, sparsity_, fcP_, cellDiag_, Ap_, opt_.reduction);
}

bool FluidSolver::fusedPressureSource() const {
  // SIMPLEC adds its correction to phiHbyA between the flux and the source: the general path.
  return opt_.fusedMomentumAssembly && !nonOrthogonal_ && !opt_.pimple.consistent;
}

bool FluidSolver::fusedCellPasses() const {
  return opt_.fusedMomentumAssembly && opt_.reduction == ReductionMode::Gather;
}

void FluidSolver::pressureSourceFlux(bool coefficients) {
  // computePhiHbyA and the face loop of assemblePressure in one kernel, for orthogonal
  // meshes where the source flux of an internal face is phiHbyA itself (no non-orthogonal
  // correction): no phiHbyA array written and read back. Same formulas, same bits. With
  // `coefficients` it also stores each face's pressure-matrix coefficient for
  // assemblePressureMatrixFused (the formulas of that kernel), from the face and cell values the
  // flux has just read.
  if (coefficients && coefP_.extent(0) == 0)
    coefP_ =
        RealView(Kokkos::view_alloc(Kokkos::WithoutInitializing, "mfsi::fluid::pressure::faceCoefficient"), nFaces_);
  const PhiHbyAFace face = phiHbyAFace();
  const lid_t nIn = nIn_;
  ConstIndexView own = mesh_.faceOwner(), nei = mesh_.faceNeighbour(), kind = bc_.kind();
  ConstRealView w = fd_.weight, dc = fd_.deltaCoeff, rAU = rAU_, pb = pb_;
  auto flux = fluxP_;
  auto cp = coefP_;
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::phiHbyAFlux", RangePolicy(exec_, 0, nFaces_), KOKKOS_LAMBDA(lid_t f) {
        real s = face(f);
        const lid_t o = own(f);
        const bool fixedP = f >= nIn && kind(f - nIn) == kFacePressure;
        if (fixedP) s -= rAU(o) * dc(f) * pb(f - nIn);
        flux(f) = s;
        if (coefficients)
          cp(f) = f < nIn ? pressureFaceCoefficient(f, o, nei(f), w, rAU, dc) : (fixedP ? rAU(o) * dc(f) : 0.0);
      });
}

void FluidSolver::assemblePressure(bool matrix) {
  ScopedRegion region("mfsi::fluid::pressure::assemble");
  // Per-face fluxes, then the per-cell gather. (A per-cell pass computing each face's flux on both
  // sides and summing it at once was measured 1.7x slower: the face data is read twice.) The
  // matrix depends on rAU and the geometry only: the same for every pressure corrector of one
  // outer iteration, so it is assembled once per outer iteration (`matrix`), the source every
  // corrector. The fused matrix pass also forms the divergence.
  const bool fusedMatrix = matrix && fusedCellPasses();
  if (fusedPressureSource())
    pressureSourceFlux(/*coefficients=*/fusedMatrix);
  else
    pressureSourceFluxFaces();
  if (fusedMatrix) {
    // CG's lattice takes the values directly when the sparsity is a lattice (no CSR values, no
    // copy pass: 64^3 cavity ~3 ms per step at 1 thread); lines of one cell (nx or ny = 1) keep
    // CSR.
    // CG's lattice copy is a one-rank fast path (a rank's rows with ghost columns are no lattice).
    SymmetricLatticeMatrix* lattice = cellHalo_ ? nullptr : linear_.pressureLattice(Ap_);
    pressureLattice_ = lattice != nullptr && lattice->nx() > 1 && lattice->ny() > 1 ? lattice : nullptr;
    if (pressureLattice_ != nullptr)
      assemblePressureLatticeFused(*pressureLattice_, /*stored=*/fusedPressureSource());
    else
      assemblePressureMatrixFused(/*stored=*/fusedPressureSource());
  } else {
    if (matrix) pressureLattice_ = nullptr;
    if (matrix) assemblePressureMatrixFaces();
    divergence<1>(exec_, mesh_, fluxP_, rhsP_, opt_.reduction, /*accumulate=*/false, /*sign=*/-1.0);
  }
  if (matrix && pinsAnyLevel()) pinPressureLevel();
  if (matrix && pressureLattice_ != nullptr) linear_.pressureLatticeAssembled(Ap_);
  finishPressureSource();
}

void FluidSolver::pressureSourceFluxFaces() {
  // General path: phiHbyA (computePhiHbyA) plus the non-orthogonal correction and boundary terms.
  const lid_t nIn = nIn_;
  ConstIndexView own = mesh_.faceOwner(), nei = mesh_.faceNeighbour();
  ConstIndexView kind = bc_.kind();
  ConstRealView w = fd_.weight, dc = fd_.deltaCoeff, rAU = rAU_, phiH = phiHbyA_, pb = pb_;
  ConstReal3View kv = fd_.nonOrth, gp = gradP_;
  const bool nonOrth = nonOrthogonal_;
  const real lim = nonOrthogonalLimitFactor(opt_.nonOrthogonalLimit);
  ConstRealView p = p_;
  auto flux = fluxP_;
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::sourceFlux", RangePolicy(exec_, 0, nFaces_), KOKKOS_LAMBDA(lid_t f) {
        const lid_t o = own(f);
        if (f < nIn) {
          real fl = phiH(f);
          if (nonOrth) {
            const lid_t n = nei(f);
            const real wf = w(f);
            const real rAUf = wf * rAU(o) + (1.0 - wf) * rAU(n);
            fl -= rAUf * limitedCorrection(nonOrthogonalPart(f, o, n, wf, kv, gp), dc(f) * (p(n) - p(o)), lim);
          }
          flux(f) = fl;
        } else if (kind(f - nIn) == kFacePressure) {
          flux(f) = phiH(f) - rAU(o) * dc(f) * pb(f - nIn);
        } else {
          flux(f) = phiH(f);
        }
      });
}

void FluidSolver::finishPressureSource() {
  // Cell terms of the source after the divergence: compressibility, reference-level pinning.
  if (compressible()) {
    const real c = opt_.artificialCompressibility.soundSpeed;
    const real k = 1.0 / (opt_.density * c * c * dt_), c0 = c0_, c00 = c00_;
    ConstRealView V0 = V0_, V00 = V00_, p0 = p0_, p00 = p00_;
    auto rhs = rhsP_;
    Kokkos::parallel_for(
        "mfsi::fluid::pressure::compressibilitySource", RangePolicy(exec_, 0, nRows_),
        KOKKOS_LAMBDA(lid_t c) { rhs(c) += k * (c0 * V0(c) * p0(c) - c00 * V00(c) * p00(c)); });
  }
  if (pinsAnyLevel()) {
    // A reference row's diagonal was doubled from a: its source gets a times its level (a = half
    // of it). The whole domain's row first, then the closed regions'.
    const lid_t ref = pinsPressureLevel() ? referenceRow_ : -1;
    const real pRef = opt_.pressureReferenceValue;
    ConstIndexView di = Ap_.diagIdx, rows = regionPinRows_;
    ConstRealView vals = Ap_.values, levels = regionPinValues_;
    ConstRealView d = pressureLattice_ != nullptr ? pressureLattice_->diagonal() : RealView();
    auto rhs = rhsP_;
    Kokkos::parallel_for(
        "mfsi::fluid::pressure::referenceSource", RangePolicy(exec_, 0, static_cast<lid_t>(rows.extent(0)) + 1),
        KOKKOS_LAMBDA(lid_t i) {
          const lid_t r = i == 0 ? ref : rows(i - 1);
          if (r < 0) return;
          rhs(r) += 0.5 * (d.extent(0) > 0 ? d(r) : vals(di(r))) * (i == 0 ? pRef : levels(i - 1));
        });
  }
}

bool FluidSolver::pinsPressureLevel() const {
  // With artificial compressibility the matrix is regular and the level is physical: no pinning.
  return !bc_.fixesPressureLevel() && !compressible();
}

void FluidSolver::correctFluxAndVelocity(bool flux) {
  ScopedRegion region("mfsi::fluid::correct");
  // Face fluxes from the pressure just solved (before any relaxation), with the same
  // non-orthogonal correction that was in the matrix source: sum_f phi_f = 0 to solver tolerance.
  if (flux) Kokkos::parallel_for("mfsi::fluid::pressure::flux", RangePolicy(exec_, 0, nFaces_), pressureFaceFlux());
  gradPValid_ = false;  // p is the one just solved for
  const real ap = opt_.pimple.relaxPressure;
  if (ap < 1.0) {
    auto p = p_;
    ConstRealView pp = pPrev_;
    Kokkos::parallel_for(
        "mfsi::fluid::pressure::relax", RangePolicy(exec_, 0, nCells_),
        KOKKOS_LAMBDA(lid_t c) { p(c) = pp(c) + ap * (p(c) - pp(c)); });
  }
  updatePressureGradient();
  {
    ConstReal3View H = HbyA_, gp = gradP_;
    ConstRealView rAU = rAU_;
    auto U = U_;
    Kokkos::parallel_for(
        "mfsi::fluid::momentum::correct", RangePolicy(exec_, 0, nCells_), KOKKOS_LAMBDA(lid_t c) {
          for (int j = 0; j < 3; ++j) U(c, j) = H(c, j) - rAU(c) * gp(c, j);
        });
  }
  if (boundaryVelocityReadsU_) updateBoundaryVelocity();
}

int FluidSolver::addClosedRegion(const std::vector<char>& localCells, long long referenceCell) {
  MFSI_CHECK(static_cast<lid_t>(localCells.size()) == nCells_,
             "fluid: addClosedRegion got " << localCells.size() << " flags for " << nCells_ << " cells");
  const int region = closedRegions_++;
  if (cellClosedRegion_.extent(0) == 0) {
    cellClosedRegion_ = IndexView("mfsi::fluid::cellClosedRegion", nCells_);
    Kokkos::deep_copy(cellClosedRegion_, -1);
  }
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), cellClosedRegion_);
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.cellGlobalIds());
  std::vector<lid_t> rows(regionPinRows_.extent(0));
  Kokkos::deep_copy(Kokkos::View<lid_t*, HostSpace>(rows.data(), rows.size()), regionPinRows_);
  lid_t found = 0;
  for (lid_t c = 0; c < nCells_; ++c) {
    if (!localCells[c]) continue;
    h(c) = region;
    if (c < nRows_ && static_cast<long long>(gid(c)) == referenceCell) {
      rows.push_back(c);
      regionPinRegion_.push_back(region);
      found = 1;
    }
  }
  regionLevel_.push_back(0);
  MFSI_CHECK(comm_.globalSum(static_cast<double>(found)) == 1.0,
             "fluid: the reference cell " << referenceCell << " of a closed region is not one of its cells");
  Kokkos::deep_copy(cellClosedRegion_, h);
  regionPinRows_ = IndexView("mfsi::fluid::regionPinRows", rows.size());
  Kokkos::deep_copy(regionPinRows_, Kokkos::View<lid_t*, HostSpace>(rows.data(), rows.size()));
  shiftPressureLevel(region, 0);  // the pinned values
  return region;
}

real FluidSolver::pressureLevel(int region) const {
  return region < 0 ? opt_.pressureReferenceValue : regionLevel_.at(static_cast<std::size_t>(region));
}

void FluidSolver::shiftPressureLevel(int region, real delta) {
  MFSI_CHECK(region < closedRegions_, "fluid: no closed region " << region);
  if (region < 0)
    opt_.pressureReferenceValue += delta;
  else
    regionLevel_[static_cast<std::size_t>(region)] += delta;
  std::vector<real> values(regionPinRegion_.size());
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = regionLevel_[static_cast<std::size_t>(regionPinRegion_[i])];
  if (regionPinValues_.extent(0) != values.size())
    regionPinValues_ = RealView("mfsi::fluid::regionPinValues", values.size());
  Kokkos::deep_copy(regionPinValues_, Kokkos::View<real*, HostSpace>(values.data(), values.size()));
  if (delta == 0) return;
  ConstIndexView cr = cellClosedRegion_, own = mesh_.faceOwner();
  auto p = p_, pp = pPrev_, pb = pb_;
  const lid_t nIn = nIn_;
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::shiftLevel", RangePolicy(exec_, 0, nCells_), KOKKOS_LAMBDA(lid_t c) {
        if (region >= 0 && cr(c) != region) return;
        p(c) += delta;
        pp(c) += delta;
      });
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::shiftLevelBoundary", RangePolicy(exec_, 0, nB_), KOKKOS_LAMBDA(lid_t b) {
        if (region >= 0 && cr(own(b + nIn)) != region) return;
        pb(b) += delta;
      });
}

real FluidSolver::prescribedInflow(int region) const {
  ConstIndexView kind = bc_.kind();
  ConstIndexView cr = cellClosedRegion_;
  ConstReal3View bv = bc_.velocity();
  ConstReal3View sf = geo_.faceArea;
  ConstIndexView own = mesh_.faceOwner();
  const lid_t nIn = nIn_, nRows = nRows_;
  real q = 0;
  Kokkos::parallel_reduce(
      "mfsi::fluid::prescribedInflow", RangePolicy(exec_, 0, nB_),
      KOKKOS_LAMBDA(lid_t b, real & s) {
        const lid_t f = b + nIn;
        if (kind(b) != kFaceVelocity || own(f) >= nRows) return;  // a ghost's face is its owner's
        if (region >= 0 && cr(own(f)) != region) return;
        s -= bv(b, 0) * sf(f, 0) + bv(b, 1) * sf(f, 1) + bv(b, 2) * sf(f, 2);
      },
      q);
  return comm_.globalSum(q);
}

bool FluidSolver::compressible() const {
  return opt_.artificialCompressibility.soundSpeed > 0 && opt_.timeScheme != TimeScheme::Steady;
}

void FluidSolver::storeDdtCorrection() {
  ConstIndexView own = mesh_.faceOwner(), nei = mesh_.faceNeighbour();
  ConstRealView w = fd_.weight;
  ConstReal3View sf = geo_.faceArea, U = U_;
  auto phi = phi_;  // read where `flux` has just written it: not through a read-only (RandomRead) view
  auto d = dphi_;
  const lid_t nIn = nIn_;
  Kokkos::parallel_for(
      "mfsi::fluid::ddtCorr::store", RangePolicy(exec_, 0, nFaces_),
      KOKKOS_LAMBDA(lid_t f) { d(f) = f < nIn ? ddtCorrectionFlux(f, own(f), nei(f), w, phi(f), U, sf) : 0.0; });
  dphiLatest_ = true;
}

real FluidSolver::continuityMax(real& sum) {
  divergence<1>(exec_, mesh_, phi_, b_, opt_.reduction);
  ConstRealView div = b_, V = geo_.cellVolume;
  real mx = 0;
  sum = 0;
  Kokkos::parallel_reduce(
      "mfsi::fluid::continuity", RangePolicy(exec_, 0, nRows_),
      KOKKOS_LAMBDA(lid_t c, real & m, real & s) {
        const real a = kmath::fabs(div(c));
        const real r = a / V(c);
        m = r > m ? r : m;
        s += a;
      },
      Kokkos::Max<real>(mx), sum);
  sum = comm_.globalSum(sum);
  return comm_.globalMax(mx);
}

void FluidSolver::fluxAndDdtCorrection() {
  // The final corrector's pressure::flux kernel, moved after the velocity correction (it reads
  // neither U nor anything the correction writes; pressure relaxation, which would change p, is
  // excluded by the caller) and joined by storeDdtCorrection, which reads the same face data: one
  // face pass with the formulas of both kernels.
  const PressureFaceFlux flux = pressureFaceFlux();
  ConstIndexView own = mesh_.faceOwner(), nei = mesh_.faceNeighbour();
  ConstRealView w = fd_.weight;
  ConstReal3View sf = geo_.faceArea, U = U_;
  auto phi = phi_;
  auto d = dphi_;
  const lid_t nIn = nIn_;
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::fluxDdt", RangePolicy(exec_, 0, nFaces_), KOKKOS_LAMBDA(lid_t f) {
        const lid_t o = own(f);
        if (f < nIn) {
          const lid_t n = nei(f);
          const real ph = flux.internal(f, o, n);
          phi(f) = ph;
          d(f) = ddtCorrectionFlux(f, o, n, w, ph, U, sf);
        } else {
          flux.boundary(f, o);
          d(f) = 0.0;
        }
      });
}

PressureFaceFlux FluidSolver::pressureFaceFlux() const {
  PressureFaceFlux F;
  F.nIn = nIn_;
  F.own = mesh_.faceOwner();
  F.nei = mesh_.faceNeighbour();
  F.kind = bc_.kind();
  F.w = fd_.weight;
  F.dc = fd_.deltaCoeff;
  F.rAU = rAU_;
  F.fl = fluxP_;
  F.p = p_;
  F.phi = phi_;
  return F;
}

real FluidSolver::finishStep(real& sum, bool& finite, bool ddtStored) {
  // storeDdtCorrection, continuityMax and fieldsFinite in one pass over the cells: each cell sums
  // its face fluxes and stores the correction flux of the faces it owns (every face has one
  // owner, so each is written once, with the formula of storeDdtCorrection; not if
  // fluxAndDdtCorrection stored them). The reductions get the same per-cell values over the same
  // range as the separate kernels'.
  ConstIndexView off = mesh_.cellFaceOffsets(), cf = mesh_.cellFaces(), own = mesh_.faceOwner(),
                 nei = mesh_.faceNeighbour();
  ConstRealView w = fd_.weight, phi = phi_, V = geo_.cellVolume, p = p_;
  ConstReal3View sf = geo_.faceArea, U = U_;
  auto d = dphi_;
  const lid_t nIn = nIn_;
  real mx = 0, fin = 0;
  sum = 0;
  Kokkos::parallel_reduce(
      "mfsi::fluid::finishStep", RangePolicy(exec_, 0, nRows_),
      KOKKOS_LAMBDA(lid_t c, real & m, real & s, real & acc) {
        real div = 0;
        for (lid_t e = off(c); e < off(c + 1); ++e) {
          const lid_t f = cf(e);
          const bool isOwner = own(f) == c;
          div += (isOwner ? 1.0 : -1.0) * phi(f);
          if (isOwner && !ddtStored) d(f) = f < nIn ? ddtCorrectionFlux(f, c, nei(f), w, phi(f), U, sf) : 0.0;
        }
        const real a = kmath::fabs(1.0 * div);
        const real r = a / V(c);
        m = r > m ? r : m;
        s += a;
        acc += fieldMagnitude(c, U, p);
      },
      Kokkos::Max<real>(mx), sum, fin);
  dphiLatest_ = true;
  finite = std::isfinite(comm_.globalSum(fin));
  sum = comm_.globalSum(sum);
  return comm_.globalMax(mx);
}

bool FluidSolver::fieldsFinite() {
  ConstReal3View U = U_;
  ConstRealView p = p_;
  real s = 0;
  Kokkos::parallel_reduce(
      "mfsi::fluid::finiteCheck", RangePolicy(exec_, 0, nRows_),
      KOKKOS_LAMBDA(lid_t c, real & acc) { acc += fieldMagnitude(c, U, p); }, s);
  return std::isfinite(comm_.globalSum(s));
}

// ------------------------------------------------------------------------------------------------
// PIMPLE
// ------------------------------------------------------------------------------------------------

bool FluidSolver::extrapolatesVelocity() const {
  return opt_.pimple.extrapolateGuess && opt_.pimple.momentumPredictor && opt_.timeScheme != TimeScheme::Steady;
}

void FluidSolver::extrapolateVelocity() {
  auto U = U_;
  ConstReal3View U0 = U0_, U00 = U00_;
  const real r = dt_ / dt0_;
  Kokkos::parallel_for(
      "mfsi::fluid::momentum::extrapolateGuess", RangePolicy(exec_, 0, nCells_), KOKKOS_LAMBDA(lid_t c) {
        for (int j = 0; j < 3; ++j) U(c, j) = U0(c, j) + r * (U0(c, j) - U00(c, j));
      });
}

void FluidSolver::startFinalPressureSolve() {
  if (dpFinal_.extent(0) == 0) {
    dpFinal_ = RealView("mfsi::fluid::pressure::finalChange", nCells_);
    pFinalStart_ =
        RealView(Kokkos::view_alloc(Kokkos::WithoutInitializing, "mfsi::fluid::pressure::finalStart"), nCells_);
  }
  // The guess p + s dp, dp the change the last final solve made, with s the multiple that
  // minimises the energy norm of the guess's error on this step's matrix and source (one
  // Galerkin step along dp). From one step to the next the correctors' changes are alike but not
  // equal in size: cavity 64^3, s rises from 0.6 to 0.92 over steps 2-20, and the final solves
  // take 6.53 instead of 7.27 iterations per step (s = 1).
  real s = dpFinalValid_ ? 1.0 : 0.0;
  if (dpFinalValid_ && opt_.pimple.projectFinalGuess) s = linear_.pressureStepAlong(exec_, pressureMatrix(), rhsP_, p_, dpFinal_);
  auto p = p_, start = pFinalStart_;
  ConstRealView dp = dpFinal_;
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::finalGuess", RangePolicy(exec_, 0, nCells_), KOKKOS_LAMBDA(lid_t c) {
        start(c) = p(c);
        p(c) += s * dp(c);
      });
}

void FluidSolver::finishFinalPressureSolve() {
  auto dp = dpFinal_;
  ConstRealView p = p_, start = pFinalStart_;
  Kokkos::parallel_for(
      "mfsi::fluid::pressure::finalChange", RangePolicy(exec_, 0, nCells_),
      KOKKOS_LAMBDA(lid_t c) { dp(c) = p(c) - start(c); });
  dpFinalValid_ = true;
}

void FluidSolver::checkClosedDomainBalance(int region) {
  // In a domain no boundary opens to a pressure, incompressibility asks the boundary fluxes
  // (inflows and the moving walls' mesh fluxes) to sum to zero; the pressure equation has no
  // solution otherwise, and a pinned reference cell would swallow the difference as a mass source.
  ConstIndexView own = mesh_.faceOwner();
  ConstIndexView cr = cellClosedRegion_;
  ConstRealView phi = phi_;
  const lid_t nIn = nIn_, nRows = nRows_;
  real sum = 0, mag = 0;
  Kokkos::parallel_reduce(
      "mfsi::fluid::closedDomainBalance", RangePolicy(exec_, 0, nB_),
      KOKKOS_LAMBDA(lid_t b, real & s, real & m) {
        const lid_t f = b + nIn;
        if (own(f) >= nRows || (region >= 0 && cr(own(f)) != region)) return;
        s += phi(f);
        m += kmath::fabs(phi(f));
      },
      sum, mag);
  ConstRealView V = geo_.cellVolume;
  real volume = 0;
  Kokkos::parallel_reduce(
      "mfsi::fluid::closedDomainVolume", RangePolicy(exec_, 0, nRows_),
      KOKKOS_LAMBDA(lid_t c, real & v) { v += (region < 0 || cr(c) == region) ? V(c) : 0.0; }, volume);
  sum = comm_.globalSum(sum);
  mag = comm_.globalSum(mag);
  volume = comm_.globalSum(volume);
  // Round-off of the fluxes, and a volume change of 1e-12 of the domain per step (what a
  // volume-constrained membrane leaves), are balance.
  if (!(std::abs(sum) <= 1e-6 * mag + 1e-12 * volume / dt_)) {
    std::ostringstream os;
    os << "fluid: " << (region < 0 ? "the domain" : "closed region " + std::to_string(region))
       << " has no boundary that prescribes the pressure, but its boundary fluxes do not balance "
       << "in the step to t = " << t_ + dt_ << ": net outflow " << sum << " m^3/s against " << mag
       << " m^3/s through the boundary; an incompressible fluid has no answer (a membrane closing it needs "
       << "coupling.volumeConstraint, or give the fluid a pressure boundary or fluid.artificialSoundSpeed)";
    throw DivergenceError(os.str());
  }
}

StepResult FluidSolver::solve() {
  ScopedRegion region("mfsi::fluid::solve");
  if (closedDomain()) checkClosedDomainBalance(-1);
  for (int r = 0; r < closedRegions_; ++r) checkClosedDomainBalance(r);
  StepResult res;
  const auto& pim = opt_.pimple;
  ConstRealView V = geo_.cellVolume;
  bool ddtStored = false;  // fluxAndDdtCorrection formed the final fluxes and correction fluxes
  for (int outer = 0; outer < pim.nOuterCorrectors; ++outer) {
    updateBoundaryVelocity();
    // The velocity gradient feeds only the non-orthogonal diffusion correction and the limited
    // convection schemes; both vanish on a Cartesian mesh with linear convection.
    const bool limited =
        opt_.convection == ConvectionScheme::LimitedLinear || opt_.convection == ConvectionScheme::VanLeer;
    gradUCurrent_ = nonOrthogonal_ || limited;
    if (gradUCurrent_) computeVelocityGradient();
    // The fused assembly also forms the solve's right-hand side when the pressure gradient is
    // already current (the usual case: nothing changed it since the last corrector).
    if (relaxFlux_.extent(0) > 0) storeRelaxationFlux();
    const MomentumAssembly formed =
        assembleMomentum(/*withB=*/pim.momentumPredictor && gradPValid_, /*withInv=*/pim.momentumPredictor);
    const bool bReady = formed.b;
    updatePressureGradient();
    real momRes = 0;
    if (pim.momentumPredictor) {
      ScopedRegion r2("mfsi::fluid::momentum::solve");
      linear_.momentumMatrixChanged(exec_, momentumMatrix(),
                                    formed.inv ? InverseDiagonal::Given : InverseDiagonal::Compute);
      // The three components share the matrix: one solve reads it once for all of them, each
      // component stopping on its own scaled residual.
      if (!bReady) {
        auto b3 = b3_;
        ConstReal3View rhs = rhsU_, gp = gradP_;
        Kokkos::parallel_for(
            "mfsi::fluid::momentum::rhs", RangePolicy(exec_, 0, nRows_), KOKKOS_LAMBDA(lid_t c) {
              for (int j = 0; j < 3; ++j) b3(c, j) = rhs(c, j) - V(c) * gp(c, j);
            });
      }
      // U is read by nothing between here and the solve: the guess changes where it starts only.
      if (freshStep_ && outer == 0 && extrapolatesVelocity() && nSteps_ >= 2) extrapolateVelocity();
      for (const auto& st : linear_.solveMomentum3(exec_, momentumMatrix(), b3_, U_, opt_.momentumSolver)) {
        momRes = std::max(momRes, st.initialResidual);
        res.momentumIterations += st.iterations;
        if (st.breakdown) res.ok = false;
      }
      if (boundaryVelocityReadsU_) updateBoundaryVelocity();
    }
    freshStep_ = false;
    real pRes = -1;
    for (int corr = 0; corr < pim.nCorrectors; ++corr) {
      computeHbyA(/*withRAU=*/corr == 0);
      if (!fusedPressureSource()) computePhiHbyA();
      if (opt_.pimple.consistent) simplecCorrection();
      bc_.updateResistance(exec_, phi_);
      if (hasResistance_) gradPValid_ = false;
      if (pim.relaxPressure < 1.0) Kokkos::deep_copy(exec_, pPrev_, p_);  // read by the relaxation alone
      for (int no = 0; no <= pim.nNonOrthogonalCorrectors; ++no) {
        updatePressureGradient();
        assemblePressure(/*matrix=*/corr == 0 && no == 0);
        if (corr == 0 && no == 0 && pressureLattice_ == nullptr) linear_.pressureValuesChanged(exec_, pressureMatrix());
        ScopedRegion r3("mfsi::fluid::pressure::solve");
        // rAU, hence the matrix, is the same for every corrector of one outer iteration.
        const int refresh = opt_.pressurePreconditioner == PressurePreconditioner::Jacobi
                                ? 1
                                : std::max(1, opt_.pressurePreconditionerRefresh);
        if (corr == 0 && no == 0 && (pressureAssemblies_++ % refresh == 0 || pressureRefreshDue_)) {
          linear_.pressureMatrixChanged(exec_, pressureMatrix());
          pressureAssemblies_ = 1;
          refreshBaselineIterations_ = -1;
          pressureRefreshDue_ = false;
        }
        // The last solve of the step may be tighter than the intermediate ones (pFinal).
        LinearSolverOptions ps = opt_.pressureSolver;
        const bool finalSolve =
            outer == pim.nOuterCorrectors - 1 && corr == pim.nCorrectors - 1 && no == pim.nNonOrthogonalCorrectors;
        if (finalSolve && opt_.pressureFinalRelTol >= 0) ps.relTol = opt_.pressureFinalRelTol;
        ps.amgFinestSweeps = finalSolve ? 1 : opt_.pressureFinestSweeps;
        // The final solve starts from p plus the change the last final solve made: from one step
        // to the next the correctors change p by similar amounts (cavity 64^3: 7x smaller
        // initial residual, one iteration fewer).
        const bool guessP = finalSolve && pim.extrapolateGuess && opt_.timeScheme != TimeScheme::Steady;
        if (guessP) startFinalPressureSolve();
        const auto st = linear_.solvePressure(exec_, pressureMatrix(), rhsP_, p_, ps);
        if (guessP) finishFinalPressureSolve();
        gradPValid_ = false;
        if (finalSolve && refresh > 1) {
          if (refreshBaselineIterations_ < 0)
            refreshBaselineIterations_ = st.iterations;
          else if (st.iterations > opt_.pressurePreconditionerStaleRatio * refreshBaselineIterations_ + 1)
            pressureRefreshDue_ = true;
        }
        if (pRes < 0) pRes = st.initialResidual;
        res.pressureIterations += st.iterations;
        if (st.breakdown) res.ok = false;
      }
      // The fluxes of a corrector are read only by the next outer iteration's momentum assembly,
      // a resistance outlet's update and the end of the step: otherwise the next corrector
      // rewrites them unread, and they are skipped. The final fluxes of the step are formed
      // after the velocity correction, in one face pass with the end-of-step correction fluxes
      // (not with pressure relaxation, which changes p after the fluxes are due).
      const bool lastCorrector = corr == pim.nCorrectors - 1;
      const bool atEnd =
          fusedCellPasses() && lastCorrector && outer == pim.nOuterCorrectors - 1 && pim.relaxPressure >= 1.0;
      const bool fluxesUnread = opt_.fusedMomentumAssembly && !lastCorrector && !hasResistance_;
      correctFluxAndVelocity(/*flux=*/!atEnd && !fluxesUnread);
      if (atEnd) {
        fluxAndDdtCorrection();
        ddtStored = true;
      }
    }
    res.outerIterations = outer + 1;
    if (outer == 0) {
      res.momentumResidual = momRes;
      res.pressureResidual = pRes;
    }
    res.finalMomentumResidual = momRes;
    res.finalPressureResidual = pRes;
    if (pim.outerTolerance > 0 && momRes < pim.outerTolerance && pRes < pim.outerTolerance) {
      res.converged = true;
      break;
    }
    if (!res.ok) break;
  }
  if (fusedCellPasses()) {
    bool finite = true;
    res.continuityMax = finishStep(res.continuitySum, finite, ddtStored);
    if (!finite || !std::isfinite(res.continuityMax)) res.ok = false;
  } else {
    storeDdtCorrection();
    res.continuityMax = continuityMax(res.continuitySum);
    if (!fieldsFinite() || !std::isfinite(res.continuityMax)) res.ok = false;
  }
  exec_.fence();
  return res;
}

StepResult FluidSolver::solveStep(real t, real dt) {
  beginStep(t, dt);
  if (motion_) {
    Real3View pts("mfsi::fluid::motionPoints", mesh_.nNodes());
    Kokkos::deep_copy(exec_, pts, points0_);
    exec_.fence();
    motion_(t + dt, pts);
    moveMesh(pts);
  }
  return solve();
}

void FluidSolver::exchangeGhosts(const RealView& x) const {
  if (cellHalo_) cellHalo_->exchange(exec_, x);
}

void FluidSolver::exchangeGhosts(const Real3View& x) const {
  if (cellHalo_) cellHalo_->exchange(exec_, x);
}

void FluidSolver::exchangeGhosts(const Tensor3View& x) const {
  if (cellHalo_) cellHalo_->exchange(exec_, x);
}

}  // namespace mfsi::fluid
