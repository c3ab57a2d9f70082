/// \file
/// \brief FsiCoupling's closed chambers (coupling/chambers/Chamber.hpp): finding them and their
/// groups, each step's volume targets and their split among the walls, the walls' and bodies'
/// volumes, the bodies' share of the multiplier, and the step's end (the fluid's pressure level
/// takes over the multiplier). The orchestration that calls these is in FsiCoupling.cpp.
#include "coupling/orchestrator/FsiCoupling.hpp"

#include "core/Error.hpp"
#include "core/HexGeometry.hpp"
#include "core/MeshRegions.hpp"
#include "core/Suggest.hpp"
#include "coupling/interface/InterfaceSegment.hpp"
#include "fluid/Loads.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mfsi {

using coupling::copySegmentToDevice;
using coupling::InterfaceVector;

void FsiCoupling::setUpLumpedChamber(const SceneConfig& section) {
  const CouplingOptions::LumpedChamber& lc = options_.lumpedChamber;
  const auto where = section.where("lumpedChamber.membrane");
  const std::vector<std::string> names = membraneNames();
  const auto it = std::find(names.begin(), names.end(), lc.membrane);
  if (it == names.end())
    throw InputError(where, "no coupled membrane '" + lc.membrane + "'" + didYouMean(lc.membrane, names) +
                                "; membranes: " + joinList(names));
  const int i = static_cast<int>(it - names.begin());
  const Panel& p = panels_[i];
  if (p.iface.side != coupling::InterfaceSide::Patch)
    throw InputError(where, lc.membrane + " has fluid on both sides (a baffle): a lumped chamber lies behind a "
                                          "membrane patch (mesh: {boundaryPatch: ...})");
  if (!p.dynamic)
    throw InputError(where, lc.membrane + ": a lumped chamber's volume constraint needs the dynamic analysis");
  // Behind a mounted membrane the chamber is taken to ride with its body (enclosed by the body and
  // the membrane): its volume is the membrane's frame-relative one, and its pressure on the body's
  // own walls cancels what the membrane would pass on, so the body takes none of it.
  if (p.mounted && singleParent(p) < 0)
    throw InputError(where, lc.membrane + " is blended between several bodies (parentBodyPatches): a lumped "
                                          "chamber rides with one body; mount the membrane on one");
  // The chamber lies on the side the element normals (out of the fluid) point into.
  addChamber({{i, real(-1)}}, -1, true);
}

void FsiCoupling::addChamber(const std::vector<std::pair<int, real>>& walls, int fluidRegion, bool lumped) {
  Chamber c;
  c.fluidRegion = fluidRegion;
  c.lumped = lumped;
  for (const auto& [panel, sign] : walls) {
    MembraneSolver& s = panels_[static_cast<std::size_t>(panel)].module->solver();
    MembraneVolumeConstraint& vc = s.volumeConstraint();
    ChamberWall w;
    w.panel = panel;
    if (chamberOf(panel) >= 0) {
      // The membrane's other side closes an earlier chamber: its constraint keeps that one's sign.
      w.sign = sign * vc.sign;
    } else {
      vc.active = true;
      vc.sign = sign;
      vc.lambda = 0;
      vc.target = s.enclosedVolume(s.displacement());
    }
    w.volumeStart = w.sign * s.enclosedVolume(s.displacement());
    c.volumeStart += w.volumeStart;
    c.walls.push_back(w);
  }
  chambers_.push_back(c);
}

int FsiCoupling::singleParent(const Panel& p) const {
  const std::size_t n = static_cast<std::size_t>(p.module->solver().mesh().nNodes());
  for (int slot = 0; slot < p.parents.nBodies(); ++slot) {
    bool all = true;
    for (std::size_t i = 0; i < n && all; ++i) all = p.parents.weight(i, slot) == 1.0;
    if (all) return slot;
  }
  return -1;
}

void FsiCoupling::addMovingWalls(Chamber& c, const std::vector<int>& cellRegion, int region) {
  for (ChamberWall& w : c.walls) {
    const Panel& p = panels_[static_cast<std::size_t>(w.panel)];
    if (!p.mounted) continue;
    w.parent = singleParent(p);
    w.blended = w.parent < 0;
    blended_ = blended_ || w.blended;
    const MembraneMesh& mm = p.module->solver().mesh();
    w.rigid = RealView("mfsi::coupling::chamberRigidWall", 3 * mm.nNodes());
    if (w.blended) w.relative = RealView("mfsi::coupling::chamberBlendedWall", 3 * mm.nNodes());
    w.pressure = RealView("mfsi::coupling::chamberWallMultiplier", mm.nElements());
  }
  // The bodies' faces on the region, each counted by the rank that owns its cell.
  const fluid::FluidSolver& f = fluid_->solver();
  auto X = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.referencePoints());
  auto fn = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.faceNodes());
  auto own = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.faceOwner());
  const lid_t nOwned = f.ownedCells();
  for (std::size_t slot = 0; slot < bodies_.size(); ++slot) {
    ChamberBody b;
    b.slot = static_cast<int>(slot);
    double sums[7] = {0, 0, 0, 0, 0, 0, 0};  // area vector, moment, face count
    for (const std::string& name : bodies_[slot].patches)
      for (int pi : f.boundaryConditions().find(name)) {
        const Patch& patch = mesh_.patches()[static_cast<std::size_t>(pi)];
        for (lid_t face = patch.start; face < patch.start + patch.size; ++face) {
          const lid_t cell = own(face);
          if (cell >= nOwned || cellRegion[static_cast<std::size_t>(cell)] != region) continue;
          std::array<double, 12> corners;
          double q[4][3];
          for (int a = 0; a < 4; ++a)
            for (int k = 0; k < 3; ++k) corners[3 * a + k] = q[a][k] = X(fn(face, a), k);
          double area[3], centre[3], magnitude = 0;
          geom::quadAreaVector(q, area);
          geom::quadCentroid(q, centre, magnitude);
          const Eigen::Vector3d S(area[0], area[1], area[2]);
          const Eigen::Vector3d r = Eigen::Vector3d(centre[0], centre[1], centre[2]) - bodies_[slot].com0;
          const Eigen::Vector3d m = r.cross(S);
          for (int k = 0; k < 3; ++k) {
            sums[k] += S[k];
            sums[3 + k] += m[k];
          }
          sums[6] += 1;
          b.faces.push_back(corners);
        }
      }
    if (domain_.distributed()) MPI_Allreduce(MPI_IN_PLACE, sums, 7, MPI_DOUBLE, MPI_SUM, domain_.comm);
    if (sums[6] == 0) continue;  // on every rank alike
    b.area = Eigen::Vector3d(sums[0], sums[1], sums[2]);
    b.moment = Eigen::Vector3d(sums[3], sums[4], sums[5]);
    c.bodies.push_back(std::move(b));
  }
  // rigidStart stays 0: the bodies start at their reference places.
}

int FsiCoupling::chamberOf(int panel) const {
  for (std::size_t k = 0; k < chambers_.size(); ++k)
    for (const ChamberWall& w : chambers_[k].walls)
      if (w.panel == panel) return static_cast<int>(k);
  return -1;
}

std::string FsiCoupling::chamberName(std::size_t chamber, const std::string& name) const {
  if (chambers_.size() == 1) return name;
  // A membrane between two chambers names the first; the other is named by another of its walls,
  // or, with none left, by the shared one and its number.
  std::vector<int> used;
  const std::vector<std::string> names = membraneNames();
  for (std::size_t k = 0; k <= chamber; ++k) {
    const std::vector<ChamberWall>& walls = chambers_[k].walls;
    const auto free = std::find_if(walls.begin(), walls.end(), [&](const ChamberWall& w) {
      return std::find(used.begin(), used.end(), w.panel) == used.end();
    });
    if (k == chamber)
      return name + "." +
             (free != walls.end() ? names[static_cast<std::size_t>(free->panel)]
                                  : names[static_cast<std::size_t>(walls[0].panel)] + "." + std::to_string(k));
    if (free != walls.end()) used.push_back(free->panel);
  }
  return name;
}

void FsiCoupling::setUpChamber(const SceneConfig& section) {
  if (!options_.lumpedChamber.membrane.empty()) setUpLumpedChamber(section);
  fluid::FluidSolver& f = fluid_->solver();
  // Artificial compressibility: the fluid takes a volume change itself.
  if (f.options().artificialCompressibility.soundSpeed > 0) return;
  std::vector<std::string> pressure;
  for (const auto& [name, bc] : f.options().boundaries)
    if (bc.type == fluid::BoundaryType::FixedPressure || bc.type == fluid::BoundaryType::Resistance)
      pressure.push_back(name);
  const MeshRegions regions = findMeshRegions(mesh_, pressure, domain_);
  const long long nClosed = std::count(regions.closed.begin(), regions.closed.end(), char(1));
  if (nClosed == 0) return;
  // Closed regions beside open ones: the fluid pins each one's pressure level and checks its balance.
  auto registerRegion = [&](int r) {
    std::vector<char> local(static_cast<std::size_t>(mesh_.nCells()));
    for (lid_t c = 0; c < mesh_.nCells(); ++c) local[c] = regions.cellRegion[static_cast<std::size_t>(c)] == r;
    return f.addClosedRegion(local, regions.firstCell[static_cast<std::size_t>(r)]);
  };
  if (!options_.volumeConstraint) {
    // Plain Dirichlet-Neumann coupling: an iterate whose volume misses the inflow then stops the
    // run with that reason (instead of a singular pressure equation).
    if (!f.closedDomain())
      for (int r = 0; r < regions.count; ++r)
        if (regions.closed[r]) registerRegion(r);
    return;
  }
  const auto where = section.where("volumeConstraint");
  if (f.closedDomain() && nClosed > 1)
    throw InputError(where, "the fluid mesh has " + std::to_string(nClosed) +
                                " regions and no pressure boundary: give one of them a pressure boundary, set "
                                "coupling.volumeConstraint: false or use artificial compressibility "
                                "(fluid.artificialSoundSpeed)");
  // The membrane sides that bound a region: a patch's fluid side, a baffle's master side (the
  // region grows along the membrane normal) or slave side (it shrinks). A baffle with fluid of the
  // region on both sides sweeps no net volume of it.
  // Each element's cell is owned by one rank, which counts it.
  auto sideIn = [&](const Panel& p, int side, int region) {
    const std::vector<lid_t>& cell = p.surface.ownedCells(side);
    long long count[2] = {0, static_cast<long long>(cell.size())};  // inside, elements
    for (lid_t c : cell) count[0] += c >= 0 && regions.cellRegion[static_cast<std::size_t>(c)] == region ? 1 : 0;
    if (domain_.distributed()) MPI_Allreduce(MPI_IN_PLACE, count, 1, MPI_LONG_LONG, MPI_SUM, domain_.comm);
    if (count[0] != 0 && count[0] != count[1])
      throw InputError(where, "a membrane side lies partly in a closed fluid region: not supported");
    return count[0] > 0;
  };
  for (int region = 0; region < regions.count; ++region) {
    if (!regions.closed[static_cast<std::size_t>(region)]) continue;
    // A region bounded by several membranes: one multiplier shared by them all.
    std::vector<std::pair<int, real>> walls;
    for (std::size_t i = 0; i < panels_.size(); ++i) {
      const Panel& p = panels_[i];
      const bool front = sideIn(p, 0, region), back = p.surface.sides() == 2 && sideIn(p, 1, region);
      if (front == back) continue;
      if (!p.dynamic)
        throw InputError(where, p.module->name() + " closes a fluid region: its volume constraint needs the "
                                "dynamic analysis (membranes.N.analysis: dynamic)");
      // A membrane that closes a chamber on its other side too (a fluid region or a lumped one)
      // carries both chambers' multipliers (groupChambers).
      // The membrane's element normals are the fluid faces' area vectors (the master side's on a
      // baffle; coupling/interface/MembraneInterface).
      walls.emplace_back(static_cast<int>(i), front ? real(1) : real(-1));
    }
    if (walls.empty()) {
      if (f.closedDomain()) return;  // no membrane closes it: the fluid checks that its fluxes balance
      throw InputError(where, "a region of the fluid no pressure boundary reaches is closed by no membrane: its "
                              "pressure level is undefined; give it a pressure boundary or artificial "
                              "compressibility");
    }
    addChamber(walls, f.closedDomain() ? -1 : registerRegion(region), false);
    addMovingWalls(chambers_.back(), regions.cellRegion, region);
  }
}

void FsiCoupling::beginChamberStep() {
  for (Chamber& c : chambers_) {
    c.volumeMiss = 0;
    if (c.lumped) {
      // The inflow's integral over the step (composite Simpson on 64 intervals: the pump's pulses
      // have square-root ends).
      const CouplingOptions::LumpedChamber& lc = options_.lumpedChamber;
      const fluid::FluidSolver& f = fluid_->solver();
      const double t0 = f.time(), h = f.timeStep() / 64;
      double sum = 0;
      for (int k = 0; k <= 64; ++k) sum += (k == 0 || k == 64 ? 1 : k % 2 ? 4 : 2) * lc.timeFunction(t0 + k * h);
      c.volumeStep = lc.flowRate * sum * h / 3;
    } else {
      // Every boundary face's flux sums to zero: the membrane's mesh flux (c1 dV^{n+1} - c00 dV^n) / dt
      // equals the prescribed inflow Q at t_n+1.
      const fluid::FluidSolver& f = fluid_->solver();
      const fluid::FluidSolver::MeshFluxWeights w = f.meshFluxWeights();
      const double q = f.prescribedInflow(c.fluidRegion);
      c.volumeStep = (w.dt * q + w.c00 * c.sweptLast) / w.c1;
    }
    c.rounds = 0;
    c.sweeps = 0;
    c.spread = 0;
    c.rigidNow = c.rigidStart;  // the bodies at the step's start: followBodies moves the targets on
  }
  for (const ChamberGroup& g : groups_) splitTarget(g);
}

void FsiCoupling::groupChambers(const SourceLocation& where) {
  std::vector<std::vector<std::pair<int, double>>> walls;
  for (const Chamber& c : chambers_) {
    walls.emplace_back();
    for (const ChamberWall& w : c.walls) walls.back().emplace_back(w.panel, double(w.sign));
  }
  groups_ = coupling::groupChambers(walls);
  for (std::size_t k = 0; k < groups_.size(); ++k) {
    const ChamberGroup& g = groups_[k];
    for (int c : g.chambers) chambers_[static_cast<std::size_t>(c)].group = static_cast<int>(k);
    if (g.pressuresFixed()) continue;
    std::string names;
    for (int c : g.chambers) {
      const Chamber& ch = chambers_[static_cast<std::size_t>(c)];
      std::string wallNames;
      for (const ChamberWall& w : ch.walls)
        wallNames += (wallNames.empty() ? "" : " and ") + panels_[static_cast<std::size_t>(w.panel)].module->name();
      names += (names.empty() ? "" : ", ") + std::string(ch.lumped ? "the lumped chamber" : "the fluid region") +
               " of " + wallNames;
    }
    throw InputError(where, "closed chambers (" + names + ") are bounded only by the membranes between them: "
                            "their inflows would fix the membranes' volumes twice and their pressures only "
                            "up to a common level; give one of them a pressure boundary");
  }
}

Eigen::VectorXd FsiCoupling::wallWeights(const ChamberGroup& g) const {
  Eigen::VectorXd w(static_cast<Eigen::Index>(g.panels.size()));
  bool compliant = true;
  for (int p : g.panels)
    compliant = compliant && panels_[static_cast<std::size_t>(p)].module->solver().volumeConstraint().compliance > 0;
  for (std::size_t j = 0; j < g.panels.size(); ++j) {
    const MembraneSolver& s = panels_[static_cast<std::size_t>(g.panels[j])].module->solver();
    w[static_cast<Eigen::Index>(j)] =
        compliant ? double(s.volumeConstraint().compliance) : double(s.mesh().referenceArea());
  }
  return w;
}

void FsiCoupling::splitTarget(const ChamberGroup& g) {
  Eigen::VectorXd d(static_cast<Eigen::Index>(g.chambers.size()));
  for (std::size_t r = 0; r < g.chambers.size(); ++r)
    d[static_cast<Eigen::Index>(r)] = chambers_[static_cast<std::size_t>(g.chambers[r])].volumeStep;
  const Eigen::VectorXd share = coupling::shareOut(g, wallWeights(g), d);
  // Each wall from its start volume (in its constraint's sign), once (a shared wall is in two chambers).
  std::vector<char> done(g.panels.size(), 0);
  for (int c : g.chambers)
    for (const ChamberWall& w : chambers_[static_cast<std::size_t>(c)].walls) {
      const Eigen::Index j = g.column(w.panel);
      if (done[static_cast<std::size_t>(j)]) continue;
      done[static_cast<std::size_t>(j)] = 1;
      memberSolver(w).volumeConstraint().target = w.sign * w.volumeStart + share[j];
    }
}

bool FsiCoupling::moveShares(const ChamberGroup& g, bool resolved) {
  const auto n = static_cast<Eigen::Index>(g.panels.size());
  Eigen::VectorXd C(n), lambda(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const Panel& p = panels_[static_cast<std::size_t>(g.panels[static_cast<std::size_t>(j)])];
    const MembraneVolumeConstraint& vc = p.module->solver().volumeConstraint();
    if (!(vc.compliance > 0))
      throw DivergenceError(p.module->name() + ": its volume does not respond to the chamber's pressure (no free node "
                            "moves it), so the chamber's volume cannot be shared among its membranes");
    C[j] = vc.compliance;
    lambda[j] = vc.lambda;
  }
  // The chambers' multipliers: one chamber, the compliance-weighted mean of its walls'.
  const Eigen::VectorXd Lambda = coupling::agreedMultipliers(g, C, lambda);
  const Eigen::VectorXd agreed = g.incidence.transpose() * Lambda;  // what each wall should carry
  // The pressure the walls carry: the multipliers and the fluid's loads.
  double scale = 0;
  for (int c : g.chambers) scale = std::max(scale, pressureScale(chambers_[static_cast<std::size_t>(c)]));
  const double spread = (lambda - agreed).cwiseAbs().maxCoeff();
  for (std::size_t r = 0; r < g.chambers.size(); ++r) {
    Chamber& c = chambers_[static_cast<std::size_t>(g.chambers[r])];
    c.lambda = Lambda[static_cast<Eigen::Index>(r)];
    c.spread = scale > 0 ? spread / scale : 0.0;
  }
  // Shares moved by less than the membranes' volume tolerance move nothing (no wall took a Newton
  // iteration): the multipliers agree as well as the membrane solves can tell.
  if (resolved && std::none_of(g.chambers.begin(), g.chambers.end(), [&](int c) {
        return wallsIterated(chambers_[static_cast<std::size_t>(c)]);
      }))
    return true;
  if (spread <= coupling::kShareAgreement * options_.fsiTol * scale) return true;
  for (Eigen::Index j = 0; j < n; ++j) {
    MembraneSolver& s = panels_[static_cast<std::size_t>(g.panels[static_cast<std::size_t>(j)])].module->solver();
    s.volumeConstraint().target += C[j] * (agreed[j] - lambda[j]);
  }
  return false;
}

void FsiCoupling::checkChamberVolume(const InterfaceVector& x) {
  const Eigen::VectorXd q = bodyCoordinates(x);
  for (Chamber& c : chambers_)
    c.volumeMiss = std::max(c.volumeMiss, std::abs(chamberVolume(c, q, &x) - (c.volumeStart + c.volumeStep)));
}

RealView FsiCoupling::wallDisplacement(const Panel& p) const {
  MembraneSolver& s = p.module->solver();
  return p.dynamic && s.hasTrial() ? s.trialDisplacement() : s.displacement();
}

double FsiCoupling::chamberVolume(Chamber& c, const Eigen::VectorXd& q, const InterfaceVector* x) {
  double volume = rigidVolumeAt(c, q, x);
  for (const ChamberWall& w : c.walls) {
    Panel& p = panels_[static_cast<std::size_t>(w.panel)];
    if (x != nullptr) copySegmentToDevice(*x, p.offset, p.iterate);
    volume += w.sign * p.module->solver().enclosedVolume(x != nullptr ? p.iterate : wallDisplacement(p));
  }
  return volume;
}

double FsiCoupling::rigidVolume(Chamber& c, const std::vector<RigidPlacement>& t, const InterfaceVector* x) {
  // The bodies' faces: the exact trilinear volume each sweeps from its reference corners to
  // their rigidly moved places (what the fluid's swept-volume fluxes of those faces add up to).
  double v = 0;
  for (const ChamberBody& b : c.bodies)
    for (const auto& f : b.faces) {
      double hex[8][3];
      for (int a = 0; a < 4; ++a) {
        const std::array<real, 3> X{f[3 * a], f[3 * a + 1], f[3 * a + 2]};
        const std::array<real, 3> y = t[static_cast<std::size_t>(b.slot)].apply(X);
        for (int k = 0; k < 3; ++k) {
          hex[a][k] = X[k];
          hex[a + 4][k] = y[k];
        }
      }
      v += geom::hexVolume(hex);
    }
  if (domain_.distributed() && !c.bodies.empty()) MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_SUM, domain_.comm);
  // Mounted walls carried undeformed by their body: a rigid motion keeps the volume between the
  // carried and the deformed membrane, so the frame-relative volume adds to this exactly. A wall
  // blended between bodies does not move rigidly: its placed volume at its displacement u, less
  // u's frame-relative volume (which the walls' targets count).
  for (ChamberWall& w : c.walls) {
    if (w.parent < 0 && !w.blended) continue;
    const Panel& p = panels_[static_cast<std::size_t>(w.panel)];
    MembraneSolver& s = memberSolver(w);
    const auto& X = s.mesh().hostPoints();
    auto h = Kokkos::create_mirror_view(w.rigid);
    if (!w.blended) {
      for (std::size_t i = 0; i < X.size(); ++i) {
        const std::array<real, 3> y = t[static_cast<std::size_t>(w.parent)].apply(X[i]);
        for (int k = 0; k < 3; ++k) h(3 * i + k) = y[k] - X[i][k];
      }
      Kokkos::deep_copy(w.rigid, h);
      v += w.sign * s.enclosedVolume(w.rigid);
      continue;
    }
    if (x != nullptr)
      copySegmentToDevice(*x, p.offset, w.relative);
    else
      Kokkos::deep_copy(w.relative, wallDisplacement(p));
    auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), w.relative);
    for (std::size_t i = 0; i < X.size(); ++i) {
      std::array<real, 3> y{0, 0, 0};
      const std::array<real, 3> at{X[i][0] + u(3 * i), X[i][1] + u(3 * i + 1), X[i][2] + u(3 * i + 2)};
      for (int b = 0; b < p.parents.nBodies(); ++b) {
        const double weight = p.parents.weight(i, b);
        if (weight == 0) continue;
        const std::array<real, 3> yb = t[static_cast<std::size_t>(b)].apply(at);
        for (int k = 0; k < 3; ++k) y[k] += weight * yb[k];
      }
      for (int k = 0; k < 3; ++k) h(3 * i + k) = y[k] - X[i][k];
    }
    Kokkos::deep_copy(w.rigid, h);
    v += w.sign * (s.enclosedVolume(w.rigid) - s.enclosedVolume(w.relative));
  }
  return v;
}

double FsiCoupling::rigidVolumeAt(Chamber& c, const Eigen::VectorXd& q, const InterfaceVector* x) {
  if (q.size() == 0 || !c.moving()) return 0;
  return rigidVolume(c, placementsOf(q), x);
}

double FsiCoupling::blendedMiss(const InterfaceVector* x) {
  double worst = 0;
  const Eigen::VectorXd q = x != nullptr ? bodyCoordinates(*x) : Eigen::VectorXd(rigid_->system().q());
  for (Chamber& c : chambers_) {
    if (!c.blended()) continue;
    double tolerance = 0;
    for (const ChamberWall& w : c.walls) tolerance = std::max(tolerance, double(memberSolver(w).volumeTolerance()));
    worst = std::max(worst, std::abs(chamberVolume(c, q, x) - (c.volumeStart + c.volumeStep)) / tolerance);
  }
  return worst;
}

void FsiCoupling::followBodies() {
  if (bodies_.empty()) return;
  const Eigen::VectorXd q = rigid_->system().q();
  for (const ChamberGroup& g : groups_) {
    // What the bodies' motion changed of each chamber's volume, since the walls' targets last took it.
    Eigen::VectorXd d(static_cast<Eigen::Index>(g.chambers.size()));
    for (std::size_t r = 0; r < g.chambers.size(); ++r) {
      Chamber& c = chambers_[static_cast<std::size_t>(g.chambers[r])];
      const double now = rigidVolumeAt(c, q);
      d[static_cast<Eigen::Index>(r)] = now - c.rigidNow;
      c.rigidNow = now;
    }
    if (d.isZero(0)) continue;
    // The walls' totals follow; their split stays.
    const Eigen::VectorXd share = coupling::shareOut(g, wallWeights(g), -d);
    for (std::size_t j = 0; j < g.panels.size(); ++j)
      panels_[static_cast<std::size_t>(g.panels[j])].module->solver().volumeConstraint().target +=
          share[static_cast<Eigen::Index>(j)];
  }
}

double FsiCoupling::chamberMultiplier(const Chamber& c) const {
  // Several walls in its group: the agreed one of the last share round (a wall between two
  // chambers carries the difference of theirs).
  if (groups_[static_cast<std::size_t>(c.group)].panels.size() > 1) return c.lambda;
  return memberSolver(c.walls[0]).volumeConstraint().lambda;
}

bool FsiCoupling::wallsIterated(const Chamber& c) const {
  return std::any_of(c.walls.begin(), c.walls.end(), [&](const ChamberWall& w) {
    return panels_[static_cast<std::size_t>(w.panel)].report.iterations > 0;
  });
}

double FsiCoupling::pressureScale(const Chamber& c) const {
  double scale = 0;
  for (const ChamberWall& w : c.walls) {
    scale = std::max(scale, std::abs(double(memberSolver(w).volumeConstraint().lambda)));
    auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), panels_[static_cast<std::size_t>(w.panel)].load);
    for (std::size_t e = 0; e < h.extent(0); ++e) scale = std::max(scale, std::abs(double(h(e))));
  }
  return scale;
}

void FsiCoupling::targetsFor(const InterfaceVector& x,
                             std::vector<std::pair<MembraneVolumeConstraint*, real>>* saved) {
  const Eigen::VectorXd q = bodyCoordinates(x);
  for (const ChamberGroup& g : groups_) {
    if (g.panels.size() < 2 && !chambers_[static_cast<std::size_t>(g.chambers[0])].moving()) continue;
    Eigen::VectorXd volume(static_cast<Eigen::Index>(g.panels.size()));
    for (std::size_t j = 0; j < g.panels.size(); ++j) {
      Panel& p = panels_[static_cast<std::size_t>(g.panels[j])];
      copySegmentToDevice(x, p.offset, p.iterate);
      volume[static_cast<Eigen::Index>(j)] = p.module->solver().enclosedVolume(p.iterate);
    }
    Eigen::VectorXd miss(static_cast<Eigen::Index>(g.chambers.size()));
    for (std::size_t r = 0; r < g.chambers.size(); ++r) {
      Chamber& c = chambers_[static_cast<std::size_t>(g.chambers[r])];
      miss[static_cast<Eigen::Index>(r)] = c.volumeStart + c.volumeStep - rigidVolumeAt(c, q, &x);
    }
    miss -= g.incidence * volume;
    const Eigen::VectorXd share = coupling::shareOut(g, wallWeights(g), miss);
    for (std::size_t j = 0; j < g.panels.size(); ++j) {
      MembraneVolumeConstraint& vc = panels_[static_cast<std::size_t>(g.panels[j])].module->solver().volumeConstraint();
      if (saved != nullptr) saved->emplace_back(&vc, vc.target);
      vc.target = volume[static_cast<Eigen::Index>(j)] + share[static_cast<Eigen::Index>(j)];
    }
  }
}

void FsiCoupling::addChamberLoads(std::size_t slot, Eigen::Vector3d& force, Eigen::Vector3d& moment) {
  const Eigen::Vector3d& c = bodies_[slot].loadCentre;
  // A chamber's multiplier (the part of its pressure the fluid's level does not carry yet) on
  // the body's faces that bound it and on the mounted walls it carries, as those walls receive it.
  for (Chamber& ch : chambers_) {
    // Weighted between the step's ends as the walls' integrator weighs their multiplier (a body
    // that took it at the step's end alone would make the two trade it back and forth, growing).
    const double af = memberSolver(ch.walls[0]).startLoadWeight();
    const double lambda = (1 - af) * ch.bodyLambda + af * ch.bodyLambdaStart;
    if (lambda == 0) continue;
    const RigidPlacement& t = transforms_[slot];
    Eigen::Matrix3d Q;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) Q(i, j) = t.rotation[i][j];
    const Eigen::Vector3d lever(t.placed[0] - c[0], t.placed[1] - c[1], t.placed[2] - c[2]);
    for (const ChamberBody& cb : ch.bodies) {
      if (cb.slot != static_cast<int>(slot)) continue;
      const Eigen::Vector3d f = lambda * (Q * cb.area);
      force += f;
      moment += lambda * (Q * cb.moment) + lever.cross(f);
    }
    for (ChamberWall& w : ch.walls) {
      if (w.parent != static_cast<int>(slot) && !w.blended) continue;  // blended: by its weights
      const Panel& p = panels_[static_cast<std::size_t>(w.panel)];
      MembraneSolver& s = memberSolver(w);
      Kokkos::deep_copy(exec_, w.pressure, s.volumeConstraint().sign * w.sign * lambda);
      const std::array<double, 6> L = p.parents.bodyLoad(exec_, static_cast<int>(slot), {c[0], c[1], c[2]},
                                                        s.mesh().elementNodes(), w.pressure, p.iface.front, 0,
                                                        p.surface.faceArea(), p.surface.faceCentroid());
      for (int k = 0; k < 3; ++k) {
        force[k] += L[k];
        moment[k] += L[3 + k];
      }
    }
  }
}

void FsiCoupling::endChamberStep(const InterfaceVector& good) {
  const Eigen::VectorXd qGood = bodyCoordinates(good);
  for (Chamber& c : chambers_) {
    // The fluid mesh ends the step at `good` (the last iterate moved to): the next step's start.
    const double start = c.volumeStart;
    c.rigidStart = c.rigidNow = rigidVolumeAt(c, qGood, &good);
    c.volumeStart = c.rigidStart;
    bool patches = true;  // every wall a membrane patch (none a baffle)
    for (ChamberWall& w : c.walls) {
      Panel& p = panels_[static_cast<std::size_t>(w.panel)];
      MembraneSolver& s = p.module->solver();
      copySegmentToDevice(good, p.offset, p.iterate);
      w.volumeStart = w.sign * s.enclosedVolume(p.iterate);
      c.volumeStart += w.volumeStart;
      patches = patches && p.iface.side == coupling::InterfaceSide::Patch;
    }
    double pa = 0, a = 0;  // patches: the fluid's load on the walls, integrated, and their area
    for (const ChamberWall& w : c.walls) {
      if (!patches || c.lumped) break;
      const Panel& p = panels_[static_cast<std::size_t>(w.panel)];
      const std::vector<real>& areas = p.module->solver().mesh().elementAreas();
      auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), p.load);
      for (std::size_t e = 0; e < areas.size(); ++e) {
        pa += areas[e] * h(e);
        a += areas[e];
      }
    }
    c.sweptLast = c.volumeStart - start;
    c.lambda = chamberMultiplier(c);
    // A lumped chamber's pressure is the multiplier over the outside pressure its membrane's load
    // is taken against. Behind a baffle the load is the difference across it: the chamber's
    // pressure is the multiplier plus the fluid's mean over the chamber's cells. Behind patches:
    // the multiplier plus the fluid's mean load on the membranes (the fluid's pressure level in a
    // closed domain is that of its reference cell and drifts with the pressure solver's tolerance;
    // the multiplier takes up the difference).
    if (c.lumped) {
      c.pressure = options_.outsidePressure + c.lambda;
    } else if (!patches) {
      const fluid::FluidSolver& f = fluid_->solver();
      const double mean =
          c.fluidRegion < 0 ? fluid::meanPressure(f) : fluid::meanPressure(f, f.cellClosedRegion(), c.fluidRegion);
      c.pressure = c.lambda + mean;
    } else {
      c.pressure = c.lambda + (a > 0 ? pa / a : 0.0);
    }
    c.maxMissRun = std::max(c.maxMissRun, c.volumeMiss);
  }
}

void FsiCoupling::shiftChamberLevels() {
  for (Chamber& c : chambers_) {
    if (c.lumped) continue;
    // The fluid's pressure level in the chamber takes over the multiplier: its field is then the
    // physical pressure, and the next step's multiplier is the change of the level over it (on
    // several walls, what each one's multiplier differs from the agreed one stays with it; a
    // membrane between two chambers carries the difference of theirs).
    const real lambda = c.lambda;
    fluid_->solver().shiftPressureLevel(c.fluidRegion, lambda);
    if (c.moving()) {
      c.bodyLambda -= lambda;
      c.bodyLambdaStart = c.bodyLambda;  // the next step's start (its first body loads take it)
    }
    for (const ChamberWall& w : c.walls) {
      Panel& p = panels_[static_cast<std::size_t>(w.panel)];
      MembraneSolver& s = p.module->solver();
      const real shift = s.volumeConstraint().sign * w.sign * lambda;
      s.shiftMultiplier(-w.sign * lambda);
      for (const RealView& v : {p.load, p.loadPrevious, p.filtered})
        if (v.extent(0) > 0) blas::shift(exec_, static_cast<lid_t>(v.extent(0)), shift, v);
    }
  }
}

}  // namespace mfsi
