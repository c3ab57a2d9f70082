#pragma once
/// \file
/// \brief Aggregation-based algebraic multigrid preconditioner for the pressure Poisson equation
/// (symmetric, M-matrix-like finite-volume Laplacians on hex meshes, possibly pure Neumann).
///
/// Method (smoothed aggregation, Vanek-Mandel-Brezina 1996):
///  - strength of connection |a_ij| >= theta sqrt(|a_ii a_jj|) (finest level; theta = 0 below);
///    greedy three-phase aggregation
///    (roots whose strong neighbours are all free take them; leftovers join the strongest
///    neighbouring aggregate; the rest form new aggregates). Host, set-up only.
///  - on a structured lattice (one block numbered x fastest, 7- or 5-point, every coupling
///    strong: `detectLattice`), lattice-aligned cubes instead (`AmgAggregation`): 2x2x2 on the
///    finest level, 3x3x3 below, numbered lexicographically, so every level is a lattice
///    operator with a few column patterns; level 1 (33 points) is stored pattern-compressed and
///    swept in long vectorised runs, where greedy aggregates give an irregular ~30-point CSR.
///  - tentative prolongator: piecewise constant on aggregates (it carries the constant null space);
///    smoothed prolongator P = (I - omega D^{-1} A) P_tent with omega = 4/3 / lambda_max(D^{-1} A)
///    (`AmgProlongation::Unsmoothed` keeps P_tent; it converges poorly and is there for comparison).
///  - Galerkin coarse operator A_c = R (A P), R = P^T, by two row-parallel sparse-product kernels
///    into sparsities computed once on the host (A P is kept: ~1.5x the memory of A per level).
///  - symmetric V-cycle with 4th-kind Chebyshev (default, Lottes 2023), first-kind Chebyshev or
///    damped-Jacobi smoothing on every level, all in D^{-1}A with lambda_max from a few Lanczos
///    steps; dense pseudo-inverse on the coarsest level (<= coarseSize rows; Eigen on the host at
///    set-up, applied on the device).
///  - every kernel writes its own rows only (no atomics): the preconditioner is deterministic.
///
/// Cycle (Amg.cpp): the V-cycle runs on its own copies of every level's operator, P and R,
/// refreshed by set-up and value updates: by default in float (`AmgPrecision::Mixed`; apply()'s r
/// and z stay double, converted by the first and last kernels), as the off-diagonal part of
/// D^{-1}A with D^{-1}-scaled right-hand sides and residuals (no diagonal in the inner loops),
/// and in fixed-width (ELL) rows where row lengths are nearly equal, with one-byte column
/// patterns on structured blocks. Every Chebyshev step is one pass (x_new = x + d into a second
/// buffer), the restriction also takes the coarse level's first smoothing step, and the
/// coarsest pseudo-inverse is applied in double. Float rounding (1e-7 relative) perturbs the
/// preconditioner far below what CG notices: the iteration counts are those of the double cycle.
///
/// Measured (tests/kernels/test_amg.cpp, 7-point Dirichlet Poisson, rough right-hand side, CG to
/// 1e-8): 7 / 7 / 8 iterations at 16^3, 24^3 and 32^3 with the defaults (4th-kind Chebyshev of
/// degree 2, prolongator damping 1.45, lattice cubes; Jacobi-CG: 59, 86, 116); operator
/// complexity 1.5-1.6. perf/bench_linsolve, defaults, one thread: 8 / 8 / 9 iterations at
/// 32^3 / 64^3 / 128^3, 0.69 / 7.6 / 62 ms per iteration (first-kind degree 3 before: 8 / 9 / 9,
/// 0.84 / 7.9 / 74 ms). The figures below are from earlier defaults (first-kind Chebyshev of
/// degree 3 or 2, damping 4/3); with today's defaults greedy aggregation takes 13 iterations at
/// 64^3 where lattice cubes take 9 (perf/RESULTS.md, distributed AMG section).
/// perf/bench_linsolve PressureSolve (same problem), greedy aggregation: 8 / 9 / 10 iterations at
/// 32^3 / 64^3 / 128^3 in both precisions (degree 2: 9 / 10 / 12). Per CG iteration on one
/// thread, float cycle vs double cycle: 64^3 11.5 vs 17.1 ms, 128^3 97 vs 133 ms
/// (perf/RESULTS.md); the degree-2 double CSR cycle the float cycle replaced took 18.0 / 152 ms.
/// At 32^3 (cache-resident) the kernels are bound by instructions, not bytes, and float gains
/// little (1.1-1.2x). Lattice cubes vs greedy aggregation (float cycle, one thread, CPU time of
/// one session on a shared machine): 8 / 9 / 9 vs 8 / 9 / 10 iterations, 0.94 / 8.2 / 73 vs
/// 1.18 / 11.0 / 93 ms per iteration at 32^3 / 64^3 / 128^3; 3D cavity at 64^3
/// (perf/bench_cavity3d): 7.5 vs 8.5 AMG-CG iterations per step, V-cycles 40 vs 75 ms per step.
/// One cell thick (512^2, Neumann): 7 vs 8 iterations at ~7.4 vs ~6.5 ms per iteration (the
/// 13-point level 1 is heavy next to a 5-point finest level): about the same time per solve.
///
/// Singular (pure Neumann) systems: aggregation keeps the constant vector in the range of every P,
/// so every coarse operator has the same null space, and the coarsest solve is a pseudo-inverse
/// (eigenvalues below 1e-10 max|lambda| are dropped): the cycle never amplifies the null
/// component. Use it with `KrylovOptions::nullSpace = NullSpace::Constant`, which projects the
/// residuals onto zero mean and returns the zero-mean solution.
///
/// Re-use: `setup` builds everything. `updateValues` (same sparsity, new values) keeps aggregates
/// and the sparsity of P, R = P^T and every coarse operator, and only recomputes values on the
/// device: diagonals, lambda_max, P, R, A_c, the small coarsest pseudo-inverse and the cycle's
/// copies. apply() uses the values of the last `setup`/`updateValues`/`updateFinestSmoother`:
/// values refilled in place in the matrix given to `setup` are not seen before the next update
/// (the preconditioner stays the fixed SPD operator of the last update).
#include "kernels/Preconditioner.hpp"

#include <memory>
#include <vector>

namespace mfsi {

namespace detail {
struct AmgHierarchy;
}  // namespace detail

enum class AmgProlongation { Smoothed, Unsmoothed };
/// \brief Aggregation of the levels. Auto: when the finest matrix is a structured lattice
/// (`detectLattice`) whose couplings are all strong, the first `latticeLevels` levels are
/// aggregated into lattice-aligned cubes numbered lexicographically (2x2x2 on the finest level,
/// 3x3x3 below; squares on a one-cell-thick lattice), so every coarse operator is again a
/// lattice operator whose rows share a few column patterns (level 1: stored pattern-compressed,
/// swept vectorised on host backends); other levels, and every other matrix (unstructured,
/// multi-block, anisotropic), are aggregated greedily. Greedy: greedy everywhere.
enum class AmgAggregation { Auto, Greedy };
/// \brief Smoother of every level, a polynomial in D^{-1}A. ChebyshevFourthKind (the default):
/// Lottes' 4th-kind Chebyshev polynomial on [0, lambda_max] (no lower bound to choose).
/// Chebyshev: the first-kind polynomial on [lambda_max / chebyshevRatio, lambda_max]. Jacobi:
/// damped Jacobi.
enum class AmgSmoother { ChebyshevFourthKind, Chebyshev, Jacobi };
/// \brief Arithmetic of the V-cycle. Mixed: every level's operator, P, R and diagonal are float
/// copies and the cycle runs in float (apply()'s r and z stay double; the coarsest dense solve
/// stays double); set-up and value updates compute in double either way. Mixed moves ~40 % fewer
/// bytes per cycle for the same CG iteration counts (tests/kernels/test_amg.cpp).
enum class AmgPrecision { Double, Mixed };

/// \brief Options of the AMG preconditioner. Defaults suit the 3D pressure Poisson equation.
struct AmgOptions {
  AmgProlongation prolongation = AmgProlongation::Smoothed;
  AmgSmoother smoother = AmgSmoother::ChebyshevFourthKind;
  int sweeps = 1;           ///< smoother applications before and after the coarse correction
  /// Smoother applications on the finest level (0: `sweeps`); `setFinestSweeps` changes it
  /// between solves without a new set-up.
  int finestSweeps = 0;
  /// Polynomial degree (SpMVs per smoother application). 4th kind, measured on the 3D cavity at
  /// 64^3 (perf/bench_cavity3d, AMG-CG iterations per step): degree 1 / 2 / 3 / 4: 11.7 / 7.40 /
  /// 7.40 / 7.33; degree 2 needs the fewest sweeps per step. First kind (ratio 10, the default
  /// before): degree 3 7.53, degree 2 7.53 with ratio 6. 4th kind degree 2 on the finest level
  /// and 3 below: 7.13, not worth the two extra level-1 sweeps per cycle.
  int chebyshevDegree = 2;
  /// First-kind Chebyshev damps the spectrum of D^{-1}A in [lambda_max / ratio, lambda_max]. The
  /// coarse level handles the rest; ~ the coarsening ratio (8-30 here) is the usual choice, 10
  /// measured best with degree 3 (11 vs 16 CG iterations with 30 at 64^3). Not used by the
  /// 4th kind.
  real chebyshevRatio = 10.0;
  real jacobiWeight = 0.0;  ///< damped-Jacobi omega; 0 = 4 / (3 lambda_max(D^{-1}A))
  /// theta of the strength of connection (0: every coupling is strong). Smoothed-aggregation
  /// coarse operators have many small couplings (|a_ij| / a_ii ~ 0.01-0.05 in 3D), so a
  /// threshold meant for the finest level would stall coarsening there: it applies on the finest
  /// level only, coarser levels use theta = 0 (as ML/MueLu's default).
  real strengthThreshold = 0.08;
  /// omega lambda_max of the prolongator smoothing. With the 4th-kind degree-2 smoother, 3D cavity
  /// 64^3 AMG-CG iterations per step: 1.3: 7.47, 4/3 (the textbook value, used before): 7.40,
  /// 1.4-1.5: 7.27, 1.55: 7.40.
  real prolongatorDamping = 1.45;
  int eigenSteps = 12;                  ///< Lanczos steps estimating lambda_max(D^{-1}A) per level
  lid_t coarseSize = 200;               ///< stop coarsening at or below this many rows
  int maxLevels = 12;
  lid_t maxDirectSize = 2000;                    ///< largest coarsest level solved densely; above: 10 smoother sweeps
  AmgPrecision precision = AmgPrecision::Mixed;  ///< arithmetic of the V-cycle
  AmgAggregation aggregation = AmgAggregation::Auto;
  /// Levels aggregated into lattice cubes under AmgAggregation::Auto, from the finest down (the
  /// default: all of them; 1: the finest only, greedy below).
  int latticeLevels = 12;
};

/// \brief Extents of a structured lattice: nx * ny * nz rows numbered x fastest. Empty (all 0)
/// when a matrix is not one.
struct AmgLattice {
  lid_t nx = 0, ny = 0, nz = 0;
  bool valid() const { return nx > 0; }
};

/// \brief The lattice of a square matrix whose every row i = x + nx (y + ny z) holds exactly its
/// diagonal and its in-range lattice neighbours i -+ 1, i -+ nx, i -+ nx ny (a 7-point stencil;
/// 5-point with nz = 1), or an empty AmgLattice: other numberings, wrap-around or extra couplings,
/// missing couplings, several blocks, 1D chains. Every row is checked (host, set-up cost).
AmgLattice detectLattice(const CsrMatrix& A);

/// \brief One level of the hierarchy, for logs and tests.
struct AmgLevelInfo {
  lid_t rows = 0;
  lid_t nnz = 0;
  real lambdaMax = 0.0;  ///< estimated largest eigenvalue of D^{-1} A
  int cycleWidth = 0;      ///< ELL width of the cycle's copy of the operator (0: CSR)
  bool cyclePatterned = false;  ///< the cycle's copy stores column patterns, not columns
  AmgLattice lattice;      ///< set when this level was aggregated into lattice cubes
};

/// \brief Hierarchy summary.
struct AmgInfo {
  std::vector<AmgLevelInfo> levels;
  real operatorComplexity = 0.0;  ///< sum of nnz over levels / nnz of the finest
  real gridComplexity = 0.0;      ///< sum of rows over levels / rows of the finest
  bool directCoarseSolve = false;
};

/// \brief Smoothed-aggregation AMG V-cycle as a (fixed, symmetric) preconditioner for CG. One
/// rank only for now (A.nCols must equal A.nRows).
class AmgPreconditioner final : public Preconditioner {
 public:
  explicit AmgPreconditioner(const AmgOptions& options = {});
  ~AmgPreconditioner() override;

  void setup(const ExecSpace& exec, const CsrMatrix& A) override;
  /// \brief New values on the sparsity given to `setup` (checked; a different sparsity falls back
  /// to `setup`). Aggregates and all coarse sparsities are reused.
  void updateValues(const ExecSpace& exec, const CsrMatrix& A) override;
  /// \brief Cheaper than `updateValues` (a few SpMVs instead of ~one solve): refresh only the
  /// finest level's smoother (diagonal, lambda_max) for A's new values; the coarse levels keep the
  /// operators of the last set-up/update. The cycle stays a symmetric positive definite
  /// preconditioner for SPD A, and degrades slowly as the values drift from the last full update.
  /// For values that change a little every step (mesh motion): full update every k steps.
  void updateFinestSmoother(const ExecSpace& exec, const CsrMatrix& A);
  /// \brief Smoother applications on the finest level from now on (0: `sweeps`): a host-side
  /// change of the level's step coefficients, no set-up. A loose solve that a stronger cycle
  /// finishes one iteration sooner can ask for more than the tight solves that follow it.
  void setFinestSweeps(int sweeps);
  /// The finest level's sweeps in force (options, or the last setFinestSweeps).
  int finestSweeps() const { return options_.finestSweeps; }
  /// \brief z = one V-cycle applied to r, from a zero initial guess.
  void apply(const ExecSpace& exec, const ConstRealView& r, const RealView& z) override;
  std::string name() const override { return "amg"; }

  /// \brief Levels, sizes and complexities of the current hierarchy (empty before set-up).
  AmgInfo info() const;
  const AmgOptions& options() const { return options_; }
  /// \brief Operator of level l (0: the matrix given to set-up). Diagnostics and tests.
  const CsrMatrix& levelMatrix(std::size_t l) const;
  /// \brief Prolongation from level l + 1 to level l (l + 1 < number of levels).
  const CsrMatrix& prolongator(std::size_t l) const;

 private:
  AmgOptions options_;
  std::unique_ptr<detail::AmgHierarchy> h_;
};

}  // namespace mfsi
