#include "structure/membrane/MembraneSolver.hpp"

#include "core/Error.hpp"
#include "core/Timers.hpp"

#include <algorithm>
#include <cmath>

namespace mfsi {

namespace {

real dist(const std::array<real, 3>& a, const std::array<real, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

}  // namespace

std::vector<MembraneNodeSpring> makeAnchorSprings(const MembraneMesh& mesh, const std::vector<lid_t>& nodes,
                                                  real stiffness) {
  std::vector<MembraneNodeSpring> out;
  for (lid_t n : nodes) out.push_back({n, mesh.hostPoints().at(n), stiffness, 0});
  return out;
}

// ---------------------------------------------------------------------------------------------
// Set-up
// ---------------------------------------------------------------------------------------------

MembraneSolver::MembraneSolver(const MembraneMesh& mesh, const MembraneOptions& options,
                               const MembraneBoundary& boundary, const MembraneLoads& loads)
    : mesh_(mesh), options_(options), boundary_(boundary), loads_(loads) {
  validate(options_.material);
  MFSI_CHECK(options_.tolerance > 0, "membrane: tolerance must be > 0");
  MFSI_CHECK(options_.loadSteps >= 1, "membrane: loadSteps must be >= 1");
  MFSI_CHECK(options_.lumped.limiterFraction > 0 && options_.newton.limiterFraction > 0,
             "membrane: limiter fractions must be > 0");
  MFSI_CHECK(options_.wrinklingStiffnessFraction >= 0, "membrane: wrinklingStiffnessFraction must be >= 0");
  const auto& dyn = options_.dynamics;
  MFSI_CHECK(dyn.rhoInfinity >= 0 && dyn.rhoInfinity <= 1, "membrane dynamics: rhoInfinity must be in [0, 1]");
  MFSI_CHECK(dyn.beta > 0 && dyn.gamma >= 0.5, "membrane dynamics: need beta > 0 and gamma >= 1/2");
  lchar_ = options_.characteristicLength > 0 ? options_.characteristicLength : std::sqrt(mesh_.referenceArea());

  geometry_ = computeMembraneReferenceGeometry(exec_, mesh_);
  data_ = makeMembraneElementData(mesh_, geometry_, options_);
  const lid_t n3 = 3 * mesh_.nNodes();
  u_ = RealView("mfsi::structure::membrane::u", n3);
  v_ = RealView("mfsi::structure::membrane::v", n3);
  a_ = RealView("mfsi::structure::membrane::a", n3);
  R_ = RealView("mfsi::structure::membrane::residual", n3);
  Fext_ = RealView("mfsi::structure::membrane::externalForce", n3);
  du_ = RealView("mfsi::structure::membrane::du", n3);
  uTrial_ = RealView("mfsi::structure::membrane::uTrial", n3);
  work_ = RealView("mfsi::structure::membrane::work", n3);
  work2_ = RealView("mfsi::structure::membrane::work2", n3);
  rn_ = RealView("mfsi::structure::membrane::residualPrevious", n3);
  pNode_ = RealView("mfsi::structure::membrane::nodePressure", mesh_.nNodes());
  a1_ = RealView("mfsi::structure::membrane::a1", n3);
  v1_ = RealView("mfsi::structure::membrane::v1", n3);
  rhs_ = RealView("mfsi::structure::membrane::dynamicResidual", n3);
  dampingForce_ = RealView("mfsi::structure::membrane::dampingForce", n3);
  volumeGrad_ = RealView("mfsi::structure::membrane::volumeGradient", n3);
  volumeDu_ = RealView("mfsi::structure::membrane::volumeDu", n3);
  lineStart_ = RealView("mfsi::structure::membrane::lineStart", n3);
  setupItems();
  setupConstraints();
  setupClamps();
}

void MembraneSolver::setupItems() {
  const lid_t nN = mesh_.nNodes();
  std::vector<std::array<lid_t, 4>> items = mesh_.hostElements();
  auto checkNode = [&](lid_t n, const char* what) {
    MFSI_CHECK(n >= 0 && n < nN, "membrane boundary: " << what << " node " << n << " out of range [0, " << nN << ")");
  };
  const auto& beams = boundary_.edgeBeams;
  std::vector<MembraneNodeSpring> springs = boundary_.edgeSprings;
  springs.insert(springs.end(), boundary_.cornerSprings.begin(), boundary_.cornerSprings.end());
  const lid_t nB = static_cast<lid_t>(beams.size()), nS = static_cast<lid_t>(springs.size());
  lines_.barNodes = Kokkos::View<lid_t* [2], MemSpace>("mfsi::structure::membrane::barNodes", nB);
  lines_.barEA = RealView("mfsi::structure::membrane::barEA", nB);
  lines_.barLength = RealView("mfsi::structure::membrane::barLength", nB);
  lines_.barTensionOnly = Kokkos::View<int*, MemSpace>("mfsi::structure::membrane::barTensionOnly", nB);
  lines_.springNode = IndexView("mfsi::structure::membrane::springNode", nS);
  lines_.springAnchor = Real3View("mfsi::structure::membrane::springAnchor", nS);
  lines_.springStiffness = RealView("mfsi::structure::membrane::springStiffness", nS);
  lines_.springRestLength = RealView("mfsi::structure::membrane::springRestLength", nS);
  auto hbn = Kokkos::create_mirror_view(lines_.barNodes);
  auto hbe = Kokkos::create_mirror_view(lines_.barEA);
  auto hbl = Kokkos::create_mirror_view(lines_.barLength);
  auto hbt = Kokkos::create_mirror_view(lines_.barTensionOnly);
  for (lid_t i = 0; i < nB; ++i) {
    const auto& b = beams[i];
    checkNode(b.node0, "edge beam");
    checkNode(b.node1, "edge beam");
    MFSI_CHECK(b.node0 != b.node1 && b.axialStiffness >= 0, "membrane edge beam " << i << ": needs two distinct nodes "
                                                                                 << "and EA >= 0");
    hbn(i, 0) = b.node0;
    hbn(i, 1) = b.node1;
    hbe(i) = b.axialStiffness;
    hbl(i) = dist(mesh_.hostPoints()[b.node0], mesh_.hostPoints()[b.node1]);
    hbt(i) = b.tensionOnly ? 1 : 0;
    items.push_back({b.node0, b.node1, -1, -1});
  }
  auto hsn = Kokkos::create_mirror_view(lines_.springNode);
  auto hsa = Kokkos::create_mirror_view(lines_.springAnchor);
  auto hsk = Kokkos::create_mirror_view(lines_.springStiffness);
  auto hsl = Kokkos::create_mirror_view(lines_.springRestLength);
  for (lid_t i = 0; i < nS; ++i) {
    const auto& s = springs[i];
    checkNode(s.node, "spring");
    MFSI_CHECK(s.stiffness >= 0, "membrane spring " << i << ": stiffness must be >= 0");
    hsn(i) = s.node;
    for (int k = 0; k < 3; ++k) hsa(i, k) = s.anchor[k];
    hsk(i) = s.stiffness;
    hsl(i) = s.restLength >= 0 ? s.restLength : dist(mesh_.hostPoints()[s.node], s.anchor);
    items.push_back({s.node, -1, -1, -1});
  }
  Kokkos::deep_copy(lines_.barNodes, hbn);
  Kokkos::deep_copy(lines_.barEA, hbe);
  Kokkos::deep_copy(lines_.barLength, hbl);
  Kokkos::deep_copy(lines_.barTensionOnly, hbt);
  Kokkos::deep_copy(lines_.springNode, hsn);
  Kokkos::deep_copy(lines_.springAnchor, hsa);
  Kokkos::deep_copy(lines_.springStiffness, hsk);
  Kokkos::deep_copy(lines_.springRestLength, hsl);

  if (options_.material.bending) {
    hinges_ = buildMembraneHinges(mesh_, plateBendingStiffness(options_.material));
    hingeItem0_ = static_cast<lid_t>(items.size());
    items.insert(items.end(), hinges_.hostNodes.begin(), hinges_.hostNodes.end());
  }
  nItems_ = static_cast<lid_t>(items.size());
  map_ = buildCsrAssemblyMap(items, nN, 3, "mfsi::structure::membrane::assembly");
  K_ = makeMatrix(map_, "mfsi::structure::membrane::tangent");
  itemVec_ = ItemValuesView("mfsi::structure::membrane::itemResidual", nItems_, kMembraneItemDofs);
  itemExt_ = ItemValuesView("mfsi::structure::membrane::itemExternal", nItems_, kMembraneItemDofs);
  itemMat_ = ItemValuesView("mfsi::structure::membrane::itemMatrix", nItems_, kMembraneItemMatrix);
}

void MembraneSolver::setupConstraints() {
  const lid_t nN = mesh_.nNodes();
  constraints_.kind = Kokkos::View<int*, MemSpace>("mfsi::structure::membrane::constraintKind", nN);
  constraints_.direction = Real3View("mfsi::structure::membrane::constraintDirection", nN);
  auto hk = Kokkos::create_mirror_view(constraints_.kind);
  auto hd = Kokkos::create_mirror_view(constraints_.direction);
  const auto& pn = boundary_.motionPlaneNormal;
  const real pnLen = std::sqrt(pn[0] * pn[0] + pn[1] * pn[1] + pn[2] * pn[2]);
  MFSI_CHECK(std::isfinite(pnLen), "membrane boundary: motion plane normal is not finite");
  for (lid_t n = 0; n < nN; ++n) {
    hk(n) = static_cast<int>(pnLen > 0 ? MembraneNodeConstraint::Plane : MembraneNodeConstraint::Free);
    for (int k = 0; k < 3; ++k) hd(n, k) = pnLen > 0 ? pn[k] / pnLen : 0.0;
  }
  const auto& normals = mesh_.hostNodeNormals();
  for (lid_t n : boundary_.normalNodes) {
    MFSI_CHECK(n >= 0 && n < nN, "membrane boundary: normal-constrained node " << n << " out of range");
    hk(n) = static_cast<int>(MembraneNodeConstraint::Direction);
    for (int k = 0; k < 3; ++k) hd(n, k) = normals[n][k];
  }
  for (const auto& c : boundary_.clamps) {
    MFSI_CHECK(c.offsets.empty() || c.offsets.size() == c.nodes.size(),
               "membrane clamp: offsets must be empty or one per node");
    for (lid_t n : c.nodes) {
      MFSI_CHECK(n >= 0 && n < nN, "membrane boundary: clamped node " << n << " out of range");
      hk(n) = static_cast<int>(MembraneNodeConstraint::Fixed);  // clamps win over normal constraints
    }
  }
  Kokkos::deep_copy(constraints_.kind, hk);
  Kokkos::deep_copy(constraints_.direction, hd);

  // Sign of the pressure offset: + where the reference normal points away from insidePoint.
  offsetSign_ = RealView("mfsi::structure::membrane::offsetSign", nN);
  auto hs = Kokkos::create_mirror_view(offsetSign_);
  for (lid_t n = 0; n < nN; ++n) {
    real s = 0;
    for (int k = 0; k < 3; ++k) s += (mesh_.hostPoints()[n][k] - loads_.insidePoint[k]) * normals[n][k];
    hs(n) = s >= 0 ? 1.0 : -1.0;
  }
  Kokkos::deep_copy(offsetSign_, hs);
}

void MembraneSolver::setupClamps() {
  for (std::size_t g = 0; g < boundary_.clamps.size(); ++g)
    for (lid_t n : boundary_.clamps[g].nodes) clampHost_.push_back({static_cast<int>(g), n});
  const lid_t nc = static_cast<lid_t>(clampHost_.size());
  clampNodes_ = IndexView("mfsi::structure::membrane::clampNodes", nc);
  clampTarget_ = Kokkos::View<real* [3], MemSpace>("mfsi::structure::membrane::clampTarget", nc);
  clampStart_ = Kokkos::View<real* [3], MemSpace>("mfsi::structure::membrane::clampStart", nc);
  auto h = Kokkos::create_mirror_view(clampNodes_);
  for (lid_t i = 0; i < nc; ++i) h(i) = clampHost_[i].second;
  Kokkos::deep_copy(clampNodes_, h);
}

// ---------------------------------------------------------------------------------------------
// Loads, clamps, residual, tangent
// ---------------------------------------------------------------------------------------------

void MembraneSolver::clampTargets(real time) {
  auto h = Kokkos::create_mirror_view(clampTarget_);
  std::vector<std::size_t> index(boundary_.clamps.size(), 0);
  std::vector<RigidPlacement> frames(boundary_.clamps.size());
  for (std::size_t g = 0; g < boundary_.clamps.size(); ++g)
    if (boundary_.clamps[g].frame) frames[g] = boundary_.clamps[g].frame(time);
  for (std::size_t i = 0; i < clampHost_.size(); ++i) {
    const auto [g, n] = clampHost_[i];
    const auto& c = boundary_.clamps[g];
    const std::size_t j = index[g]++;
    std::array<real, 3> X = mesh_.hostPoints()[n];
    if (!c.offsets.empty())
      for (int k = 0; k < 3; ++k) X[k] += c.offsets[j][k];
    const std::array<real, 3> x = c.frame ? frames[g].apply(X) : X;
    for (int k = 0; k < 3; ++k) h(i, k) = x[k] - mesh_.hostPoints()[n][k];
  }
  Kokkos::deep_copy(clampTarget_, h);
}

void MembraneSolver::applyClamps(const RealView& u, real weight) {
  auto nodes = clampNodes_;
  auto target = clampTarget_;
  auto start = clampStart_;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::applyClamps", RangePolicy(exec_, 0, static_cast<lid_t>(nodes.extent(0))),
      KOKKOS_LAMBDA(lid_t i) {
        for (int k = 0; k < 3; ++k)
          u(3 * nodes(i) + k) = start(i, k) + weight * (target(i, k) - start(i, k));
      });
}

void MembraneSolver::updatePressure(real time, real loadFactor) {
  // The volume constraint's multiplier is a reaction, not a load: never scaled by a load factor.
  const real uniform = loadFactor * loads_.pressure * (loads_.pressureTime ? loads_.pressureTime(time) : 1.0) +
                       (volume_.active ? volume_.sign * volume_.lambda : 0.0);
  const real ramp = loads_.pressureOffsetRampTime > 0 ? std::min<real>(1, time / loads_.pressureOffsetRampTime) : 1;
  const real offset = loadFactor * loads_.pressureOffset * ramp;
  const bool hasField = loads_.nodePressure.extent(0) > 0;
  MFSI_CHECK(!hasField || static_cast<lid_t>(loads_.nodePressure.extent(0)) == mesh_.nNodes(),
             "membrane loads: nodePressure must have one value per node");
  MFSI_CHECK(loads_.elementPressure.extent(0) == 0 ||
                 static_cast<lid_t>(loads_.elementPressure.extent(0)) == mesh_.nElements(),
             "membrane loads: elementPressure must have one value per element");
  auto p = pNode_;
  auto field = loads_.nodePressure;
  auto sign = offsetSign_;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::nodePressure", RangePolicy(exec_, 0, mesh_.nNodes()), KOKKOS_LAMBDA(lid_t n) {
        p(n) = uniform + (hasField ? loadFactor * field(n) : 0) + sign(n) * offset;
      });
  if (loads_.elementPressure.extent(0) == 0) {
    pElem_ = RealView();
  } else if (loadFactor == 1) {
    pElem_ = loads_.elementPressure;
  } else {
    if (pElemScaled_.extent(0) != loads_.elementPressure.extent(0))
      pElemScaled_ = RealView("mfsi::structure::membrane::elementPressureScaled", loads_.elementPressure.extent(0));
    blas::axpby(exec_, mesh_.nElements(), loadFactor, loads_.elementPressure, 0.0, pElemScaled_);
    pElem_ = pElemScaled_;
  }
}

MembranePressureKernel MembraneSolver::pressureKernel(bool withStiffness) const {
  MembranePressureKernel pr;
  pr.nodePressure = pNode_;
  pr.elementPressure = pElem_;
  pr.follower = loads_.direction == MembranePressureDirection::Follower;
  pr.lumped = loads_.integration == MembranePressureIntegration::Lumped;
  pr.stiffness = withStiffness && options_.newton.pressureStiffness == MembranePressureStiffness::Symmetrized;
  return pr;
}

void MembraneSolver::evalResidual(const ConstRealView& u, real time, real loadFactor) {
  updatePressure(time, loadFactor);
  membraneResidualItems(exec_, data_, pressureKernel(false), lines_, u, itemVec_, itemExt_);
  if (hinges_.size() > 0) membraneHingeResidualItems(exec_, hinges_, data_.X, u, hingeItem0_, itemVec_, itemExt_);
  gatherItemVectors(exec_, map_, itemVec_, R_);
  gatherItemVectors(exec_, map_, itemExt_, Fext_);
  if (loads_.nodeForce.extent(0) > 0) {
    MFSI_CHECK(static_cast<lid_t>(loads_.nodeForce.extent(0)) == mesh_.nNodes(),
               "membrane loads: nodeForce must have one row per node");
    auto f = loads_.nodeForce;
    auto R = R_;
    auto F = Fext_;
    Kokkos::parallel_for(
        "mfsi::structure::membrane::nodeForce", RangePolicy(exec_, 0, mesh_.nNodes()), KOKKOS_LAMBDA(lid_t n) {
          for (int k = 0; k < 3; ++k) {
            R(3 * n + k) += loadFactor * f(n, k);
            F(3 * n + k) += loadFactor * f(n, k);
          }
        });
  }
}

void MembraneSolver::assembleTangentAt(const ConstRealView& u, bool withPressure) {
  membraneTangentItems(exec_, data_, pressureKernel(withPressure), lines_, u, itemMat_);
  if (hinges_.size() > 0) membraneHingeTangentItems(exec_, hinges_, data_.X, u, hingeItem0_, false, itemMat_);
  gatherItemMatrices(exec_, map_, itemMat_, K_);
}

RealView MembraneSolver::residual(real time, real loadFactor) {
  evalResidual(u_, time, loadFactor);
  return R_;
}

const CsrMatrix& MembraneSolver::assembleTangent(real time, bool withPressureStiffness) {
  updatePressure(time, 1);
  assembleTangentAt(u_, withPressureStiffness);
  return K_;
}

const CsrMatrix& MembraneSolver::assembleConsistentMass() {
  if (M_.values.extent(0) == 0) M_ = makeMatrix(map_, "mfsi::structure::membrane::mass");
  membraneMassItems(exec_, data_, nItems_, false, itemMat_);
  gatherItemMatrices(exec_, map_, itemMat_, M_);
  return M_;
}

MembraneSolver::Norms MembraneSolver::norms(const ConstRealView& r) {
  auto kind = constraints_.kind;
  auto dir = constraints_.direction;
  auto F = Fext_;
  const auto s = blas::reduce<3>(exec_, SolverComm{}, "mfsi::structure::membrane::norms", mesh_.nNodes(),
                                 KOKKOS_LAMBDA(lid_t n, blas::Sums<3> & acc) {
                                   real v[3] = {r(3 * n), r(3 * n + 1), r(3 * n + 2)};
                                   const real full = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
                                   membrane::projectNode(kind(n), dir(n, 0), dir(n, 1), dir(n, 2), v);
                                   const real fr = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
                                   acc[0] += fr;
                                   acc[1] += full - fr;
                                   for (int k = 0; k < 3; ++k) acc[2] += F(3 * n + k) * F(3 * n + k);
                                 });
  Norms out;
  out.free = std::sqrt(s[0]);
  out.reaction = std::sqrt(std::max<real>(0, s[1]));
  out.external = std::sqrt(s[2]);
  return out;
}

real MembraneSolver::relativeResidual(const Norms& q, real initialFree) const {
  // The reference force: loads, support reactions, and the out-of-balance force the solve started
  // from. The last one matters when the answer carries no force at all (a slack membrane, a rigid
  // motion): loads and reactions then both tend to zero and their ratio to the residual need not.
  // With tiny loads on a slack membrane (the first steps of an FSI run) every force is far below
  // the round-off of the internal forces, which then sets the floor (residualFloor).
  const real scale = std::max({q.external, q.reaction, initialFree, residualFloor() / options_.tolerance});
  return scale > 0 ? q.free / scale : 0.0;
}

real MembraneSolver::maxNodalNorm(const ConstRealView& d) {
  real m = 0;
  Kokkos::parallel_reduce(
      "mfsi::structure::membrane::maxNodalNorm", RangePolicy(exec_, 0, mesh_.nNodes()),
      KOKKOS_LAMBDA(lid_t n, real & acc) {
        const real s = kmath::sqrt(d(3 * n) * d(3 * n) + d(3 * n + 1) * d(3 * n + 1) + d(3 * n + 2) * d(3 * n + 2));
        if (!(s <= acc)) acc = s;  // NaN propagates
      },
      Kokkos::Max<real>(m));
  return m;
}

real MembraneSolver::enclosedVolumeAt(const ConstRealView& u, const RealView& gradient) {
  const real v = membraneVolumeItems(exec_, data_, nItems_, u, itemVec_);
  gatherItemVectors(exec_, map_, itemVec_, gradient);
  if (volume_.sign != 1) blas::axpby(exec_, 3 * mesh_.nNodes(), volume_.sign, gradient, 0.0, gradient);
  return volume_.sign * v;
}

real MembraneSolver::enclosedVolume(const ConstRealView& u) { return enclosedVolumeAt(u, volumeGrad_); }

real MembraneSolver::volumeTolerance() const { return volume_.tolerance * mesh_.referenceArea() * lchar_; }

real MembraneSolver::projectOntoVolume(const RealView& u) {
  const lid_t n3 = 3 * mesh_.nNodes();
  const real tol = volumeTolerance();
  Kokkos::deep_copy(exec_, volumeDu_, u);
  // Newton on the step length along the projected gradient: V is smooth and the moves are small
  // (a relaxation's second-order volume error), so two or three steps reach round-off.
  for (int it = 0; it < 20; ++it) {
    const real c = enclosedVolumeAt(u, volumeGrad_) - volume_.target;
    if (!std::isfinite(c)) break;
    if (std::abs(c) <= tol) break;
    projectConstraints(exec_, constraints_, volumeGrad_, volumeGrad_);
    const real gg = blas::dot(exec_, SolverComm{}, n3, volumeGrad_, volumeGrad_);
    MFSI_CHECK(gg > 0, "membrane: the enclosed volume does not change with any free node (volume constraint)");
    blas::axpy(exec_, n3, -c / gg, volumeGrad_, u);
  }
  blas::axpy(exec_, n3, -1.0, u, volumeDu_);
  return maxNodalNorm(volumeDu_);
}

// ---------------------------------------------------------------------------------------------
// Statics
// ---------------------------------------------------------------------------------------------

MembraneSolveReport MembraneSolver::solveStatic(real time) {
  ScopedRegion region("mfsi::structure::membrane::static");
  MFSI_CHECK(!volume_.active, "membrane: a volume constraint needs the dynamic step (solveStep), not a static solve");
  const double t0 = wallSeconds();
  time_ = time;
  clampTargets(time);
  // Ramp the clamps from where they are now.
  {
    auto nodes = clampNodes_;
    auto start = clampStart_;
    auto u = u_;
    Kokkos::parallel_for(
        "mfsi::structure::membrane::clampStart", RangePolicy(exec_, 0, static_cast<lid_t>(nodes.extent(0))),
        KOKKOS_LAMBDA(lid_t i) {
          for (int k = 0; k < 3; ++k) start(i, k) = u(3 * nodes(i) + k);
        });
  }
  MembraneSolveReport total;
  total.converged = true;
  for (int s = 1; s <= options_.loadSteps; ++s) {
    const real lambda = static_cast<real>(s) / options_.loadSteps;
    applyClamps(u_, lambda);
    const MembraneSolveReport r = options_.solver == MembraneStaticSolver::Newton ? newtonSolve(time, lambda)
                                                                                  : lumpedSolve(time, lambda);
    total.iterations += r.iterations;
    total.linearIterations += r.linearIterations;
    total.lineSearchSteps += r.lineSearchSteps;
    total.relativeResidual = r.relativeResidual;
    if (!r.converged) {
      total.converged = false;
      break;
    }
  }
  exec_.fence();
  total.seconds = wallSeconds() - t0;
  last_ = total;
  return total;
}

MembraneSolveReport MembraneSolver::newtonSolve(real time, real loadFactor) {
  const auto& opt = options_.newton;
  const lid_t n3 = 3 * mesh_.nNodes();
  MembraneSolveReport rep;
  evalResidual(u_, time, loadFactor);
  Norms nrm = norms(R_);
  const real initialFree = nrm.free;
  auto relative = [&](const Norms& q) { return relativeResidual(q, initialFree); };
  real rel = relative(nrm);
  const real dmax = opt.limiterFraction * lchar_;
  for (int it = 0; it < opt.maxIterations; ++it) {
    rep.relativeResidual = rel;
    if (rel <= options_.tolerance) {
      rep.converged = true;
      return rep;
    }
    if (!std::isfinite(rel)) return rep;
    // Inexact Newton forcing (see MembraneNewtonOptions::cgRelTol).
    const real eta = opt.cgRelTol > 0 ? opt.cgRelTol
                                      : std::min<real>(1e-2, std::max<real>(std::min<real>(rel, 1e-2),
                                                                            0.5 * options_.tolerance / rel));
    assembleTangentAt(u_, true);
    MembraneCgResult cg = cg_.solve(exec_, K_, constraints_, R_, du_, eta, opt.cgMaxIterations);
    rep.linearIterations += cg.iterations;
    if (cg.negativeCurvature) {
      // The load stiffness made the matrix indefinite (far from equilibrium): drop it this step.
      assembleTangentAt(u_, false);
      cg = cg_.solve(exec_, K_, constraints_, R_, du_, eta, opt.cgMaxIterations);
      rep.linearIterations += cg.iterations;
    }
    ++rep.iterations;
    // Limiter: scale the whole step (direction kept) so no node moves more than dmax.
    const real dn = maxNodalNorm(du_);
    if (!std::isfinite(dn) || dn == 0) return rep;
    const real alphaMax = dn > dmax ? dmax / dn : 1.0;
    // Line search on the directional derivative g(alpha) = du . R(u + alpha du) (Crisfield;
    // Matthies & Strang): for a conservative problem g is minus the slope of the potential energy
    // along du, and we look for its root. Unlike a residual-norm backtracking, it also
    // *extrapolates*, which is what a membrane needs: from a flat or slack state the tangent is
    // far too soft (stress ~ deflection^2), the Newton step overshoots by orders of magnitude and
    // the root of g gives the right amplitude in a few residual evaluations. Near the solution
    // g(1) ~ 0 and the full step is taken at the cost of one residual.
    const real g0 = blas::dot(exec_, SolverComm{}, n3, du_, R_);
    real alpha = alphaMax, lo = 0, gLo = g0, hi = -1, gHi = 0;
    real bestAlpha = alpha, bestG = -1;
    int evals = 0;
    for (;;) {
      Kokkos::deep_copy(exec_, uTrial_, u_);
      blas::axpy(exec_, n3, alpha, du_, uTrial_);
      evalResidual(uTrial_, time, loadFactor);
      ++evals;
      const real g = blas::dot(exec_, SolverComm{}, n3, du_, R_);
      if (std::isfinite(g) && (bestG < 0 || std::abs(g) < bestG)) {
        bestG = std::abs(g);
        bestAlpha = alpha;
      }
      // Accept: |g| reduced enough, or no descent information (g0 <= 0: indefinite direction).
      if (!(g0 > 0) || (std::isfinite(g) && std::abs(g) <= 0.5 * g0)) break;
      if (evals > opt.maxLineSearchSteps) {
        if (alpha != bestAlpha) {
          alpha = bestAlpha;
          Kokkos::deep_copy(exec_, uTrial_, u_);
          blas::axpy(exec_, n3, alpha, du_, uTrial_);
          evalResidual(uTrial_, time, loadFactor);
        }
        break;
      }
      ++rep.lineSearchSteps;
      if (std::isfinite(g) && g > 0) {
        // Root beyond alpha.
        if (alpha >= alphaMax) break;  // the limiter forbids going further: take the step
        lo = alpha;
        gLo = g;
        if (hi > 0) {
          alpha = lo + (hi - lo) * gLo / (gLo - gHi);
        } else {
          const real secant = g < g0 ? alpha * g0 / (g0 - g) : 4 * alpha;  // root of the line through (0,g0), (alpha,g)
          alpha = std::min(alphaMax, std::min(secant, 4 * alpha));
        }
      } else {
        // Overshoot (or non-finite): bracket and interpolate (regula falsi, kept off the ends).
        hi = alpha;
        gHi = std::isfinite(g) ? g : -10 * g0;
        const real t = gLo / (gLo - gHi);
        alpha = lo + (hi - lo) * std::min<real>(0.9, std::max<real>(0.1, t));
      }
    }
    nrm = norms(R_);
    Kokkos::deep_copy(exec_, u_, uTrial_);
    rel = relative(nrm);
  }
  rep.relativeResidual = rel;
  rep.converged = rel <= options_.tolerance;
  return rep;
}

MembraneSolveReport MembraneSolver::lumpedSolve(real time, real loadFactor) {
  const auto& opt = options_.lumped;
  MembraneSolveReport rep;
  evalResidual(u_, time, loadFactor);
  Norms nrm = norms(R_);
  const real initialFree = nrm.free;
  auto relative = [&](const Norms& q) { return relativeResidual(q, initialFree); };
  real rel = relative(nrm);
  const real dmax = opt.limiterFraction * lchar_;
  // Bidirectional limiter: every nodal step is clipped to |du| <= cap in any direction, and the
  // cap itself goes both ways: halved when the residual grew, grown back (x 1.2, up to dmax) while
  // it shrinks.
  real cap = dmax;
  const real floorFrac = opt.stiffnessFloor;
  auto kind = constraints_.kind;
  auto dir = constraints_.direction;
  for (int it = 0; it < opt.maxIterations; ++it) {
    rep.relativeResidual = rel;
    if (rel <= options_.tolerance) {
      rep.converged = true;
      return rep;
    }
    if (!std::isfinite(rel)) return rep;
    membraneLumpedStiffnessItems(exec_, data_, lines_, u_, itemVec_);
    if (hinges_.size() > 0) membraneHingeTangentItems(exec_, hinges_, data_.X, u_, hingeItem0_, true, itemVec_);
    gatherItemVectors(exec_, map_, itemVec_, work_);
    auto D = work_;
    auto R = R_;
    auto u = u_;
    const real c = cap;
    Kokkos::parallel_for(
        "mfsi::structure::membrane::lumpedUpdate", RangePolicy(exec_, 0, mesh_.nNodes()), KOKKOS_LAMBDA(lid_t n) {
          const real dm = kmath::fabs(D(3 * n)) > kmath::fabs(D(3 * n + 1))
                              ? (kmath::fabs(D(3 * n)) > kmath::fabs(D(3 * n + 2)) ? D(3 * n) : D(3 * n + 2))
                              : (kmath::fabs(D(3 * n + 1)) > kmath::fabs(D(3 * n + 2)) ? D(3 * n + 1) : D(3 * n + 2));
          const real lo = floorFrac * kmath::fabs(dm);
          real d[3];
          for (int k = 0; k < 3; ++k) {
            const real kk = D(3 * n + k) > lo ? D(3 * n + k) : lo;
            d[k] = kk > 0 ? R(3 * n + k) / kk : 0;
          }
          membrane::projectNode(kind(n), dir(n, 0), dir(n, 1), dir(n, 2), d);
          const real l = kmath::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
          const real s = l > c ? c / l : 1.0;
          for (int k = 0; k < 3; ++k) u(3 * n + k) += s * d[k];
        });
    ++rep.iterations;
    evalResidual(u_, time, loadFactor);
    const Norms next = norms(R_);
    cap = next.free > nrm.free ? std::max<real>(0.5 * cap, 1e-6 * dmax) : std::min<real>(dmax, 1.2 * cap);
    nrm = next;
    rel = relative(nrm);
  }
  rep.relativeResidual = rel;
  rep.converged = rel <= options_.tolerance;
  return rep;
}

// ---------------------------------------------------------------------------------------------
// Dynamics
// ---------------------------------------------------------------------------------------------

MembraneSolver::Integrator MembraneSolver::integrator() const {
  const auto& dyn = options_.dynamics;
  Integrator c;
  c.beta = dyn.beta;
  c.gamma = dyn.gamma;
  if (dyn.integrator == MembraneTimeIntegrator::GeneralizedAlpha) {
    const real rho = dyn.rhoInfinity;
    c.am = (2 * rho - 1) / (rho + 1);
    c.af = rho / (rho + 1);
    c.gamma = 0.5 - c.am + c.af;
    c.beta = 0.25 * (1 - c.am + c.af) * (1 - c.am + c.af);
  }
  return c;
}

void MembraneSolver::trialKinematics() {
  // a1 = (u1 - un - dt vn)/(beta dt^2) - (1/(2 beta) - 1) an ;  v1 = vn + dt((1-gamma) an + gamma a1)
  const Integrator c = integrator();
  const real beta = c.beta, gamma = c.gamma, dt = trial_.dt;
  auto u1 = uTrial_;
  auto un = u_;
  auto vn = v_;
  auto an = a_;
  auto A1 = a1_;
  auto V1 = v1_;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::newmarkKinematics", RangePolicy(exec_, 0, 3 * mesh_.nNodes()),
      KOKKOS_LAMBDA(lid_t i) {
        const real acc = (u1(i) - un(i) - dt * vn(i)) / (beta * dt * dt) - (0.5 / beta - 1) * an(i);
        A1(i) = acc;
        V1(i) = vn(i) + dt * ((1 - gamma) * an(i) + gamma * acc);
      });
}

void MembraneSolver::setTrialDisplacement(const ConstRealView& u1) {
  MFSI_CHECK(trial_.valid, "membrane: setTrialDisplacement before solveStep");
  MFSI_CHECK(static_cast<lid_t>(u1.extent(0)) == 3 * mesh_.nNodes(),
             "membrane: setTrialDisplacement got " << u1.extent(0) << " values for " << 3 * mesh_.nNodes());
  if (u1.data() != uTrial_.data()) Kokkos::deep_copy(exec_, uTrial_, u1);
  trialKinematics();
}

void MembraneSolver::commitStep() {
  MFSI_CHECK(trial_.valid, "membrane: commitStep without a solved step");
  Kokkos::deep_copy(exec_, u_, uTrial_);
  Kokkos::deep_copy(exec_, v_, v1_);
  Kokkos::deep_copy(exec_, a_, a1_);
  time_ += trial_.dt;
  trial_ = {};
  lambdaCommitted_ = volume_.lambda;
  exec_.fence();
}

void MembraneSolver::discardStep() { trial_ = {}; }

void MembraneSolver::adoptStep(real dt, const MembraneSolveReport& report, real lambda) {
  MFSI_CHECK(dt > 0, "membrane: adoptStep needs dt > 0");
  trial_.valid = true;
  trial_.dt = dt;
  haveAcceleration_ = true;  // the owner's, received with the step
  volume_.lambda = lambda;
  last_ = report;
}

void MembraneSolver::adoptStatic(real time, const MembraneSolveReport& report) {
  time_ = time;
  last_ = report;
}

RealView MembraneSolver::nodalMass() {
  if (nodalMass_.extent(0) == static_cast<std::size_t>(mesh_.nNodes())) return nodalMass_;
  const lid_t n = mesh_.nNodes();
  RealView perDof("mfsi::structure::membrane::lumpedPerDof", 3 * n);
  membraneMassItems(exec_, data_, nItems_, true, itemVec_);
  gatherItemVectors(exec_, map_, itemVec_, perDof);
  nodalMass_ = RealView("mfsi::structure::membrane::nodalMass", n);
  auto m = nodalMass_;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::nodalMass", RangePolicy(exec_, 0, n), KOKKOS_LAMBDA(lid_t i) { m(i) = perDof(3 * i); });
  return nodalMass_;
}

void MembraneSolver::setInterfaceMass(real massPerArea) {
  MFSI_CHECK(std::isfinite(massPerArea) && massPerArea >= 0,
             "membrane: the interface mass must be finite and >= 0, got " << massPerArea);
  interfaceMass_ = massPerArea;
  if (massPerArea == 0) return;
  MFSI_CHECK(options_.material.density > 0 && options_.material.thickness > 0,
             "membrane: an interface mass needs density and thickness > 0");
  // The nodal masses rho h A_i per dof, scaled to massPerArea A_i.
  const lid_t n3 = 3 * mesh_.nNodes();
  interfaceNodeMass_ = RealView("mfsi::structure::membrane::interfaceNodeMass", n3);
  anchor_ = RealView("mfsi::structure::membrane::interfaceAnchor", n3);
  auto m = nodalMass();
  auto mi = interfaceNodeMass_;
  const real scale = massPerArea / (options_.material.density * options_.material.thickness);
  Kokkos::parallel_for(
      "mfsi::structure::membrane::interfaceNodeMass", RangePolicy(exec_, 0, n3),
      KOKKOS_LAMBDA(lid_t i) { mi(i) = scale * m(i / 3); });
}

MembraneSolveReport MembraneSolver::step(real dt) {
  const MembraneSolveReport rep = solveStep(dt);
  if (rep.converged) commitStep();
  return rep;
}

MembraneSolveReport MembraneSolver::solveStep(real dt) {
  ScopedRegion region("mfsi::structure::membrane::step");
  MFSI_CHECK(dt > 0, "membrane step: dt must be > 0");
  MFSI_CHECK(options_.material.density > 0, "membrane dynamics needs density > 0");
  const double wall0 = wallSeconds();
  const auto& dyn = options_.dynamics;
  const lid_t n3 = 3 * mesh_.nNodes();
  const bool lumpedMass = dyn.mass == MembraneMassType::Lumped;
  const Integrator ic = integrator();
  const real am = ic.am, af = ic.af, beta = ic.beta, gamma = ic.gamma;
  // A second solve of the same step (an FSI iteration) starts from the last trial state.
  const bool warm = trial_.valid && trial_.dt == dt;
  trial_.valid = true;
  trial_.dt = dt;
  if (!haveMass_) {
    if (lumpedMass) {
      lumpedMass_ = RealView("mfsi::structure::membrane::lumpedMass", n3);
      membraneMassItems(exec_, data_, nItems_, true, itemVec_);
      gatherItemVectors(exec_, map_, itemVec_, lumpedMass_);
    } else {
      assembleConsistentMass();
    }
    Kdamp_ = makeMatrix(map_, "mfsi::structure::membrane::dampingStiffness");
    haveMass_ = true;
  }
  const real ra = dyn.rayleighAlpha, rb = dyn.rayleighBeta;
  auto mass = [&](const ConstRealView& x, const RealView& y) {
    if (lumpedMass) {
      auto m = lumpedMass_;
      Kokkos::parallel_for(
          "mfsi::structure::membrane::lumpedMassApply", RangePolicy(exec_, 0, n3),
          KOKKOS_LAMBDA(lid_t i) { y(i) = m(i) * x(i); });
    } else {
      blas::spmv(exec_, M_, x, y);
    }
  };
  // y = C x = ra M x + rb Kdamp x (y must not alias x).
  auto damping = [&](const ConstRealView& x, const RealView& y) {
    blas::fill(exec_, n3, 0.0, y);
    if (ra != 0) {
      mass(x, work2_);
      blas::axpy(exec_, n3, ra, work2_, y);
    }
    if (rb != 0) blas::spmv(exec_, rb, Kdamp_, x, 1.0, y);
  };

  // Damping stiffness: the tangent at the start of the step (frozen during the step).
  if (rb != 0) {
    updatePressure(time_, 1);
    assembleTangentAt(u_, false);
    Kokkos::deep_copy(exec_, Kdamp_.values, K_.values);
  }
  // Residual at t_n (needed by generalized-alpha) and, the first time, a_n from M a = R - C v.
  // (with the multiplier of t_n: the iterate's own, a warm start, enters only R_{n+1})
  const real lambdaIterate = volume_.lambda;
  volume_.lambda = lambdaCommitted_;
  evalResidual(u_, time_, 1);
  volume_.lambda = lambdaIterate;
  Kokkos::deep_copy(exec_, rn_, R_);
  MembraneSolveReport rep;
  if (!haveAcceleration_) {
    damping(v_, work_);
    blas::axpby(exec_, n3, 1.0, R_, -1.0, work_);  // work = R - C v
    if (lumpedMass) {
      auto m = lumpedMass_;
      auto w = work_;
      auto a = a_;
      Kokkos::parallel_for(
          "mfsi::structure::membrane::initialAcceleration", RangePolicy(exec_, 0, n3),
          KOKKOS_LAMBDA(lid_t i) { a(i) = m(i) > 0 ? w(i) / m(i) : 0; });
      projectConstraints(exec_, constraints_, a_, a_);
    } else {
      const auto r = cg_.solve(exec_, M_, constraints_, work_, a_, 1e-12, 10000);
      rep.linearIterations += r.iterations;
    }
    haveAcceleration_ = true;
  }

  const real t1 = time_ + dt;
  // Predictor with a_{n+1} = 0 (or the last trial of this step), then the clamps at t_{n+1}.
  if (!warm) {
    Kokkos::deep_copy(exec_, uTrial_, u_);
    blas::axpy(exec_, n3, dt, v_, uTrial_);
    blas::axpy(exec_, n3, (0.5 - beta) * dt * dt, a_, uTrial_);
  }
  clampTargets(t1);
  Kokkos::deep_copy(exec_, clampStart_, clampTarget_);
  applyClamps(uTrial_, 1);
  const bool withInterfaceMass = interfaceMass_ > 0;
  if (withInterfaceMass) Kokkos::deep_copy(exec_, anchor_, uTrial_);  // a_1* (see setInterfaceMass)

  const RealView a1 = a1_, v1 = v1_, rhs = rhs_;
  const real cM = (1 - am) / (beta * dt * dt), cC = (1 - af) * gamma / (beta * dt);
  auto kinematics = [&]() { trialKinematics(); };
  const auto& nopt = options_.newton;
  const bool constrained = volume_.active;
  const real volumeTol = volumeTolerance();
  // The step's residual at the trial displacement (and the multiplier): rhs = (1-af) R1 + af Rn
  // - M((1-am) a1 + am an) - C((1-af) v1 + af vn) [- the interface mass term]. Returns |M a_mid|.
  auto stepResidual = [&]() {
    kinematics();
    evalResidual(uTrial_, t1, 1);
    Kokkos::deep_copy(exec_, work_, a1);
    blas::axpby(exec_, n3, am, a_, 1 - am, work_);
    mass(work_, rhs);  // rhs = M a_mid (inertia)
    const real inertia = blas::norm2(exec_, SolverComm{}, n3, rhs);
    blas::axpby(exec_, n3, 1 - af, R_, -1.0, rhs);
    blas::axpy(exec_, n3, af, rn_, rhs);
    if (ra != 0 || rb != 0) {
      Kokkos::deep_copy(exec_, work_, v1);
      blas::axpby(exec_, n3, af, v_, 1 - af, work_);
      damping(work_, dampingForce_);
      blas::axpy(exec_, n3, -1.0, dampingForce_, rhs);
    }
    if (withInterfaceMass) {
      // - m_i (1 - am)(a_1 - a_1*) = - cM m_i (u_1 - u_1*): the accelerations share u_n, v_n, a_n.
      auto mi = interfaceNodeMass_;
      auto anchor = anchor_;
      auto u1 = uTrial_;
      Kokkos::parallel_for(
          "mfsi::structure::membrane::interfaceInertia", RangePolicy(exec_, 0, n3),
          KOKKOS_LAMBDA(lid_t i) { rhs(i) -= cM * mi(i) * (u1(i) - anchor(i)); });
    }
    return inertia;
  };
  real rel = 1;
  bool fresh = false;  // rhs_ already holds the residual at uTrial_ (the line search's last evaluation)
  real inertia = 0;
  for (int it = 0; it < nopt.maxIterations; ++it) {
    if (!fresh) inertia = stepResidual();
    fresh = false;
    const Norms nrm = norms(rhs);
    const real scale = std::max({nrm.external, nrm.reaction, inertia, residualFloor() / options_.tolerance});
    rel = scale > 0 ? nrm.free / scale : (nrm.free > 0 ? 1.0 : 0.0);
    rep.relativeResidual = rel;
    // The volume constraint's residual c and gradient g at the trial displacement.
    const real volumeMiss = constrained ? enclosedVolumeAt(uTrial_, volumeGrad_) - volume_.target : 0.0;
    if (!std::isfinite(volumeMiss)) break;
    if (rel <= options_.tolerance && std::abs(volumeMiss) <= volumeTol) {
      rep.converged = true;
      break;
    }
    if (!std::isfinite(rel)) break;
    // Effective matrix (1-af) K + cM M + cC C on the shared sparsity.
    assembleTangentAt(uTrial_, true);
    {
      auto K = K_.values;
      auto M = M_.values;
      auto Kd = Kdamp_.values;
      const bool consistent = !lumpedMass;
      const bool useKd = rb != 0;
      Kokkos::parallel_for(
          "mfsi::structure::membrane::effectiveMatrix", RangePolicy(exec_, 0, K_.nnz()), KOKKOS_LAMBDA(lid_t p) {
            real v = (1 - af) * K(p);
            if (consistent) v += (cM + cC * ra) * M(p);
            if (useKd) v += cC * rb * Kd(p);
            K(p) = v;
          });
      if (lumpedMass) {
        auto diag = K_.diagIdx;
        auto m = lumpedMass_;
        Kokkos::parallel_for(
            "mfsi::structure::membrane::effectiveLumped", RangePolicy(exec_, 0, n3),
            KOKKOS_LAMBDA(lid_t i) { K(diag(i)) += (cM + cC * ra) * m(i); });
      }
      if (withInterfaceMass) {
        auto diag = K_.diagIdx;
        auto mi = interfaceNodeMass_;
        Kokkos::parallel_for(
            "mfsi::structure::membrane::effectiveInterface", RangePolicy(exec_, 0, n3),
            KOKKOS_LAMBDA(lid_t i) { K(diag(i)) += cM * mi(i); });
      }
    }
    const real eta = std::min<real>(1e-2, std::max<real>(std::min<real>(rel, 1e-2), 0.5 * options_.tolerance / rel));
    const MembraneCgResult cg = cg_.solve(exec_, K_, constraints_, rhs, du_, eta, nopt.cgMaxIterations);
    rep.linearIterations += cg.iterations;
    real dLambdaStep = 0;
    if (constrained) {
      // du = a + dlambda b with A a = rhs (just solved), A b = (1 - af) g; g . du = -c.
      blas::axpby(exec_, n3, 1 - af, volumeGrad_, 0.0, volumeGrad_);
      const MembraneCgResult cgb = cg_.solve(exec_, K_, constraints_, volumeGrad_, volumeDu_, eta, nopt.cgMaxIterations);
      rep.linearIterations += cgb.iterations;
      const real ga = blas::dot(exec_, SolverComm{}, n3, volumeGrad_, du_) / (1 - af);
      const real gb = blas::dot(exec_, SolverComm{}, n3, volumeGrad_, volumeDu_) / (1 - af);
      if (!(gb > 0)) break;  // the volume does not respond to the free nodes
      volume_.compliance = gb;  // dV/dlambda = g.du/dlambda = g.b
      const real dLambda = -(volumeMiss + ga) / gb;
      blas::axpy(exec_, n3, dLambda, volumeDu_, du_);
      dLambdaStep = dLambda;
    }
    ++rep.iterations;
    // Line search on g(alpha) = du . rhs(u + alpha du, lambda + alpha dlambda), as in the static
    // solve: the full step when it halves g, else the root of g by secant and regula falsi. A
    // time step's matrix is definite, but the tension-field law switches a point between taut,
    // wrinkled and slack, where the tangent jumps by E h: a full Newton step from a slack region
    // can overshoot into a stiff one and back, step after step.
    const real g0 = blas::dot(exec_, SolverComm{}, n3, du_, rhs);
    // A step from equilibrium towards a moved volume target (membranes sharing a multiplier move
    // their shares between solves) is the constraint's alone: du . rhs starts at round-off, so
    // the search would cut the step to nothing. It is taken whole (linear in the target).
    const bool constraintStep = constrained && rel <= options_.tolerance;
    Kokkos::deep_copy(exec_, lineStart_, uTrial_);
    const real lambdaStart = volume_.lambda;
    auto tryStep = [&](real alpha) {
      Kokkos::deep_copy(exec_, uTrial_, lineStart_);
      blas::axpy(exec_, n3, alpha, du_, uTrial_);
      volume_.lambda = lambdaStart + alpha * dLambdaStep;
      inertia = stepResidual();
      return blas::dot(exec_, SolverComm{}, n3, du_, rhs);
    };
    real alpha = 1, lo = 0, gLo = g0, hi = -1, gHi = 0, bestAlpha = 1, bestG = -1;
    for (int evals = 1;; ++evals) {
      const real g = tryStep(alpha);
      if (std::isfinite(g) && (bestG < 0 || std::abs(g) < bestG)) {
        bestG = std::abs(g);
        bestAlpha = alpha;
      }
      if (!(g0 > 0) || constraintStep || (std::isfinite(g) && std::abs(g) <= 0.5 * g0)) break;
      if (evals > nopt.maxLineSearchSteps) {
        if (alpha != bestAlpha) tryStep(bestAlpha);
        break;
      }
      ++rep.lineSearchSteps;
      if (std::isfinite(g) && g > 0) {
        // The root lies beyond alpha: extrapolate (at most 4x), or interpolate in a bracket.
        lo = alpha;
        gLo = g;
        alpha = hi > 0 ? lo + (hi - lo) * gLo / (gLo - gHi) : std::min<real>(g < g0 ? alpha * g0 / (g0 - g) : 4 * alpha, 4 * alpha);
      } else {
        hi = alpha;
        gHi = std::isfinite(g) ? g : -10 * g0;
        const real t = gLo / (gLo - gHi);
        alpha = lo + (hi - lo) * std::min<real>(0.9, std::max<real>(0.1, t));
      }
    }
    fresh = true;
  }
  if (!rep.converged) kinematics();  // the trial velocity matches the trial displacement
  exec_.fence();
  rep.seconds = wallSeconds() - wall0;
  last_ = rep;
  return rep;
}

// ---------------------------------------------------------------------------------------------
// Checkpoints
// ---------------------------------------------------------------------------------------------

void MembraneSolver::saveState(io::StateWriter& w) const {
  w.putReal("time", time_);
  w.putView("displacement", u_);
  w.putView("velocity", v_);
  w.putView("acceleration", a_);
  w.putBool("haveAcceleration", haveAcceleration_);
  // An uncommitted step: a repeated solveStep of the same dt starts Newton from its trial
  // displacement (the trial velocity and acceleration follow from it and the committed state).
  io::StateWriter trial = w.sub("trial");
  trial.putBool("valid", trial_.valid);
  trial.putReal("dt", trial_.dt);
  if (trial_.valid) trial.putView("displacement", uTrial_);
  io::StateWriter report = w.sub("lastReport");
  report.putBool("converged", last_.converged);
  report.putInt("iterations", last_.iterations);
  report.putInt("linearIterations", last_.linearIterations);
  report.putInt("lineSearchSteps", last_.lineSearchSteps);
  report.putReal("relativeResidual", last_.relativeResidual);
  report.putReal("seconds", last_.seconds);
  report.tag("seconds", io::Entity::RankOwn);
  if (volume_.active) {
    w.putReal("volumeMultiplier", volume_.lambda);
    w.putReal("volumeMultiplierCommitted", lambdaCommitted_);
  }
  io::StateWriter loads = w.sub("loads");
  if (loads_.nodePressure.extent(0) > 0) loads.putView("nodePressure", loads_.nodePressure);
  if (loads_.elementPressure.extent(0) > 0) loads.putView("elementPressure", loads_.elementPressure);
  if (loads_.nodeForce.extent(0) > 0) loads.putView("nodeForce", loads_.nodeForce);
}

void MembraneSolver::loadState(const io::StateReader& r) {
  // The displacement first: a checkpoint of another mesh fails before anything else changes.
  r.getView("displacement", u_);
  r.getView("velocity", v_);
  r.getView("acceleration", a_);
  time_ = r.real("time");
  haveAcceleration_ = r.boolean("haveAcceleration");
  const io::StateReader report = r.sub("lastReport");
  last_.converged = report.boolean("converged");
  last_.iterations = static_cast<int>(report.integer("iterations"));
  last_.linearIterations = static_cast<int>(report.integer("linearIterations"));
  last_.lineSearchSteps = static_cast<int>(report.integer("lineSearchSteps"));
  last_.relativeResidual = report.real("relativeResidual");
  last_.seconds = report.real("seconds");
  if (volume_.active && r.has("volumeMultiplier")) {
    volume_.lambda = r.real("volumeMultiplier");
    lambdaCommitted_ = r.real("volumeMultiplierCommitted");
  }
  const io::StateReader loads = r.sub("loads");
  if (loads.has("nodePressure")) {
    if (loads_.nodePressure.extent(0) == 0)
      loads_.nodePressure = RealView("mfsi::structure::membrane::loads::nodePressure", mesh_.nNodes());
    loads.getView("nodePressure", loads_.nodePressure);
  }
  if (loads.has("elementPressure")) {
    if (loads_.elementPressure.extent(0) == 0)
      loads_.elementPressure = RealView("mfsi::structure::membrane::loads::elementPressure", mesh_.nElements());
    loads.getView("elementPressure", loads_.elementPressure);
  }
  if (loads.has("nodeForce")) {
    if (loads_.nodeForce.extent(0) == 0)
      loads_.nodeForce = Real3View("mfsi::structure::membrane::loads::nodeForce", mesh_.nNodes());
    loads.getView("nodeForce", loads_.nodeForce);
  }
  const io::StateReader trial = r.sub("trial");
  trial_.valid = trial.boolean("valid");
  trial_.dt = trial.real("dt");
  if (trial_.valid) {
    trial.getView("displacement", uTrial_);
    trialKinematics();
    exec_.fence();
  }
}

// ---------------------------------------------------------------------------------------------
// Output
// ---------------------------------------------------------------------------------------------

MembraneResults MembraneSolver::results() {
  MembraneResults r;
  const lid_t nN = mesh_.nNodes();
  r.displacement = Real3View("mfsi::structure::membrane::out::displacement", nN);
  r.displacementMagnitude = RealView("mfsi::structure::membrane::out::displacementMagnitude", nN);
  auto d = r.displacement;
  auto m = r.displacementMagnitude;
  auto u = u_;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::out::nodes", RangePolicy(exec_, 0, nN), KOKKOS_LAMBDA(lid_t n) {
        for (int k = 0; k < 3; ++k) d(n, k) = u(3 * n + k);
        m(n) = kmath::sqrt(u(3 * n) * u(3 * n) + u(3 * n + 1) * u(3 * n + 1) + u(3 * n + 2) * u(3 * n + 2));
      });
  r.elements = allocateMembraneElementOutput(mesh_.nElements());
  membraneElementOutput(exec_, data_, u_, r.elements);
  exec_.fence();
  return r;
}

std::map<std::string, double> MembraneSolver::summary() {
  const MembraneResults r = results();
  auto um = Kokkos::create_mirror_view_and_copy(HostSpace(), r.displacementMagnitude);
  auto uh = Kokkos::create_mirror_view_and_copy(HostSpace(), r.displacement);
  auto s1 = Kokkos::create_mirror_view_and_copy(HostSpace(), r.elements.principal1);
  auto s2 = Kokkos::create_mirror_view_and_copy(HostSpace(), r.elements.principal2);
  auto vm = Kokkos::create_mirror_view_and_copy(HostSpace(), r.elements.vonMises);
  auto ws = Kokkos::create_mirror_view_and_copy(HostSpace(), r.elements.wrinkleState);
  std::map<std::string, double> out;
  double maxU = 0;
  for (lid_t n = 0; n < mesh_.nNodes(); ++n) maxU = std::max<double>(maxU, um(n));
  const lid_t c = mesh_.hasNodeSet("centre") && !mesh_.nodeSet("centre").empty() ? mesh_.nodeSet("centre").front()
                                                                                 : mesh_.centreNode();
  double wc = 0;
  for (int k = 0; k < 3; ++k) wc += uh(c, k) * mesh_.hostNodeNormals()[c][k];
  double maxVm = 0, maxS1 = -1e300, minS2 = 1e300, wr = 0, sl = 0;
  const auto& area = mesh_.elementAreas();
  for (lid_t e = 0; e < mesh_.nElements(); ++e) {
    maxVm = std::max<double>(maxVm, vm(e));
    maxS1 = std::max<double>(maxS1, s1(e));
    minS2 = std::min<double>(minS2, s2(e));
    if (ws(e) == static_cast<int>(MembraneWrinkleState::Wrinkled)) wr += area[e];
    if (ws(e) == static_cast<int>(MembraneWrinkleState::Slack)) sl += area[e];
  }
  out["maxDisplacement"] = maxU;
  out["centreDeflection"] = wc;
  out["maxVonMises"] = maxVm;
  out["maxPrincipalStress"] = maxS1;
  out["minPrincipalStress"] = minS2;
  out["wrinkledFraction"] = wr / mesh_.referenceArea();
  out["slackFraction"] = sl / mesh_.referenceArea();
  if (hinges_.size() > 0) out["bendingEnergy"] = membraneBendingEnergy(exec_, hinges_, data_.X, u_);
  out["iterations"] = last_.iterations;
  out["linearIterations"] = last_.linearIterations;
  out["relativeResidual"] = last_.relativeResidual;
  out["time"] = time_;
  return out;
}

}  // namespace mfsi
