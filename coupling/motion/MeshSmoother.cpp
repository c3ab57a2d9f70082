#include "coupling/motion/MeshSmoother.hpp"

#include "core/Error.hpp"

#include <sstream>

namespace mfsi::coupling {

namespace {

// The constructor's kernels are free functions: nvcc takes no device lambda in a constructor.

/// fixed(i) = 1 for every node of a boundary face. Several faces may mark one node: every writer
/// stores the same 1, so the race is benign.
Kokkos::View<std::uint8_t*, MemSpace> boundaryNodes(const HexMesh& mesh) {
  Kokkos::View<std::uint8_t*, MemSpace> fixed("mfsi::coupling::motion::prescribed", mesh.nNodes());
  const ConstQuad4View fn = mesh.faceNodes();
  Kokkos::parallel_for(
      "mfsi::coupling::motion::markBoundaryNodes", RangePolicy(ExecSpace(), mesh.nInternalFaces(), mesh.nFaces()),
      KOKKOS_LAMBDA(lid_t f) {
        for (int k = 0; k < 4; ++k) fixed(fn(f, k)) = 1;
      });
  return fixed;
}

/// 1 / L^2 for every node -> node entry, L the reference edge length.
RealView inverseSquareEdgeWeights(const HexMesh& mesh) {
  const ConstIndexView off = mesh.nodeNodeOffsets(), nb = mesh.nodeNodes();
  const ConstReal3View X0 = mesh.referencePoints();
  RealView w("mfsi::coupling::motion::stiffWeights", nb.extent(0));
  Kokkos::parallel_for(
      "mfsi::coupling::motion::stiffWeights", RangePolicy(ExecSpace(), 0, mesh.nNodes()), KOKKOS_LAMBDA(lid_t i) {
        for (lid_t k = off(i); k < off(i + 1); ++k) {
          const lid_t j = nb(k);
          const real dx = X0(j, 0) - X0(i, 0), dy = X0(j, 1) - X0(i, 1), dz = X0(j, 2) - X0(i, 2);
          w(k) = real(1) / (dx * dx + dy * dy + dz * dz);
        }
      });
  return w;
}

}  // namespace

MeshSmoother::MeshSmoother(const HexMesh& mesh, const MeshSmootherOptions& options)
    : mesh_(mesh), options_(options) {
  MFSI_CHECK(options_.sweeps >= 0, "mesh motion: sweeps must be >= 0, got " << options_.sweeps);
  MFSI_CHECK(options_.retries >= 0, "mesh motion: retries must be >= 0, got " << options_.retries);
  const lid_t nn = mesh.nNodes();
  fixed_ = boundaryNodes(mesh);
  graph_ = SmoothingGraph{mesh.nodeNodeOffsets(), mesh.nodeNodes(), fixed_, {}};
  stiff_ = graph_;
  stiff_.weights = inverseSquareEdgeWeights(mesh);
  d_ = Real3View("mfsi::coupling::motion::displacement", nn);
  work_ = Real3View("mfsi::coupling::motion::work", nn);
  start_ = Real3View("mfsi::coupling::motion::start", nn);
  good_ = Real3View("mfsi::coupling::motion::accepted", nn);
  Kokkos::fence();
}

void MeshSmoother::place(const ExecSpace& exec, const ConstReal3View& d) const {
  const Real3View x = mesh_.points();
  const ConstReal3View X0 = mesh_.referencePoints();
  Kokkos::parallel_for(
      "mfsi::coupling::motion::place", RangePolicy(exec, 0, mesh_.nNodes()), KOKKOS_LAMBDA(lid_t i) {
        for (int c = 0; c < 3; ++c) x(i, c) = X0(i, c) + d(i, c);
      });
}

MotionReport MeshSmoother::move(const ExecSpace& exec, MeshGeometry& geo) {
  ScopedRegion region("mfsi::coupling::motion");
  Kokkos::deep_copy(exec, start_, d_);  // prescribed values + the warm start
  MotionReport rep;
  for (int attempt = 0; attempt <= options_.retries; ++attempt) {
    const bool stiff = attempt > 0 && attempt == options_.retries;
    const int sweeps = stiff ? options_.sweeps << (attempt - 1) : options_.sweeps << attempt;
    if (attempt > 0) Kokkos::deep_copy(exec, d_, start_);
    jacobiSmooth(exec, stiff ? stiff_ : graph_, d_, work_, sweeps);
    place(exec, d_);
    computeGeometry(exec, mesh_, geo);
    const MeshQuality q = computeQuality(exec, mesh_, geo);
    rep = MotionReport{sweeps, attempt, stiff, q.minScaledJacobian};
    if (q.minScaledJacobian >= options_.minScaledJacobian) break;
  }
  if (!(rep.minScaledJacobian > 0)) {
    Kokkos::deep_copy(exec, d_, good_);
    place(exec, d_);
    computeGeometry(exec, mesh_, geo);
    exec.fence();
    std::ostringstream os;
    os << "mesh motion inverts a cell (minimum scaled Jacobian " << rep.minScaledJacobian << " after "
       << rep.retries << " retries, up to " << rep.sweeps
       << " sweeps and the stiffened smoother); the mesh is left at the last accepted motion";
    throw DivergenceError(os.str());
  }
  Kokkos::deep_copy(exec, good_, d_);
  return rep;
}

}  // namespace mfsi::coupling
