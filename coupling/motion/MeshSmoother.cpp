#include "coupling/motion/MeshSmoother.hpp"

#include "core/Error.hpp"
#include "core/PointTree.hpp"
#include "core/parallel/SharedNodes.hpp"
#include "coupling/motion/MeshColumns.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <vector>

namespace mfsi::coupling {

namespace {

// The constructor's kernels are free functions: nvcc takes no device lambda in a constructor.

/// Which nodes the smoother may move, on the host: fixed[i] = 1 for every node of a boundary face,
/// except faces of empty patches (the front and back of a one-cell-thick 2D mesh: their nodes
/// follow the in-plane motion; a displacement with no out-of-plane part prescribed anywhere keeps
/// none after smoothing, exactly) and faces of sliding patches: a node all of whose other boundary
/// faces are on sliding patches and share one plane slides in that plane (its unit normal), a node
/// where sliding planes meet at an angle or a non-sliding face touches is fixed. On a rank's part
/// (`part`) the faces towards other ranks' cells are not the mesh's boundary.
struct NodeRoles {
  std::vector<std::uint8_t> fixed, slides;
  std::vector<std::array<double, 3>> normal;

  /// A sliding face's unit normal `n` at node v.
  void slide(lid_t v, const double* n) {
    if (!slides[v]) {
      for (int c = 0; c < 3; ++c) normal[v][c] = n[c];
      slides[v] = 1;
    } else if (std::abs(normal[v][0] * n[0] + normal[v][1] * n[1] + normal[v][2] * n[2]) < 1 - 1e-9) {
      fixed[v] = 1;  // a corner of sliding planes
    }
  }
};

NodeRoles boundaryRoles(const HexMesh& mesh, const std::vector<std::string>& sliding, bool part) {
  const lid_t nn = mesh.nNodes();
  const int np = static_cast<int>(mesh.patches().size());
  std::vector<int> role(np, 1);  // 0: empty, 1: prescribes, 2: slides
  for (int p = 0; p < np; ++p) {
    const Patch& pt = mesh.patches()[p];
    if (pt.kind == PatchKind::Empty || (part && pt.name == kProcessorPatch)) role[p] = 0;
    for (const auto& s : sliding)
      if (s == pt.name) role[p] = 2;
  }
  for (const auto& s : sliding)
    MFSI_CHECK(mesh.findPatch(s) >= 0, "mesh motion: no patch '" << s << "' to slide along");
  auto fn = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceNodes());
  auto fp = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.facePatch());
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.referencePoints());
  NodeRoles roles;
  roles.fixed.assign(nn, 0);
  roles.slides.assign(nn, 0);
  roles.normal.assign(nn, {0, 0, 0});
  for (lid_t f = mesh.nInternalFaces(); f < mesh.nFaces(); ++f) {
    const int r = fp(f) < 0 ? 1 : role[fp(f)];
    if (r == 0) continue;
    if (r == 1) {
      for (int k = 0; k < 4; ++k) roles.fixed[fn(f, k)] = 1;
      continue;
    }
    // Unit normal of the face from its diagonals.
    double d1[3], d2[3], n[3];
    for (int c = 0; c < 3; ++c) {
      d1[c] = x(fn(f, 2), c) - x(fn(f, 0), c);
      d2[c] = x(fn(f, 3), c) - x(fn(f, 1), c);
    }
    n[0] = d1[1] * d2[2] - d1[2] * d2[1];
    n[1] = d1[2] * d2[0] - d1[0] * d2[2];
    n[2] = d1[0] * d2[1] - d1[1] * d2[0];
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int c = 0; c < 3; ++c) n[c] /= len;
    for (int k = 0; k < 4; ++k) roles.slide(fn(f, k), n);
  }
  return roles;
}

/// The roles on a rank's part made the mesh's: a node's copies on other ranks may see boundary
/// faces this rank does not hold (in cells that meet its cells at that node alone). Each copy's
/// roles are folded into the owner's as its faces would be, and the owner's copied back.
void shareRoles(const RankDomain& domain, NodeRoles& roles) {
  const lid_t nn = domain.nodes.nLocal;
  std::vector<double> packed(static_cast<std::size_t>(nn) * 5);
  for (lid_t i = 0; i < nn; ++i) {
    double* p = &packed[static_cast<std::size_t>(i) * 5];
    p[0] = roles.fixed[i];
    p[1] = roles.slides[i];
    for (int c = 0; c < 3; ++c) p[2 + c] = roles.normal[i][c];
  }
  foldGhostsIntoOwners(domain.comm, domain.nodes, 5, packed, [&roles](lid_t i, const double* copy) {
    if (copy[0] != 0) roles.fixed[i] = 1;
    if (copy[1] != 0) roles.slide(i, copy + 2);
  });
  for (lid_t i = 0; i < domain.nodes.nOwned; ++i) {
    double* p = &packed[static_cast<std::size_t>(i) * 5];
    p[0] = roles.fixed[i];
    p[1] = roles.slides[i];
    for (int c = 0; c < 3; ++c) p[2 + c] = roles.normal[i][c];
  }
  copyOwnersToGhosts(domain.comm, domain.nodes, 5, packed);
  for (lid_t i = domain.nodes.nOwned; i < nn; ++i) {
    const double* p = &packed[static_cast<std::size_t>(i) * 5];
    roles.fixed[i] = p[0] != 0;
    roles.slides[i] = p[1] != 0;
    for (int c = 0; c < 3; ++c) roles.normal[i][c] = p[2 + c];
  }
}

/// The prescribed flags on the device, and the slide normals (empty when no node slides).
Kokkos::View<std::uint8_t*, MemSpace> deviceRoles(const NodeRoles& roles, Real3View& slide) {
  const lid_t nn = static_cast<lid_t>(roles.fixed.size());
  Kokkos::View<std::uint8_t*, MemSpace> fixed("mfsi::coupling::motion::prescribed", nn);
  auto hf = Kokkos::create_mirror_view(fixed);
  bool any = false;
  for (lid_t i = 0; i < nn; ++i) {
    hf(i) = roles.fixed[i];
    any = any || (roles.slides[i] && !roles.fixed[i]);
  }
  Kokkos::deep_copy(fixed, hf);
  slide = Real3View();
  if (any) {
    slide = Real3View("mfsi::coupling::motion::slideNormal", nn);
    auto hs = Kokkos::create_mirror_view(slide);
    for (lid_t i = 0; i < nn; ++i)
      for (int c = 0; c < 3; ++c) hs(i, c) = roles.slides[i] && !roles.fixed[i] ? roles.normal[i][c] : 0.0;
    Kokkos::deep_copy(slide, hs);
  }
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
    : MeshSmoother(mesh, options, RankDomain{}) {}

MeshSmoother::MeshSmoother(const HexMesh& mesh, const MeshSmootherOptions& options, const RankDomain& domain)
    : mesh_(mesh), options_(options) {
  MFSI_CHECK(options_.sweeps >= 0, "mesh motion: sweeps must be >= 0, got " << options_.sweeps);
  MFSI_CHECK(options_.retries >= 0, "mesh motion: retries must be >= 0, got " << options_.retries);
  const lid_t nn = mesh.nNodes();
  NodeRoles roles = boundaryRoles(mesh, options_.slidingPatches, domain.distributed());
  if (domain.distributed()) {
    long long bad = domain.incompleteNode;  // every rank stops together
    MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_LONG_LONG, MPI_MAX, domain.comm);
    if (bad >= 0)
      throw InputError("mesh motion on several ranks: node " + std::to_string(bad) +
                       " has edges in cells its rank does not hold (cells that meet the rank's cells at a node "
                       "alone); run the scene on one rank");
    MFSI_CHECK(domain.nodes.nLocal == nn,
               "mesh motion: a node plan of " << domain.nodes.nLocal << " nodes for a part of " << nn);
    shareRoles(domain, roles);
    nodeHalo_ = std::make_unique<Halo>(domain.comm, domain.nodes);
    nodePlan_ = domain.nodes;
    nodeComm_ = domain.comm;
    comm_ = SolverComm(domain.comm, nodeHalo_.get());
  }
  fixed_ = deviceRoles(roles, slide_);
  graph_.offsets = mesh.nodeNodeOffsets();
  graph_.neighbours = mesh.nodeNodes();
  graph_.fixed = fixed_;
  graph_.slideNormal = slide_;
  if (domain.distributed()) {
    graph_.owned = mesh.nOwnedNodes();
    graph_.comm = comm_;
  }
  stiff_ = graph_;
  stiff_.weights = inverseSquareEdgeWeights(mesh);
  d_ = Real3View("mfsi::coupling::motion::displacement", nn);
  work_ = Real3View("mfsi::coupling::motion::work", nn);
  start_ = Real3View("mfsi::coupling::motion::start", nn);
  good_ = Real3View("mfsi::coupling::motion::accepted", nn);
  Kokkos::fence();
}

void MeshSmoother::setMovingNodes(const std::vector<std::array<real, 3>>& points) {
  const double q = options_.distanceExponent;
  if (!(q > 0) || points.empty()) return;
  // Host, once: the distance of every edge midpoint from the nearest moving node (a k-d tree of the
  // moving nodes), floored at the edge's own length.
  const PointTree tree(points);
  auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.nodeNodeOffsets());
  auto nb = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.nodeNodes());
  auto X = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.referencePoints());
  auto w = Kokkos::create_mirror_view_and_copy(HostSpace(), stiff_.weights);
  RealView scaled("mfsi::coupling::motion::distanceWeights", w.extent(0));
  auto h = Kokkos::create_mirror_view(scaled);
  for (lid_t i = 0; i < mesh_.nNodes(); ++i)
    for (lid_t k = off(i); k < off(i + 1); ++k) {
      const lid_t j = nb(k);
      std::array<real, 3> m;
      double len2 = 0;
      for (int c = 0; c < 3; ++c) {
        m[c] = 0.5 * (X(i, c) + X(j, c));
        len2 += (X(i, c) - X(j, c)) * (X(i, c) - X(j, c));
      }
      const double d = std::sqrt(std::max(tree.nearestSquaredDistance(m), len2));
      h(k) = w(k) / std::pow(d, q);
    }
  Kokkos::deep_copy(scaled, h);
  stiff_.weights = scaled;
  cg_ = LaplacianCgWork{};  // the AMG is set up again on the new weights
}

lid_t MeshSmoother::setColumnFeet(const std::vector<gid_t>& feet) {
  if (!options_.columns || feet.empty()) return 0;
  auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.nodeNodeOffsets());
  auto nb = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.nodeNodes());
  auto X = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.referencePoints());
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.nodeGlobalIds());
  auto fixed = Kokkos::create_mirror_view_and_copy(HostSpace(), fixed_);
  const lid_t nn = mesh_.nNodes();
  ColumnGraph g;
  g.offsets.assign(off.data(), off.data() + nn + 1);
  g.neighbours.assign(nb.data(), nb.data() + off(nn));
  g.points.resize(3 * static_cast<std::size_t>(nn));
  g.fixed.resize(static_cast<std::size_t>(nn));
  g.sliding.assign(static_cast<std::size_t>(nn), 0);
  g.gid.resize(static_cast<std::size_t>(nn));
  for (lid_t i = 0; i < nn; ++i) {
    for (int c = 0; c < 3; ++c) g.points[3 * i + c] = X(i, c);
    g.fixed[i] = fixed(i) != 0 ? 1 : 0;
    g.gid[i] = gid(i);
  }
  if (slide_.extent(0) > 0) {
    auto sl = Kokkos::create_mirror_view_and_copy(HostSpace(), slide_);
    for (lid_t i = 0; i < nn; ++i) g.sliding[i] = (sl(i, 0) != 0 || sl(i, 1) != 0 || sl(i, 2) != 0) ? 1 : 0;
  }
  g.nOwned = nodeHalo_ ? nodePlan_.nOwned : nn;
  if (nodeHalo_) {
    g.comm = nodeComm_;
    g.ghostOwner.resize(static_cast<std::size_t>(nn - g.nOwned));
    for (std::size_t k = 0; k < nodePlan_.neighbours.size(); ++k)
      for (lid_t i = nodePlan_.recvOffsets[k]; i < nodePlan_.recvOffsets[k + 1]; ++i)
        g.ghostOwner[i] = nodePlan_.neighbours[k];
  }
  const ColumnSet set = findColumns(g, feet);
  // Each copy of a column node knows its foot and factor: the owner's, copied to the ghosts.
  std::vector<double> column(2 * static_cast<std::size_t>(nn), -1.0);
  for (std::size_t k = 0; k < set.node.size(); ++k) {
    column[2 * set.node[k]] = set.foot[k];
    column[2 * set.node[k] + 1] = set.weight[k];
  }
  if (nodeHalo_) copyOwnersToGhosts(nodeComm_, nodePlan_, 2, column);
  std::vector<lid_t> hNode, hFoot;
  std::vector<real> hWeight;
  for (lid_t i = 0; i < nn; ++i) {
    if (column[2 * i] < 0) continue;
    hNode.push_back(i);
    hFoot.push_back(static_cast<lid_t>(column[2 * i]));
    hWeight.push_back(column[2 * i + 1]);
    fixed(i) = 1;
  }
  columns_.node = toDevice(hNode, "mfsi::coupling::motion::columnNode");
  columns_.foot = toDevice(hFoot, "mfsi::coupling::motion::columnFoot");
  columns_.weight = toDevice(hWeight, "mfsi::coupling::motion::columnWeight");
  columns_.feet = Real3View("mfsi::coupling::motion::columnFeet", feet.size());
  columns_.acrossRanks = set.acrossRanks;
  Kokkos::deep_copy(fixed_, fixed);
  cg_ = LaplacianCgWork{};  // the AMG is set up again without the column nodes
  return set.count;
}

void MeshSmoother::applyColumns(const ExecSpace& exec) const {
  const IndexView node = columns_.node, foot = columns_.foot;
  const RealView w = columns_.weight;
  const Real3View d = d_;
  const ConstReal3View feet = columns_.feet;
  Kokkos::parallel_for(
      "mfsi::coupling::motion::columns", RangePolicy(exec, 0, static_cast<lid_t>(node.extent(0))),
      KOKKOS_LAMBDA(lid_t i) {
        for (int c = 0; c < 3; ++c) d(node(i), c) = w(i) * feet(foot(i), c);
      });
}

void MeshSmoother::place(const ExecSpace& exec, const ConstReal3View& d) const {
  const Real3View x = mesh_.points();
  const ConstReal3View X0 = mesh_.referencePoints();
  Kokkos::parallel_for(
      "mfsi::coupling::motion::place", RangePolicy(exec, 0, mesh_.nNodes()), KOKKOS_LAMBDA(lid_t i) {
        for (int c = 0; c < 3; ++c) x(i, c) = X0(i, c) + d(i, c);
      });
}

namespace {
/// d += sign * base on every node.
void addBase(const ExecSpace& exec, const Real3View& d, const ConstReal3View& base, real sign) {
  Kokkos::parallel_for(
      "mfsi::coupling::motion::addBase", RangePolicy(exec, 0, static_cast<lid_t>(d.extent(0))),
      KOKKOS_LAMBDA(lid_t i) {
        for (int c = 0; c < 3; ++c) d(i, c) += sign * base(i, c);
      });
}
}  // namespace

void MeshSmoother::subtractBase(const ExecSpace& exec) const {
  // Prescribed values less the base; the free nodes' warm start is the last motion's remainder:
  // d - last base (their d holds the last total), and on a sliding node only its tangential part,
  // its normal component being data (total zero).
  const Real3View d = d_;
  const ConstReal3View base = base_, last = lastBase_, sn = slide_;
  const auto fixed = fixed_;
  const bool sliding = sn.extent(0) > 0;
  Kokkos::parallel_for(
      "mfsi::coupling::motion::subtractBase", RangePolicy(exec, 0, static_cast<lid_t>(d.extent(0))),
      KOKKOS_LAMBDA(lid_t i) {
        real delta[3] = {0, 0, 0};
        if (fixed(i) == 0) {
          for (int c = 0; c < 3; ++c) delta[c] = base(i, c) - last(i, c);
          if (sliding) {
            const real dn = delta[0] * sn(i, 0) + delta[1] * sn(i, 1) + delta[2] * sn(i, 2);
            for (int c = 0; c < 3; ++c) delta[c] -= dn * sn(i, c);
          }
        }
        for (int c = 0; c < 3; ++c) d(i, c) += delta[c] - base(i, c);
      });
}

MotionReport MeshSmoother::move(const ExecSpace& exec) {
  ScopedRegion region("mfsi::coupling::motion");
  if (columns_.node.extent(0) > 0) applyColumns(exec);
  const bool based = base_.extent(0) > 0;
  // The Laplacian smooths what the base leaves: d - base (the interior's warm start too).
  if (based) {
    if (lastBase_.extent(0) != base_.extent(0)) lastBase_ = Real3View("mfsi::coupling::motion::lastBase", base_.extent(0));
    subtractBase(exec);
  }
  Kokkos::deep_copy(exec, start_, d_);  // prescribed values + the warm start
  MotionReport rep;
  auto measure = [&](int sweeps, int attempt, bool stiff) {
    if (based) {
      Kokkos::deep_copy(exec, work_, d_);
      addBase(exec, work_, base_, 1);
    }
    place(exec, based ? work_ : d_);
    rep = MotionReport{sweeps, attempt, stiff, -comm_.globalMax(-minScaledJacobian(exec, mesh_))};
  };
  if (options_.method == MeshMotionMethod::ConjugateGradient) {
    // Solved once, on the 1/L^2-weighted graph: on a graded mesh the plain graph Laplacian is
    // harmonic in index space and crushes the thin cells, the weighted one approximates the
    // Laplacian of the geometry. A converged solve gains nothing from a retry.
    LaplacianCgOptions o;
    o.relTol = options_.relTol;
    // The previous coupling iteration's motion is an excellent start: tolerance on the field's
    // scale, so a motion that hardly changed costs a few iterations (tube: 1.9 per motion instead
    // of 22; the flexible cavity's curve the same to 1.4e-5).
    o.fieldScaled = true;
    o.maxIterations = options_.maxIterations;
    o.preconditioner = options_.preconditioner;
    measure(laplacianCg(exec, stiff_, d_, cg_, o).iterations, 0, true);
  } else {
    for (int attempt = 0; attempt <= options_.retries; ++attempt) {
      const bool stiff = attempt > 0 && attempt == options_.retries;
      const int sweeps = stiff ? options_.sweeps << (attempt - 1) : options_.sweeps << attempt;
      if (attempt > 0) Kokkos::deep_copy(exec, d_, start_);
      jacobiSmooth(exec, stiff ? stiff_ : graph_, d_, work_, sweeps);
      measure(sweeps, attempt, stiff);
      if (rep.minScaledJacobian >= options_.minScaledJacobian) break;
    }
  }
  if (based) addBase(exec, d_, base_, 1);
  if (!(rep.minScaledJacobian > 0)) {
    Kokkos::deep_copy(exec, d_, good_);
    place(exec, d_);
    exec.fence();
    std::ostringstream os;
    os << "mesh motion inverts a cell (minimum scaled Jacobian " << rep.minScaledJacobian << " after "
       << rep.retries << " retries, up to " << rep.sweeps
       << " sweeps and the stiffened smoother); the mesh is left at the last accepted motion";
    throw DivergenceError(os.str());
  }
  Kokkos::deep_copy(exec, good_, d_);
  if (based) Kokkos::deep_copy(exec, lastBase_, base_);
  return rep;
}

void MeshSmoother::saveState(io::StateWriter& w) const {
  w.putView("displacement", d_, io::Entity::Nodes);
  w.putView("accepted", good_, io::Entity::Nodes);
  // The next motion's warm start.
  if (lastBase_.extent(0) > 0) w.putView("lastBase", lastBase_, io::Entity::Nodes);
}

void MeshSmoother::loadState(const io::StateReader& r) {
  r.getView("displacement", d_);
  r.getView("accepted", good_);
  if (r.has("lastBase")) {
    lastBase_ = Real3View("mfsi::coupling::motion::lastBase", d_.extent(0));
    r.getView("lastBase", lastBase_);
  }
}

}  // namespace mfsi::coupling
