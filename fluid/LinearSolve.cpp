#include "fluid/LinearSolve.hpp"

#include "core/Error.hpp"
#include "kernels/Amg.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace mfsi::fluid {

namespace {

using blas::reduce;
using blas::Sums;

/// Jacobi on an inverse diagonal that LinearSolver owns and refreshes, so the one-component
/// BiCGStab and the three-component BiCGStab3 share it.
class SharedJacobi final : public Preconditioner {
 public:
  explicit SharedJacobi(const RealView& invDiag) : inv_(invDiag) {}
  void setup(const ExecSpace& exec, const CsrMatrix& A) override { invertDiagonal(exec, A, inv_); }
  void apply(const ExecSpace& exec, const ConstRealView& r, const RealView& z) override {
    const ConstRealView inv = inv_;
    // The inverse diagonal may reach into the ghosts (BiCGStab3 reads it at neighbours): the rows
    // are those of r.
    const lid_t n = static_cast<lid_t>(std::min(inv.extent(0), r.extent(0)));
    Kokkos::parallel_for(
        "mfsi::fluid::linear::jacobi", RangePolicy(exec, 0, n),
        KOKKOS_LAMBDA(lid_t i) { z(i) = inv(i) * r(i); });
  }
  std::string name() const override { return "jacobi"; }

 private:
  RealView inv_;
};

/// The Krylov stopping tolerance on |r|_1 that is OpenFOAM's test on the scaled residual
/// |r|_1 / nf: below tolerance, or below relTol times the initial one. A residual that is only
/// round-off of the terms it is made of (e.g. an exactly preserved uniform flow) counts as
/// converged: iterating would only stir round-off.
real l1Tolerance(const LinearSolverOptions& o, real nf, real r1, real scale) {
  return std::max({o.tolerance * nf, o.relTol * r1, 1e-14 * scale});
}

}  // namespace

LinearSolver::LinearSolver() = default;
LinearSolver::~LinearSolver() = default;
LinearSolver::LinearSolver(LinearSolver&&) noexcept = default;
LinearSolver& LinearSolver::operator=(LinearSolver&&) noexcept = default;

LinearSolver::LinearSolver(lid_t n, PressurePreconditioner pp)
    : uSolver_(makeKrylovSolver(KrylovMethod::BiCGStab)),
      pSolver_(std::make_unique<ConjugateGradient>()),
      r_("mfsi::fluid::linear::residual", n) {
  if (pp == PressurePreconditioner::Amg)
    pPrec_ = std::make_unique<AmgPreconditioner>();
  else
    pPrec_ = std::make_unique<JacobiPreconditioner>();
}

void LinearSolver::distribute(const SolverComm& comm, std::unique_ptr<Preconditioner> pressure) {
  comm_ = comm;
  uSolver_ = makeKrylovSolver(KrylovMethod::BiCGStab, {}, comm_);
  pSolver_ = std::make_unique<ConjugateGradient>(KrylovOptions{}, comm_);
  u3Solver_ = BiCGStab3({}, comm_);
  if (pressure) pPrec_ = std::move(pressure);
  uReady_ = pReady_ = false;
}

RealView LinearSolver::momentumInverseDiagonal(lid_t n) {
  if (uInvDiag_.extent(0) != static_cast<std::size_t>(n) || !uPrec_) {
    uInvDiag_ = RealView(Kokkos::view_alloc(Kokkos::WithoutInitializing, "mfsi::fluid::linear::momentumInvDiag"), n);
    uPrec_ = std::make_unique<SharedJacobi>(uInvDiag_);
  }
  return uInvDiag_;
}

void LinearSolver::momentumMatrixChanged(const ExecSpace& exec, const CsrMatrix& A, InverseDiagonal inverse) {
  // BiCGStab3 reads the inverse diagonal at the neighbours of a row: on a decomposed mesh it has
  // the ghosts' entries too, from their owners.
  const lid_t nc = std::max(A.nRows, A.nCols);
  if (inverse == InverseDiagonal::Given)
    MFSI_CHECK(uInvDiag_.extent(0) == static_cast<std::size_t>(nc) && uPrec_,
               "LinearSolver::momentumMatrixChanged: no inverse diagonal was given");
  else
    invertDiagonal(exec, A, momentumInverseDiagonal(nc));
  comm_.updateGhosts(exec, uInvDiag_);
  uReady_ = true;
}

void LinearSolver::pressureMatrixChanged(const ExecSpace& exec, const CsrMatrix& A) {
  // Values assembled into CG's lattice only: the preconditioner reads A's CSR values.
  if (pSolver_->lattice().assembledFor(A)) pSolver_->lattice().writeCsr(exec, A);
  auto* amg = dynamic_cast<AmgPreconditioner*>(pPrec_.get());
  if (pReady_)
    pPrec_->updateValues(exec, A);
  else
    pPrec_->setup(exec, A);
  // Remember what it was built from (see PressurePreconditionerHistory).
  PressurePreconditionerHistory& h = pHistory_;
  RealView& keep = pReady_ ? h.refreshValues : h.setupValues;
  if (keep.extent(0) != A.values.extent(0)) keep = RealView("mfsi::fluid::pressure::preconditionerValues", A.values.extent(0));
  Kokkos::deep_copy(exec, keep, A.values);
  (pReady_ ? h.refreshSweeps : h.setupSweeps) = amg ? amg->finestSweeps() : 0;
  h.refreshed = pReady_;
  pReady_ = true;
}

void LinearSolver::savePressurePreconditioner(io::StateWriter& w) const {
  const PressurePreconditionerHistory& h = pHistory_;
  w.putBool("ready", pReady_);
  w.putBool("refreshed", h.refreshed);
  w.putInt("setupSweeps", h.setupSweeps);
  w.putInt("refreshSweeps", h.refreshSweeps);
  w.putInt("sweeps", h.sweeps);
  w.putView("setupValues", h.setupValues, io::Entity::Part);
  w.putView("refreshValues", h.refreshed ? h.refreshValues : RealView(), io::Entity::Part);
}

void LinearSolver::loadPressurePreconditioner(const io::StateReader& r, const ExecSpace& exec, const CsrMatrix& A) {
  if (!r.boolean("ready")) return;
  auto* amg = dynamic_cast<AmgPreconditioner*>(pPrec_.get());
  PressurePreconditionerHistory& h = pHistory_;
  const bool refreshed = r.boolean("refreshed");
  const int sweeps = static_cast<int>(r.integer("sweeps"));
  const int setupSweeps = static_cast<int>(r.integer("setupSweeps"));
  const int refreshSweeps = static_cast<int>(r.integer("refreshSweeps"));
  const RealView values("mfsi::fluid::pressure::checkpointValues", A.values.extent(0));
  r.getView("setupValues", values);
  Kokkos::deep_copy(exec, A.values, values);
  pReady_ = false;
  if (amg) amg->setFinestSweeps(setupSweeps);
  pressureMatrixChanged(exec, A);
  if (refreshed) {
    r.getView("refreshValues", values);
    Kokkos::deep_copy(exec, A.values, values);
    if (amg) amg->setFinestSweeps(refreshSweeps);
    pressureMatrixChanged(exec, A);
  }
  h.sweeps = sweeps;
  if (amg) amg->setFinestSweeps(sweeps);
}

void LinearSolver::pressureValuesChanged(const ExecSpace& exec, const CsrMatrix& A) {
  // CG's lattice copy is a one-rank fast path (a rank's rows with ghost columns are no lattice).
  if (comm_.ranks() > 1) return;
  pSolver_->matrixChanged(exec, A);
}

SymmetricLatticeMatrix* LinearSolver::pressureLattice(const CsrMatrix& A) {
  SymmetricLatticeMatrix& L = pSolver_->lattice();
  return L.prepare(A) ? &L : nullptr;
}

void LinearSolver::pressureLatticeAssembled(const CsrMatrix& A) { pSolver_->lattice().markAssembled(A); }

LinearSolveStats LinearSolver::solveMomentum(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b,
                                             const RealView& x, const LinearSolverOptions& o) {
  MFSI_CHECK(uReady_, "LinearSolver::solveMomentum: momentumMatrixChanged was not called");
  return solve(exec, *uSolver_, *uPrec_, A, b, x, o);
}

LinearSolveStats LinearSolver::solvePressure(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b,
                                             const RealView& x, const LinearSolverOptions& o) {
  if (auto* amg = dynamic_cast<AmgPreconditioner*>(pPrec_.get())) {
    amg->setFinestSweeps(o.amgFinestSweeps);
    pHistory_.sweeps = o.amgFinestSweeps;
  }
  return solve(exec, *pSolver_, *pPrec_, A, b, x, o);
}

real LinearSolver::pressureStepAlong(const ExecSpace& exec, const CsrMatrix& A, const ConstRealView& b,
                                     const ConstRealView& x, const ConstRealView& d) {
  const lid_t n = A.nRows;
  const SolverComm& comm = comm_;
  std::array<double, 3> s{};  // {d.b, (A d).x, d.(A d)}
  if (const SymmetricLatticeMatrix* L = pSolver_->latticeCopy(A)) {
    // The lattice product into the residual work array (free until the next solve), then the dots.
    if (r_.extent(0) < static_cast<std::size_t>(n)) r_ = RealView("mfsi::fluid::linear::residual", n);
    const RealView w = r_;
    L->spmv(exec, d, w);
    s = reduce<3>(
        exec, comm, "mfsi::fluid::linear::stepAlong", n, KOKKOS_LAMBDA(lid_t i, Sums<3> & acc) {
          acc[0] += d(i) * b(i);
          acc[1] += w(i) * x(i);
          acc[2] += d(i) * w(i);
        });
  } else {
    const ConstIndexView rp = A.rowPtr, ci = A.colIdx;
    const ConstRealView v = A.values;
    s = reduce<3>(
        exec, comm, "mfsi::fluid::linear::stepAlong", n, KOKKOS_LAMBDA(lid_t i, Sums<3> & acc) {
          real w = 0;
          for (lid_t k = rp(i); k < rp(i + 1); ++k) w += v(k) * d(ci(k));
          acc[0] += d(i) * b(i);
          acc[1] += w * x(i);
          acc[2] += d(i) * w;
        });
  }
  const real num = s[0] - s[1];
  return s[2] > 0.0 && std::isfinite(num) ? num / s[2] : 0.0;
}

LinearSolveStats LinearSolver::solve(const ExecSpace& exec, KrylovSolver& solver, Preconditioner& M, const CsrMatrix& A,
                                     const ConstRealView& b, const RealView& x, const LinearSolverOptions& o) {
  LinearSolveStats st;
  const lid_t n = A.nRows;
  const SolverComm& comm = comm_;
  if (r_.extent(0) < static_cast<std::size_t>(n)) r_ = RealView("mfsi::fluid::linear::residual", n);
  comm.updateGhosts(exec, x);
  // Two passes: the mean of x, then r = b - A x with the sums {|r|_1, normalisation factor,
  // round-off scale, r.r}; r and its norms are the Krylov solver's starting residual.
  const real xbar = blas::mean(exec, comm, n, x);
  const ConstIndexView rp = A.rowPtr, ci = A.colIdx;
  const ConstRealView v = A.values;
  const RealView r = r_;
  // CG's lattice copy of A, when it holds one (the announced pressure matrix), reads 32 instead
  // of 84 B of A per row.
  const SymmetricLatticeMatrix* lattice = pSolver_->latticeCopy(A);
  const auto s = lattice
                     ? lattice->scaledResidual(exec, comm, x, b, xbar, r)
                     : reduce<4>(
                           exec, comm, "mfsi::fluid::linear::scaledResidual", n, KOKKOS_LAMBDA(lid_t i, Sums<4> & acc) {
                             real ax = 0, rs = 0;
                             for (lid_t k = rp(i); k < rp(i + 1); ++k) {
                               ax += v(k) * x(ci(k));
                               rs += v(k);
                             }
                             r(i) = blas::scaledResidualTerms(b(i), ax, rs, xbar, acc);
                           });
  const real r1 = s[0], scale = s[2];
  if (!std::isfinite(r1) || !std::isfinite(s[1])) {
    st.breakdown = true;
    st.initialResidual = st.finalResidual = r1;
    return st;
  }
  const real nf = s[1] + 1e-300;
  st.initialResidual = st.finalResidual = r1 / nf;
  KrylovOptions ko;
  ko.relTol = 0.0;
  ko.absTol = 0.0;
  ko.l1AbsTol = l1Tolerance(o, nf, r1, scale);
  ko.maxIterations = o.maxIter;
  solver.setOptions(ko);
  InitialResidual r0;
  r0.r = r;
  r0.rr = s[3];
  r0.l1 = r1;
  const KrylovResult kr = solver.solve(exec, A, b, x, M, r0);
  comm.updateGhosts(exec, x);  // the solver updates the owned rows: the ghosts follow their owners
  st.iterations = kr.iterations;
  st.converged = kr.converged;
  st.breakdown = kr.status == KrylovStatus::NotFinite || kr.status == KrylovStatus::Breakdown;
  st.finalResidual = kr.finalResidualL1 / nf;
  return st;
}

std::array<LinearSolveStats, 3> LinearSolver::solveMomentum3(const ExecSpace& exec, const CsrMatrix& A,
                                                             const ConstReal3View& b, const Real3View& x,
                                                             const LinearSolverOptions& o) {
  ScopedRegion region("mfsi::fluid::linear::momentum3");
  MFSI_CHECK(uReady_, "LinearSolver::solveMomentum3: momentumMatrixChanged was not called");
  const lid_t n = A.nRows;
  const lid_t nc = std::max(A.nRows, A.nCols);  // BiCGStab3 gathers its residual at neighbours
  const SolverComm& comm = comm_;
  if (r3_.extent(0) != static_cast<std::size_t>(nc)) r3_ = Real3View("mfsi::fluid::linear::residual3", nc);
  comm.updateGhosts(exec, x);
  // The three means of x in one reduction, then one pass over A for the three columns: the row
  // sum (for A xbar) is shared, and per column the sums {|r|_1, normalisation factor, round-off
  // scale, r.r} - 12 sums in one deterministic reduction.
  const auto xs = reduce<3>(
      exec, comm, "mfsi::fluid::linear::mean3", n, KOKKOS_LAMBDA(lid_t i, Sums<3> & acc) {
        for (int c = 0; c < 3; ++c) acc[c] += x(i, c);
      });
  const real nGlobal = comm.globalSum(static_cast<real>(n));
  Kokkos::Array<real, 3> xbar;
  for (int c = 0; c < 3; ++c) xbar[c] = nGlobal > 0 ? xs[c] / nGlobal : 0.0;
  const ConstIndexView rp = A.rowPtr, ci = A.colIdx;
  const ConstRealView v = A.values;
  const Real3View r = r3_;
  const auto s = reduce<12>(
      exec, comm, "mfsi::fluid::linear::scaledResidual3", n, KOKKOS_LAMBDA(lid_t i, Sums<12> & acc) {
        real ax[3] = {0, 0, 0}, rs = 0;
        for (lid_t k = rp(i); k < rp(i + 1); ++k) {
          const real a = v(k);
          const lid_t j = ci(k);
          ax[0] += a * x(j, 0);
          ax[1] += a * x(j, 1);
          ax[2] += a * x(j, 2);
          rs += a;
        }
        for (int c = 0; c < 3; ++c) {
          const real bi = b(i, c), ri = bi - ax[c];
          r(i, c) = ri;
          acc[c] += kmath::fabs(ri);
          acc[3 + c] += kmath::fabs(ax[c] - rs * xbar[c]) + kmath::fabs(bi - rs * xbar[c]);
          acc[6 + c] += kmath::fabs(bi) + kmath::fabs(ax[c]);
          acc[9 + c] += ri * ri;
        }
      });

  std::array<LinearSolveStats, 3> st;
  std::array<KrylovOptions, 3> ko;
  std::array<real, 3> nf{};
  InitialResidual3 r0;
  r0.r = r;
  for (int c = 0; c < 3; ++c) {
    const real r1 = s[c], scale = s[6 + c];
    r0.rr[c] = s[9 + c];
    r0.l1[c] = r1;
    ko[c].relTol = 0.0;
    ko[c].absTol = 0.0;
    ko[c].maxIterations = o.maxIter;
    if (!std::isfinite(r1) || !std::isfinite(s[3 + c])) {
      // The solver leaves this column alone (a NaN residual would also stop it at once).
      st[c].breakdown = true;
      st[c].initialResidual = st[c].finalResidual = r1;
      ko[c].maxIterations = 0;
      nf[c] = 1.0;
      continue;
    }
    nf[c] = s[3 + c] + 1e-300;
    st[c].initialResidual = st[c].finalResidual = r1 / nf[c];
    ko[c].l1AbsTol = l1Tolerance(o, nf[c], r1, scale);
  }
  u3Solver_.setOptions(ko);
  const auto kr = u3Solver_.solve(exec, A, b, x, uInvDiag_, r0);
  comm.updateGhosts(exec, x);
  for (int c = 0; c < 3; ++c) {
    if (st[c].breakdown) continue;
    st[c].iterations = kr[c].iterations;
    st[c].converged = kr[c].converged;
    st[c].breakdown = kr[c].status == KrylovStatus::NotFinite || kr[c].status == KrylovStatus::Breakdown;
    st[c].finalResidual = kr[c].finalResidualL1 / nf[c];
  }
  return st;
}

}  // namespace mfsi::fluid
