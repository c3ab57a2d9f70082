#include "coupling/orchestrator/FsiCoupling.hpp"

#include "coupling/interface/InterfaceSegment.hpp"

#include "core/io/HostCopy.hpp"

#include "core/Error.hpp"
#include "core/Suggest.hpp"
#include "fluid/BoundaryConditions.hpp"
#include "fluid/Loads.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <unordered_map>

namespace mfsi {

using coupling::copySegmentToDevice;
using coupling::copySegmentToHost;
using coupling::InterfaceVector;
using coupling::kMaxShareRounds;
using coupling::kShareAgreement;

namespace {

/// An interface residual this many times the step's smallest one means the iteration diverges.
constexpr double kResidualGrowthLimit = 1e3;

}  // namespace

FsiCoupling::FsiCoupling(const CouplingOptions& options, const SceneConfig& section, HexMesh& mesh, Timers& timers,
                         std::unique_ptr<FluidModule> fluid, std::vector<std::unique_ptr<MembraneModule>> membranes,
                         std::unique_ptr<RigidModule> rigid, const RankDomain* domain)
    : Module("coupling"),
      options_(options),
      mesh_(mesh),
      domain_(domain != nullptr ? *domain : RankDomain{}),
      timers_(timers),
      fluid_(std::move(fluid)),
      ownedMembranes_(std::move(membranes)),
      rigid_(std::move(rigid)) {
  MFSI_CHECK(fluid_, "coupling: no fluid module");
  if (domain_.distributed()) MPI_Comm_rank(domain_.comm, &rank_);
  fluid_->solver().keepStepStart(options_.fluidFromStepStart);
  if (ownedMembranes_.empty() && options_.bodyPatches.empty())
    throw InputError(section.where(), "the coupling needs at least one membrane cut from the fluid mesh "
                                      "(membranes.N.mesh: baffles or boundaryPatch) or a rigid body (bodyPatches)");
  const fluid::BoundaryConditions& bc = fluid_->solver().boundaryConditions();
  std::vector<coupling::InterfaceBlock> layout;
  for (auto& m : ownedMembranes_) {
    const MembranePanelOptions& po = m->panel();
    if (po.mesh.kind != MembraneMeshKind::Baffle && po.mesh.kind != MembraneMeshKind::Patch)
      throw InputError(section.where(), m->name() + " is not cut from the fluid mesh: give it 'mesh: {baffles: ...}' "
                                                    "or 'mesh: {boundaryPatch: ...}' to couple it");
    Panel p;
    p.module = m.get();
    MFSI_CHECK(m->fluidSurface() != nullptr, "coupling: " << m->name() << " keeps no fluid surface");
    const FluidSurfaceMembraneInput& surf = *m->fluidSurface();
    const MembraneMesh& mm = m->solver().mesh();
    MFSI_CHECK(static_cast<lid_t>(surf.fluidNode.size()) == mm.nNodes() && surf.nElements() == mm.nElements(),
               "coupling: " << m->name() << "'s mesh does not match its fluid surface");
    const bool baffle = po.mesh.kind == MembraneMeshKind::Baffle;
    const std::string surface = baffle ? po.mesh.baffle : po.mesh.patch;
    p.surface = coupling::SurfaceGather(mesh_, domain_.comm, surf, surface,
                                        baffle ? coupling::InterfaceSide::Baffle : coupling::InterfaceSide::Patch);
    p.iface = p.surface.gatheredInterface();
    if (domain_.distributed()) p.owner = p.surface.ownerRank();
    p.dynamic = po.analysis == MembraneAnalysis::Dynamic;
    if (options_.interfaceMass > 0) {
      if (!p.dynamic)
        throw InputError(section.where("interfaceMass"),
                         "interfaceMass acts on a membrane's inertia: " + m->name() + " has 'analysis: static'");
      m->solver().setInterfaceMass(options_.interfaceMass);
    }
    // The fluid walls on the membrane must move with it: either they take the membrane velocity
    // (membraneWall: External), or the mesh velocity (movingWall).
    for (int pi : bc.find(surface)) {
      const fluid::ResolvedPatch& rp = bc.patches()[pi];
      const bool external = rp.type == fluid::BoundaryType::Wall && rp.bc.wallMotion == fluid::WallMotion::External;
      const bool meshVelocity =
          rp.type == fluid::BoundaryType::Wall && rp.bc.wallMotion == fluid::WallMotion::MeshVelocity;
      if (!external && !meshVelocity)
        throw InputError(section.where(), "fluid.boundary." + rp.name + " is under " + m->name() +
                                              ": make it 'type: membraneWall' (wall velocity from the membrane) or "
                                              "'type: movingWall' (from the mesh motion)");
      p.wallVelocity = p.wallVelocity || external;
    }
    p.load = RealView("mfsi::coupling::load", mm.nElements());
    p.loadPrevious = RealView("mfsi::coupling::loadPrevious", mm.nElements());
    if (options_.extrapolatedPredictor)
      p.loadLastStep = RealView("mfsi::coupling::loadLastStep", mm.nElements());
    p.faceVelocity = Real3View("mfsi::coupling::faceVelocity", mm.nElements());
    p.iterate = RealView("mfsi::coupling::iterate", 3 * mm.nNodes());
    if (options_.pNetSmoothIter > 0) {
      p.graph = coupling::elementGraph(mm.hostElements(), mm.elementAreas());
      p.smoothWork = RealView("mfsi::coupling::smoothWork", mm.nElements());
    }
    if (options_.pNetFilterTau > 0) p.filtered = RealView("mfsi::coupling::filteredLoad", mm.nElements());
    m->solver().loads().elementPressure = p.load;
    if (options_.viscousTraction) {
      p.force = Real3View("mfsi::coupling::viscousForce", mm.nNodes());
      p.forcePrevious = Real3View("mfsi::coupling::viscousForcePrevious", mm.nNodes());
      m->solver().loads().nodeForce = p.force;
    }
    p.offset = size_;
    layout.push_back({m->name(), size_, 3 * mm.nNodes()});
    size_ += 3 * mm.nNodes();
    panels_.push_back(std::move(p));
  }
  for (std::size_t i = 0; i < options_.motion.slidingPatches.size(); ++i) {
    const std::string& s = options_.motion.slidingPatches[i];
    if (mesh_.findPatch(s) < 0)
      throw InputError(section.where("meshMotion.slidingPatches." + std::to_string(i)), mesh_.noPatchMessage(s));
  }
  setUpBodies(section, layout);
  setUpParents(section);
  setUpChamber(section);
  groupChambers(section.where(options_.lumpedChamber.membrane.empty() ? "volumeConstraint" : "lumpedChamber"));
  smoother_ = std::make_unique<coupling::MeshSmoother>(mesh_, options_.motion, domain_);
  if (!options_.bodyReach.empty()) {
    std::vector<coupling::RigidBlend::Body> reach;
    for (const auto& r : options_.bodyReach) {
      const auto it = std::find_if(bodies_.begin(), bodies_.end(), [&](const CoupledBody& b) { return b.name == r.body; });
      reach_.slot.push_back(static_cast<int>(it - bodies_.begin()));
      reach.push_back({it->motion.allReferencePoints(), r.innerDistance, r.outerDistance});
    }
    reach_.blend = coupling::RigidBlend(reach, mesh_);
    reach_.base = Real3View("mfsi::coupling::rigidBase", mesh_.nNodes());
    reach_.transforms.resize(reach.size());
    smoother_->setBase(reach_.base);
  }
  if (options_.motion.distanceExponent > 0) {
    std::vector<std::array<real, 3>> moving;
    for (const Panel& p : panels_)  // the surface's points: the fluid nodes' reference positions
      for (const auto& x : p.module->fluidSurface()->mesh.points) moving.push_back(x);
    for (const CoupledBody& b : bodies_)
      for (const auto& x : b.motion.allReferencePoints()) moving.push_back(x);
    smoother_->setMovingNodes(moving);
  }
  if (options_.motion.columns) {
    std::vector<gid_t> feet;  // every membrane's nodes (each rank holds every membrane's surface)
    for (Panel& p : panels_) {
      const std::vector<gid_t>& nodes = p.module->fluidSurface()->fluidNode;
      std::vector<lid_t> row(nodes.size());
      for (std::size_t i = 0; i < nodes.size(); ++i) row[i] = static_cast<lid_t>(feet.size() + i);
      p.feet = p.iface;
      p.feet.fluidNode = toDevice(row, "mfsi::coupling::footRow");
      feet.insert(feet.end(), nodes.begin(), nodes.end());
    }
    columnFeet_ = static_cast<lid_t>(feet.size());
    columns_ = smoother_->setColumnFeet(feet);
    if (columns_ == 0)
      throw InputError(section.where("meshMotion.columns"),
                       "no column of cell edges leaves the membranes' nodes (a membrane on a boundary patch or a "
                       "baffle of a mesh extruded from it is needed)");
  }
  acceleration_ = coupling::makeAcceleration(options_.acceleration, layout);
}

std::vector<std::string> FsiCoupling::membraneNames() const {
  std::vector<std::string> names;
  for (const Panel& p : panels_) {  // the scene's names: module "membrane.<name>" -> "<name>"
    const std::string& n = p.module->panel().name;
    names.push_back(n.rfind("membrane.", 0) == 0 ? n.substr(9) : n);
  }
  return names;
}

Eigen::VectorXd FsiCoupling::bodyCoordinates(const InterfaceVector& x) const {
  if (bodies_.empty()) return {};
  return x.segment(bodyOffset_, rigid_->system().nDof());
}

void FsiCoupling::setUpBodies(const SceneConfig& section, std::vector<coupling::InterfaceBlock>& layout) {
  if (options_.bodyPatches.empty()) return;
  if (!rigid_) throw InputError(section.where("bodyPatches"), "bodyPatches needs the scene's 'bodies' section");
  if (options_.fsiStartTime > 0)
    throw InputError(section.where("fsiStartTime"),
                     "fsiStartTime > 0 with coupled rigid bodies is not supported yet (freeze a body with "
                     "bodies.newmark.accelerationDamping = 0 instead)");
  const RigidBodySystem& sys = rigid_->system();
  std::vector<std::string> bodyNames;
  for (int b = 0; b < sys.nBodies(); ++b) bodyNames.push_back(sys.model().bodyName(b));
  RigidTreeKinematics kin;
  sys.model().kinematics(sys.time(), sys.q(), sys.qdot(), sys.qddot(), kin);
  const fluid::BoundaryConditions& bc = fluid_->solver().boundaryConditions();
  for (const auto& bp : options_.bodyPatches) {
    const std::string key = "bodyPatches." + bp.body;
    if (std::find(bodyNames.begin(), bodyNames.end(), bp.body) == bodyNames.end())
      throw InputError(section.where(key), "the bodies section has no body '" + bp.body + "'" +
                                               didYouMean(bp.body, bodyNames) + "; bodies: " + joinList(bodyNames));
    CoupledBody b;
    b.index = sys.bodyIndex(bp.body);
    b.name = bp.body;
    b.patches = bp.patches;
    for (std::size_t i = 0; i < bp.patches.size(); ++i) {
      const std::string& name = bp.patches[i];
      const std::string at = key + "." + std::to_string(i);
      if (coupling::BodyPatchMotion::patchIndices(mesh_, name).empty())
        throw InputError(section.where(at), mesh_.noPatchMessage(name) + " (or a baffle of that name)");
      for (int pi : bc.find(name)) {
        const fluid::ResolvedPatch& rp = bc.patches()[pi];
        if (rp.type != fluid::BoundaryType::Wall || rp.bc.wallMotion != fluid::WallMotion::MeshVelocity)
          throw InputError(section.where(at), "fluid.boundary." + name + " moves with body " + bp.body +
                                                  ": make it 'type: movingWall' (wall velocity from the mesh motion)");
      }
    }
    b.motion = coupling::BodyPatchMotion(mesh_, bp.patches, domain_);
    b.com0 = kin.bodies[b.index].com;
    b.rotation0 = kin.bodies[b.index].frame.rotation;
    bodies_.push_back(std::move(b));
  }
  transforms_.resize(bodies_.size());
  // Bodies whose joints are all prescribed (or fixed) move the mesh without unknowns: one-way.
  bodyOffset_ = size_;
  if (sys.nDof() > 0) layout.push_back({"bodies", size_, sys.nDof()});
  size_ += sys.nDof();
}

void FsiCoupling::setUpParents(const SceneConfig& section) {
  if (options_.parentBodyPatches.empty()) return;
  const std::vector<std::string> names = membraneNames();
  for (const auto& pp : options_.parentBodyPatches) {
    const std::string key = "parentBodyPatches." + pp.membrane;
    auto it = std::find(names.begin(), names.end(), pp.membrane);
    if (it == names.end())
      throw InputError(section.where(key), "no coupled membrane '" + pp.membrane + "'" +
                                               didYouMean(pp.membrane, names) +
                                               "; membranes: " + joinList(names));
    Panel& p = panels_[static_cast<std::size_t>(it - names.begin())];
    if (p.wallVelocity)
      throw InputError(section.where(key), "the fluid walls of " + pp.membrane +
                                               " must take the mesh velocity on a moving frame: make them "
                                               "'type: movingWall' instead of membraneWall");
    std::vector<std::array<real, 3>> candidates;
    std::vector<int> candidateBody;
    for (std::size_t i = 0; i < pp.patches.size(); ++i) {
      const std::string& name = pp.patches[i];
      int slot = -1;
      for (std::size_t b = 0; b < bodies_.size() && slot < 0; ++b)
        if (std::find(bodies_[b].patches.begin(), bodies_[b].patches.end(), name) != bodies_[b].patches.end())
          slot = static_cast<int>(b);
      if (slot < 0)
        throw InputError(section.where(key + "." + std::to_string(i)),
                         "'" + name + "' is not a patch of a coupled body (bodyPatches)");
      const coupling::BodyPatchMotion patch(mesh_, {name}, domain_);
      for (const auto& x : patch.allReferencePoints()) {
        candidates.push_back(x);
        candidateBody.push_back(slot);
      }
    }
    p.parents = coupling::ParentFrames(p.module->solver().mesh().hostPoints(), candidates, candidateBody,
                                       static_cast<int>(bodies_.size()));
    p.mounted = true;
    const lid_t n = p.module->solver().mesh().nNodes();
    if (options_.viscousTraction || p.dynamic) {  // the FEM takes the viscous forces and the inertia in its frames
      p.forceFrame = Real3View("mfsi::coupling::nodeForceInFrames", n);
      p.module->solver().loads().nodeForce = p.forceFrame;
    }
    if (options_.viscousTraction || p.dynamic) p.nodePosition = Real3View("mfsi::coupling::mountedNodePosition", n);
    if (p.dynamic) {
      p.reaction = Real3View("mfsi::coupling::relativeInertia", n);
      p.inertia = Real3View("mfsi::coupling::frameInertia", n);
      p.framePosition = Real3View("mfsi::coupling::framePosition", n);
      if (options_.viscousTraction) p.nodeLoad = Real3View("mfsi::coupling::mountedNodeLoad", n);
      // The membrane's mass rides on its bodies: each node's share by its weights joins the body
      // (so a body's solve sees the mass it carries, and the FEM the frames' acceleration).
      RigidBodySystem& sys = rigid_->system();
      auto mass = Kokkos::create_mirror_view_and_copy(HostSpace(), p.module->solver().nodalMass());
      const auto& X = p.module->solver().mesh().hostPoints();
      for (std::size_t slot = 0; slot < bodies_.size(); ++slot) {
        std::vector<double> m;
        std::vector<Eigen::Vector3d> x;
        for (lid_t i = 0; i < n; ++i) {
          const double w = p.parents.weight(static_cast<std::size_t>(i), static_cast<int>(slot));
          if (w == 0) continue;
          m.push_back(w * mass(i));
          x.emplace_back(X[i][0], X[i][1], X[i][2]);
        }
        if (!m.empty()) sys.addPointMasses(bodies_[slot].index, m, x);
      }
    }
  }
  // The bodies' centres of mass moved with the masses they took on.
  const RigidBodySystem& sys = rigid_->system();
  RigidTreeKinematics kin;
  sys.model().kinematics(sys.time(), sys.q(), sys.qdot(), sys.qddot(), kin);
  for (CoupledBody& b : bodies_) {
    b.com0 = kin.bodies[b.index].com;
    b.rotation0 = kin.bodies[b.index].frame.rotation;
  }
}

void FsiCoupling::addOutputFields(io::FieldFrame& frame) {
  // A mounted panel is written at its fluid nodes (frame and membrane never gap). On several ranks
  // each rank fills in the nodes it owns and zeros elsewhere, and one sum gives rank 0 every node
  // exactly (each node has one owner): no rank gathers the mesh.
  std::vector<double> points;                   // this rank's mesh points, read once
  std::unordered_map<gid_t, std::size_t> owned;  // global node id -> this rank's owned node
  for (const Panel& p : panels_) {
    if (!p.mounted) continue;
    const std::vector<gid_t>& node = p.module->fluidSurface()->fluidNode;  // global node ids
    if (points.empty()) {
      points = io::hostValues(mesh_.points(), static_cast<std::size_t>(mesh_.nNodes()));
      if (domain_.distributed()) {
        auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh_.nodeGlobalIds());
        for (lid_t i = 0; i < mesh_.nOwnedNodes(); ++i) owned.emplace(gid(i), static_cast<std::size_t>(i));
      }
    }
    std::vector<double> x(3 * node.size(), 0.0);
    for (std::size_t i = 0; i < node.size(); ++i) {
      std::size_t at = static_cast<std::size_t>(node[i]);
      if (domain_.distributed()) {
        const auto it = owned.find(node[i]);
        if (it == owned.end()) continue;
        at = it->second;
      }
      for (std::size_t k = 0; k < 3; ++k) x[3 * i + k] = points[3 * at + k];
    }
    if (domain_.distributed())
      MPI_Reduce(rank_ == 0 ? MPI_IN_PLACE : x.data(), x.data(), static_cast<int>(x.size()), MPI_DOUBLE, MPI_SUM, 0,
                 domain_.comm);
    if (io::OutputGrid* grid = frame.find(p.module->name()); grid && rank_ == 0) grid->points = std::move(x);
  }
}

std::vector<Module*> FsiCoupling::parts() {
  std::vector<Module*> v{fluid_.get()};
  for (auto& m : ownedMembranes_) v.push_back(m.get());
  if (rigid_) v.push_back(rigid_.get());
  return v;
}

double FsiCoupling::loadScale(double t1) const {
  if (options_.fsiRampTime <= 0) return 1;
  return std::clamp((t1 - options_.fsiStartTime) / options_.fsiRampTime, 0.0, 1.0);
}

void FsiCoupling::advanceLoadFilter() {
  if (options_.pNetFilterTau <= 0) return;
  for (Panel& p : panels_) {
    Kokkos::deep_copy(exec_, p.filtered, p.load);
    p.haveFiltered = true;
  }
}

void FsiCoupling::updateLoads(double scale, bool relax, double dt, bool stepStart) {
  ScopedTimer timer(timers_, "coupling.transfer");
  const fluid::FluidSolver& f = fluid_->solver();
  double change2 = 0, norm2 = 0;
  for (Panel& p : panels_) {
    Kokkos::deep_copy(exec_, p.loadPrevious, p.load);
    p.surface.gather(exec_, f);
    coupling::interfacePressure(exec_, p.iface, p.surface.pressure(), options_.outsidePressure, scale,
                                options_.pClamp, p.load);
    if (options_.pNetSmoothIter > 0)
      coupling::smoothInterfacePressure(exec_, p.graph, p.load, p.smoothWork, options_.pNetSmoothIter);
    const RealView load = p.load, prev = p.loadPrevious;
    if (options_.pNetFilterTau > 0 && p.haveFiltered) {
      const real alpha = dt / (options_.pNetFilterTau + dt);
      const RealView old = p.filtered;
      Kokkos::parallel_for(
          "mfsi::coupling::loadFilter", RangePolicy(exec_, 0, p.iface.nElements()),
          KOKKOS_LAMBDA(lid_t e) { load(e) = alpha * load(e) + (1 - alpha) * old(e); });
    }
    const double w = relax ? options_.forceOmega : 1.0;
    double c = 0, n = 0;
    Kokkos::parallel_reduce(
        "mfsi::coupling::loadRelaxation", RangePolicy(exec_, 0, p.iface.nElements()),
        KOKKOS_LAMBDA(lid_t e, double& dc, double& dn) {
          const real v = w * load(e) + (1 - w) * prev(e);
          load(e) = v;
          dc += (v - prev(e)) * (v - prev(e));
          dn += v * v;
        },
        c, n);
    change2 += c;
    norm2 += n;
    if (!options_.viscousTraction) continue;
    Kokkos::deep_copy(exec_, p.forcePrevious, p.force);
    p.surface.gatherTraction(exec_, f);
    coupling::interfaceViscousForce(exec_, p.iface, p.module->solver().mesh().nodeElements(), 0,
                                    p.surface.faceAreaMag(), p.surface.viscousTractionFront(),
                                    p.surface.viscousTractionBack(), scale, p.force);
    // Relaxed like the pressure; the load residual is the pressure's alone (one unit).
    const Real3View force = p.force, fprev = p.forcePrevious;
    Kokkos::parallel_for(
        "mfsi::coupling::forceRelaxation", RangePolicy(exec_, 0, p.iface.nNodes()), KOKKOS_LAMBDA(lid_t i) {
          for (int k = 0; k < 3; ++k) force(i, k) = w * force(i, k) + (1 - w) * fprev(i, k);
        });
    // A mounted dynamic membrane's FEM load also carries its inertia: updateFrameInertia rotates
    // both before each structure solve.
    if (p.mounted && !p.dynamic) p.parents.toFrames(exec_, p.force, p.forceFrame);
  }
  updateBodyLoads(scale, stepStart);
  const SolverComm comm;
  change2 = comm.globalSum(change2);
  norm2 = comm.globalSum(norm2);
  forceResidual_ = norm2 > 0 ? std::sqrt(change2 / norm2) : (change2 > 0 ? 1.0 : 0.0);
}

void FsiCoupling::extrapolateLoads() {
  for (Panel& p : panels_) {
    // p_n+1 ~ 2 p_n - p_n-1; p_n is kept for the next step.
    const RealView load = p.load, last = p.loadLastStep;
    const bool have = p.haveLastStep;
    Kokkos::parallel_for(
        "mfsi::coupling::extrapolateLoad", RangePolicy(exec_, 0, p.iface.nElements()), KOKKOS_LAMBDA(lid_t e) {
          const real now = load(e);
          if (have) load(e) = 2 * now - last(e);
          last(e) = now;
        });
    p.haveLastStep = true;
  }
}

void FsiCoupling::updateFrameInertia() {
  if (bodies_.empty()) return;
  const RigidBodySystem& sys = rigid_->system();
  std::vector<coupling::ParentFrames::BodyAcceleration> acc(bodies_.size());
  for (std::size_t slot = 0; slot < bodies_.size(); ++slot) {
    const RigidBodyReport r = sys.bodyReport(bodies_[slot].index);
    for (int k = 0; k < 3; ++k) {
      acc[slot].centre[k] = r.position[k];
      acc[slot].acceleration[k] = r.acceleration[k];
      acc[slot].omega[k] = r.angularVelocity[k];
      acc[slot].alpha[k] = r.angularAcceleration[k];
    }
  }
  for (Panel& p : panels_) {
    if (p.inertia.extent(0) == 0) continue;
    MembraneSolver& s = p.module->solver();
    // At the step's start state (the committed displacement and velocity): the rotational terms'
    // lever and the Coriolis term's relative velocity.
    p.parents.setAccelerations(acc);
    p.parents.positions(exec_, s.mesh().referencePoints(), s.displacement(), p.framePosition);
    p.parents.inertialForce(exec_, p.framePosition, s.velocity(), s.nodalMass(), p.inertia);
    if (!options_.viscousTraction) {
      p.parents.toFrames(exec_, p.inertia, p.forceFrame);
      continue;
    }
    const Real3View load = p.nodeLoad, inertia = p.inertia, viscous = p.force;
    Kokkos::parallel_for(
        "mfsi::coupling::mountedNodeLoad", RangePolicy(exec_, 0, s.mesh().nNodes()), KOKKOS_LAMBDA(lid_t i) {
          for (int k = 0; k < 3; ++k) load(i, k) = inertia(i, k) + viscous(i, k);
        });
    p.parents.toFrames(exec_, p.nodeLoad, p.forceFrame);
  }
}

void FsiCoupling::updateBodyLoads(double scale, bool stepStart) {
  if (bodies_.empty()) return;
  const fluid::FluidSolver& f = fluid_->solver();
  RigidBodySystem& sys = rigid_->system();
  // Mounted membranes: the nodes' positions (the levers of nodal forces) and, for a dynamic one,
  // the reaction of its motion relative to the frames: at the step's start from the committed
  // state of membranes and bodies (what a restart has too), in an iteration from the trial state
  // at the iterate.
  if (stepStart) updateFrameInertia();
  for (Panel& p : panels_) {
    if (!p.mounted || p.nodePosition.extent(0) == 0) continue;
    MembraneSolver& s = p.module->solver();
    p.parents.positions(exec_, s.mesh().referencePoints(), stepStart ? s.displacement() : p.iterate, p.nodePosition);
    if (p.dynamic && p.parents.hasAccelerations())
      p.parents.relativeInertia(exec_, stepStart ? s.velocity() : s.trialVelocity(),
                                stepStart ? s.acceleration() : s.trialAcceleration(), s.nodalMass(), p.reaction);
  }
  for (std::size_t slot = 0; slot < bodies_.size(); ++slot) {
    const CoupledBody& b = bodies_[slot];
    // Force and moment about the body's centre of mass in its latest state.
    const Eigen::Vector3d c = sys.bodyReport(b.index).position;
    Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
    auto add = [&](const std::array<double, 6>& L) {
      for (int k = 0; k < 3; ++k) {
        force[k] += L[k];
        moment[k] += L[3 + k];
      }
    };
    for (const auto& patch : b.patches) {
      const fluid::PatchLoads L = fluid::patchLoads(f, patch, {c[0], c[1], c[2]});
      add({scale * L.force[0], scale * L.force[1], scale * L.force[2], scale * L.moment[0], scale * L.moment[1],
           scale * L.moment[2]});
    }
    // Mounted membranes pass their load (already scaled and relaxed) on to their bodies.
    for (const Panel& p : panels_) {
      if (!p.mounted) continue;
      const int s = static_cast<int>(slot);
      add(p.parents.bodyLoad(exec_, s, {c[0], c[1], c[2]}, p.module->solver().mesh().elementNodes(), p.load,
                             p.iface.front, 0, p.surface.faceArea(), p.surface.faceCentroid()));
      // The viscous nodal forces (relaxed, as the membrane receives them) at the nodes' positions.
      if (options_.viscousTraction) add(p.parents.nodeLoad(exec_, s, {c[0], c[1], c[2]}, p.nodePosition, p.force));
      // The reaction of the membrane's motion relative to the frames (its mass's share of the
      // frames' own motion is in the bodies' inertia).
      if (p.dynamic && p.parents.hasAccelerations())
        add(p.parents.nodeLoad(exec_, s, {c[0], c[1], c[2]}, p.nodePosition, p.reaction));
    }
    bodies_[slot].loadCentre = c;
    bodies_[slot].loadForce = force;
    bodies_[slot].loadMoment = moment;
  }
  applyBodyLoads();
}

void FsiCoupling::applyBodyLoads() {
  if (bodies_.empty()) return;
  RigidBodySystem& sys = rigid_->system();
  for (std::size_t slot = 0; slot < bodies_.size(); ++slot) {
    const CoupledBody& b = bodies_[slot];
    Eigen::Vector3d force = b.loadForce, moment = b.loadMoment;
    addChamberLoads(slot, force, moment);
    sys.setExternalLoad(b.index, force, moment);
  }
}

void FsiCoupling::solveStructure(double t1, double dt) {
  ScopedTimer timer(timers_, "coupling.structure");
  // Chambers with moving walls: the bodies move under the chamber's multiplier, the walls'
  // volumes take what the bodies' motion leaves, and their multiplier is the chamber's. The
  // multiplier the bodies are solved with is iterated by secant until the walls return it.
  const bool moving = std::any_of(chambers_.begin(), chambers_.end(), [](const Chamber& c) { return c.moving(); });
  std::vector<double> lambdaLast(chambers_.size()), missLast(chambers_.size());
  for (int sweep = 0;; ++sweep) {
    if (!bodies_.empty()) {
      RigidBodySystem& sys = rigid_->system();
      try {
        sys.solveStep(sys.time(), dt);
      } catch (const DivergenceError& e) {
        throw DivergenceError(std::string("bodies: the rigid step to t = ") + std::to_string(t1) +
                              " failed: " + e.what());
      }
    }
    updateFrameInertia();  // the bodies' accelerations of this solve
    followBodies();        // chambers the bodies bound: the walls' targets at the bodies' trial places
    solveMembranes(t1, dt);
    if (!moving || std::any_of(panels_.begin(), panels_.end(), [](const Panel& p) { return !p.report.converged; }))
      break;  // a failed solve is reported below
    bool again = false;
    for (std::size_t k = 0; k < chambers_.size(); ++k) {
      Chamber& c = chambers_[k];
      if (!c.moving()) continue;
      const double lambda = chamberMultiplier(c);
      const double miss = lambda - c.bodyLambda;
      // A sweep whose walls took no Newton iteration can tell no more.
      if ((sweep > 0 && !wallsIterated(c)) || std::abs(miss) <= kShareAgreement * options_.fsiTol * pressureScale(c))
        continue;
      if (sweep >= kMaxShareRounds) {
        std::ostringstream os;
        os << "coupling: the bodies and the membranes of a chamber ("
           << panels_[static_cast<std::size_t>(c.walls[0].panel)].module->name() << ", ...) did not agree on its "
           << "pressure in " << kMaxShareRounds << " sweeps of the step to t = " << t1
           << " (" << lambda << " Pa against " << c.bodyLambda << ")";
        throw DivergenceError(os.str());
      }
      const double next = sweep == 0 || miss == missLast[k]
                              ? lambda
                              : c.bodyLambda - miss * (c.bodyLambda - lambdaLast[k]) / (miss - missLast[k]);
      lambdaLast[k] = c.bodyLambda;
      missLast[k] = miss;
      c.bodyLambda = next;
      c.sweeps = std::max(c.sweeps, sweep + 1);
      c.maxSweepsRun = std::max(c.maxSweepsRun, c.sweeps);
      again = true;
    }
    // A wall blended between bodies: its volume beyond the frame-relative one moved with its
    // solve; the walls' targets follow it (followBodies) until the chambers' volumes hold.
    if (!again && blended_ && sweep + 1 < kMaxShareRounds && blendedMiss(nullptr) > 1) again = true;
    if (!again) break;
    applyBodyLoads();
  }
  for (Panel& p : panels_) {
    const MembraneSolveReport& rep = p.report;
    if (!rep.converged || !std::isfinite(rep.relativeResidual)) {
      std::ostringstream os;
      os << p.module->name() << ": the structure solve did not converge in the step to t = " << t1 << " ("
         << (last_.iterations == 0 ? std::string("the predictor on the loads of t_n")
                                   : "coupling iteration " + std::to_string(last_.iterations))
         << "; " << rep.iterations << " Newton iterations, relative residual " << rep.relativeResidual << ")";
      throw DivergenceError(os.str());
    }
  }
  ++last_.structureSolves;
}

void FsiCoupling::solveMembranes(double t1, double dt) {
  // On several ranks each membrane is solved by the rank that owns its faces, the ranks' membranes
  // at the same time; then every owner sends its answer to the others. The walls of a region
  // bounded by several membranes solve again on their moved shares until their multipliers agree
  // (each solve starts from its last answer); every rank moves the shares alike.
  std::vector<char> solve(panels_.size(), 1);
  for (int round = 1;; ++round) {
    for (std::size_t i = 0; i < panels_.size(); ++i) {
      Panel& p = panels_[i];
      if (!solve[i] || (p.owner >= 0 && p.owner != rank_)) continue;
      MembraneSolver& s = p.module->solver();
      p.report = p.dynamic ? s.solveStep(dt) : s.solveStatic(t1);
    }
    for (std::size_t i = 0; i < panels_.size(); ++i)
      if (solve[i] && panels_[i].owner >= 0) shareSolve(panels_[i], t1, dt);
    const std::vector<char> solved = solve;
    std::fill(solve.begin(), solve.end(), char(0));
    bool again = false;
    for (const ChamberGroup& g : groups_) {
      if (g.panels.size() < 2 || !solved[static_cast<std::size_t>(g.panels[0])]) continue;
      bool converged = true;  // a wall whose solve failed is reported below
      for (int p : g.panels) converged = converged && panels_[static_cast<std::size_t>(p)].report.converged;
      for (int k : g.chambers) {
        Chamber& c = chambers_[static_cast<std::size_t>(k)];
        c.rounds = std::max(c.rounds, round);
        c.maxRoundsRun = std::max(c.maxRoundsRun, round);
      }
      if (!converged || moveShares(g, round > 1)) continue;
      if (round >= kMaxShareRounds) {
        std::ostringstream os;
        os << "coupling: the membranes of a chamber ("
           << panels_[static_cast<std::size_t>(g.panels[0])].module->name() << ", ...) did not agree on its "
           << "pressure in " << kMaxShareRounds << " share rounds of the step to t = " << t1 << " (multipliers "
           << chambers_[static_cast<std::size_t>(g.chambers[0])].spread << " of the pressure apart)";
        throw DivergenceError(os.str());
      }
      for (int p : g.panels) solve[static_cast<std::size_t>(p)] = 1;
      again = true;
    }
    if (!again) break;
  }
}

void FsiCoupling::shareSolve(Panel& p, double t1, double dt) {
  ScopedTimer timer(timers_, "coupling.structureShare");
  MembraneSolver& s = p.module->solver();
  const bool mine = rank_ == p.owner;
  // The answer's Views (a step's trial state and the committed acceleration; a static solve's
  // displacement), then the report and the multiplier, in one message.
  std::vector<RealView> views;
  if (p.dynamic) {
    for (const RealView& v : s.stepResult()) views.push_back(v);
  } else {
    views.push_back(s.displacement());
  }
  std::size_t n = 0;
  for (const RealView& v : views) n += v.extent(0);
  constexpr std::size_t kReport = 8;
  std::vector<double> buffer(n + kReport);
  if (mine) {
    std::size_t at = 0;
    for (const RealView& v : views) {
      auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
      std::copy(h.data(), h.data() + h.extent(0), buffer.begin() + static_cast<std::ptrdiff_t>(at));
      at += h.extent(0);
    }
    const MembraneSolveReport& r = p.report;
    const double tail[kReport] = {r.converged ? 1.0 : 0.0, static_cast<double>(r.iterations),
                                  static_cast<double>(r.linearIterations), static_cast<double>(r.lineSearchSteps),
                                  r.relativeResidual, r.seconds, s.volumeConstraint().lambda,
                                  s.volumeConstraint().compliance};
    std::copy(tail, tail + kReport, buffer.begin() + static_cast<std::ptrdiff_t>(n));
  }
  MPI_Bcast(buffer.data(), static_cast<int>(buffer.size()), MPI_DOUBLE, p.owner, domain_.comm);
  if (mine) return;
  std::size_t at = 0;
  for (const RealView& v : views) {
    Kokkos::View<const double*, HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>> h(buffer.data() + at, v.extent(0));
    Kokkos::deep_copy(v, h);
    at += v.extent(0);
  }
  MembraneSolveReport& r = p.report;
  r.converged = buffer[n] != 0;
  r.iterations = static_cast<int>(buffer[n + 1]);
  r.linearIterations = static_cast<int>(buffer[n + 2]);
  r.lineSearchSteps = static_cast<int>(buffer[n + 3]);
  r.relativeResidual = buffer[n + 4];
  r.seconds = buffer[n + 5];
  s.volumeConstraint().compliance = buffer[n + 7];
  if (p.dynamic)
    s.adoptStep(dt, r, buffer[n + 6]);
  else
    s.adoptStatic(t1, r);
}

void FsiCoupling::gatherTrial(InterfaceVector& xt) const {
  for (const Panel& p : panels_) {
    MembraneSolver& s = p.module->solver();
    copySegmentToHost(p.dynamic ? s.trialDisplacement() : s.displacement(), xt, p.offset);
  }
  if (!bodies_.empty()) xt.segment(bodyOffset_, rigid_->system().nDof()) = rigid_->system().q();
}

void FsiCoupling::setTrial(InterfaceVector& x) {
  // A region bounded by several membranes: x's split of the volume among them is the
  // acceleration's (the mode in which they trade volume through the fluid is where a strong added
  // mass lives), so only the total is corrected, the miss shared by the walls' compliances (a
  // uniform change of the region's pressure). The structure solve's shares are kept for its next solve.
  // With moving walls the walls' total is what the bodies' places at x leave. A wall blended
  // between bodies adds a volume of its own displacement to that: the targets and the projection
  // repeat until the chambers' volumes hold at x.
  std::vector<std::pair<MembraneVolumeConstraint*, real>> shares;
  for (int pass = 0;; ++pass) {
    targetsFor(x, pass == 0 ? &shares : nullptr);
    for (std::size_t i = 0; i < panels_.size(); ++i) {
      Panel& p = panels_[i];
      if (!p.dynamic || chamberOf(static_cast<int>(i)) < 0) continue;
      // A relaxed iterate misses the volume to second order in its update: the fluid must get one
      // it can follow.
      copySegmentToDevice(x, p.offset, p.iterate);
      p.module->solver().projectOntoVolume(p.iterate);
      copySegmentToHost(p.iterate, x, p.offset);
    }
    if (!blended_ || pass + 1 >= kMaxShareRounds || blendedMiss(&x) <= 1) break;
  }
  for (Panel& p : panels_) {
    MembraneSolver& s = p.module->solver();
    if (p.dynamic) {
      copySegmentToDevice(x, p.offset, p.iterate);
      s.setTrialDisplacement(p.iterate);
    } else {
      copySegmentToDevice(x, p.offset, s.displacement());
    }
  }
  for (const auto& [vc, share] : shares) vc->target = share;
  if (!chambers_.empty()) checkChamberVolume(x);
}

void FsiCoupling::commitStructure() {
  for (Panel& p : panels_)
    if (p.dynamic) p.module->solver().commitStep();
  if (!bodies_.empty()) {
    rigid_->system().commitStep();
    rigid_->recordStep();
  }
}

bool FsiCoupling::limitUpdate(InterfaceVector& x, const InterfaceVector& previous, double dt) const {
  bool limited = false;
  if (options_.maxDeltaDispFrac > 0)
    for (const Panel& p : panels_) {
      const MembraneMesh& mm = p.module->solver().mesh();
      const double cap = options_.maxDeltaDispFrac * std::sqrt(mm.referenceArea());
      for (Eigen::Index i = 0; i < 3 * Eigen::Index(mm.nNodes()); i += 3) {
        const Eigen::Index o = p.offset + i;
        const double n = (x.segment<3>(o) - previous.segment<3>(o)).norm();
        if (n <= cap) continue;
        x.segment<3>(o) = previous.segment<3>(o) + (cap / n) * (x.segment<3>(o) - previous.segment<3>(o));
        limited = true;
      }
    }
  if (options_.maxMeshVelocity > 0 && !bodies_.empty() && rigid_->system().nDof() > 0) {
    // The largest factor on the coordinate update that keeps every coupled body's centre within the limit.
    const RigidBodySystem& sys = rigid_->system();
    const Eigen::Index n = sys.nDof();
    const Eigen::VectorXd q0 = previous.segment(bodyOffset_, n), q1 = x.segment(bodyOffset_, n),
                          zero = Eigen::VectorXd::Zero(n);
    RigidTreeKinematics k0, k1;
    sys.model().kinematics(stepEnd_, q0, zero, zero, k0);
    sys.model().kinematics(stepEnd_, q1, zero, zero, k1);
    const double cap = options_.maxMeshVelocity * dt;
    double factor = 1;
    for (const CoupledBody& b : bodies_) {
      const double move = (k1.bodies[b.index].com - k0.bodies[b.index].com).norm();
      if (move > cap) factor = std::min(factor, cap / move);
    }
    if (factor < 1) {
      x.segment(bodyOffset_, n) = q0 + factor * (q1 - q0);
      limited = true;
    }
  }
  return limited;
}

std::vector<RigidPlacement> FsiCoupling::placementsOf(const Eigen::VectorXd& q) const {
  const RigidBodySystem& sys = rigid_->system();
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(sys.nDof());
  RigidTreeKinematics kin;
  sys.model().kinematics(stepEnd_, q, zero, zero, kin);
  std::vector<RigidPlacement> t(bodies_.size());
  for (std::size_t slot = 0; slot < bodies_.size(); ++slot) {
    const CoupledBody& b = bodies_[slot];
    t[slot] = placementFromStart(b.com0, b.rotation0, kin.bodies[b.index].com, kin.bodies[b.index].frame.rotation);
  }
  return t;
}

void FsiCoupling::placeBodies(const InterfaceVector& x) {
  if (bodies_.empty()) return;
  transforms_ = placementsOf(x.segment(bodyOffset_, rigid_->system().nDof()));
  for (std::size_t slot = 0; slot < bodies_.size(); ++slot)
    bodies_[slot].motion.apply(exec_, transforms_[slot], smoother_->displacement());
  if (!reach_.blend.empty()) {
    for (std::size_t i = 0; i < reach_.slot.size(); ++i) reach_.transforms[i] = transforms_[reach_.slot[i]];
    reach_.blend.displacement(exec_, reach_.transforms, reach_.base);
  }
  for (Panel& p : panels_)
    if (p.mounted) p.parents.setTransforms(transforms_);
}

void FsiCoupling::moveMesh(const InterfaceVector& x) {
  {
    ScopedTimer timer(timers_, "coupling.transfer");
    placeBodies(x);
    for (Panel& p : panels_) {
      copySegmentToDevice(x, p.offset, p.iterate);
      auto place = [&](const coupling::MembraneInterface& iface, const Real3View& target) {
        if (p.mounted)
          p.parents.displacement(exec_, p.module->solver().mesh().referencePoints(), p.iterate, iface.fluidNode,
                                 target);
        else
          coupling::interfaceDisplacement(exec_, iface, p.iterate, target);
      };
      place(p.iface, smoother_->displacement());  // the membrane's nodes on this rank's part
      if (p.feet.nNodes() > 0) place(p.feet, smoother_->columnFeet());  // every node, on every rank
    }
  }
  {
    ScopedTimer timer(timers_, "coupling.motion");
    coupling::MotionReport r;
    {
      ScopedTimer part(timers_, "coupling.motion.smoother");
      r = smoother_->move(exec_);
      exec_.fence();
    }
    last_.minScaledJacobian = std::min(last_.minScaledJacobian, r.minScaledJacobian);
    last_.motionIterations += r.sweeps;
    ScopedTimer part(timers_, "coupling.motion.fluidGeometry");
    fluid_->solver().moveMesh(mesh_.points());
    exec_.fence();
  }
  ScopedTimer timer(timers_, "coupling.transfer");
  for (Panel& p : panels_) {
    if (!p.wallVelocity) continue;
    MembraneSolver& s = p.module->solver();
    coupling::interfaceFaceVelocity(exec_, p.iface, s.mesh().elementNodes(), s.trialVelocity(), p.faceVelocity);
    p.surface.setWallVelocity(exec_, fluid_->solver(), p.faceVelocity);
  }
}

bool FsiCoupling::moveMeshGuarded(InterfaceVector& x, InterfaceVector& good) {
  const InterfaceVector target = x;
  double fraction = 1;
  for (int cut = 0;; ++cut) {
    try {
      moveMesh(x);
      good = x;
      return cut == 0;
    } catch (const DivergenceError&) {
      if (cut == 6) throw;
      ++last_.cutBacks;
      fraction *= 0.5;
      x = good + fraction * (target - good);
      setTrial(x);
    }
  }
}

void FsiCoupling::solveFluid(const TimeState& t) {
  ScopedTimer timer(timers_, "coupling.fluid");
  if (options_.fluidFromStepStart && last_.iterations > 0) fluid_->solver().restoreStepStart();
  fluid_->solveIteration(t);
  ++last_.iterations;
}

void FsiCoupling::advance(const TimeState& t) {
  const double t1 = t.time + t.dt;
  stepEnd_ = t1;
  last_ = StepReport{};
  fluid_->beginStep(t);
  if (t1 <= options_.fsiStartTime + 1e-12 * std::max(1.0, std::abs(t1))) {
    // The structure is frozen and the mesh fixed until fsiStartTime.
    solveFluid(t);
    for (Panel& p : panels_) p.module->solver().setTime(t1);
    for (Chamber& c : chambers_) c.sweptLast = 0;
    fluid_->endStep();
    last_.converged = true;
    ++steps_;
    return;
  }
  for (Panel& p : panels_) {
    p.module->solver().setTime(t.time);
    p.module->solver().discardStep();
  }
  const double scale = loadScale(t1);
  updateLoads(scale, false, t.dt, true);  // the loads of the fluid at t_n (the structure goes first)
  if (options_.extrapolatedPredictor) extrapolateLoads();
  InterfaceVector x(size_), xt(size_), good(size_);
  for (const Panel& p : panels_) copySegmentToHost(p.module->solver().displacement(), good, p.offset);  // the mesh is there
  if (!bodies_.empty()) good.segment(bodyOffset_, rigid_->system().nDof()) = rigid_->system().q();  // the bodies too
  acceleration_->beginStep();
  const bool implicit = options_.scheme == CouplingScheme::Implicit;
  // The structure goes first, on the loads of t_n: its answer is the predictor x_1 (and the whole
  // step's answer in the explicit scheme). It is not a value of the fixed-point map of this step
  // (the fluid has not seen t_n+1 yet), so it never enters the acceleration's history.
  beginChamberStep();
  solveStructure(t1, t.dt);
  gatherTrial(x);
  checkChamberVolume(x);
  double smallestResidual = std::numeric_limits<double>::infinity();
  for (;;) {
    // An iterate the mesh cannot follow (a quasi-Newton step too far) is cut back towards the last
    // one it could, and the acceleration starts afresh from there.
    if (!moveMeshGuarded(x, good)) acceleration_->resetHistory();
    solveFluid(t);
    updateLoads(scale, true, t.dt);
    if (!implicit) break;
    solveStructure(t1, t.dt);
    gatherTrial(xt);
    checkChamberVolume(xt);
    const double nx = acceleration_->norm(xt), nr = acceleration_->norm(xt - x);
    last_.displacementResidual = nx > 0 ? nr / nx : nr;
    last_.forceResidual = forceResidual_;
    // An iteration that diverges (an Aitken omega that cannot reach the secant of a strong
    // added-mass map, a poor quasi-Newton model) is stopped here with its cause, before its
    // growing iterates break the fluid or the mesh.
    smallestResidual = std::min(smallestResidual, nr);
    if (!std::isfinite(nr) || (smallestResidual > 0 && nr > kResidualGrowthLimit * smallestResidual)) {
      std::ostringstream os;
      os << "coupling: the interface residual grew from " << smallestResidual << " to " << nr << " within the step to t = "
         << t1 << " (" << last_.iterations << " iterations): the coupling iteration diverges; ";
      // A fluid whose outer loop stops short of its tolerance answers each iterate with its own
      // error: that, not the coupling, is then what to mend first.
      const fluid::StepResult& fr = fluid_->lastStep();
      const fluid::PimpleOptions& po = fluid_->solver().options().pimple;
      if (po.outerTolerance > 0 && !fr.converged)
        os << "the fluid's outer loop did not converge in its last solve (" << fr.outerIterations
           << " outer correctors, final pressure residual " << fr.finalPressureResidual << " against outerTolerance "
           << po.outerTolerance << "): more fluid.pimple.correctors or nonOrthogonalCorrectors, or a smaller time "
           << "step, may be needed; ";
      os << "with Aitken, a strong added mass may need omegaMin below 1 / (1 + m_added / m), or IQN-ILS "
         << "(iqnMaxCols > 0)";
      throw DivergenceError(os.str());
    }
    const bool small = last_.displacementResidual < options_.fsiTol &&
                       (options_.convergence == CouplingConvergence::Displacement || forceResidual_ < options_.fsiTol);
    if (last_.iterations >= options_.minFsiIter && small) {
      last_.converged = true;
      break;
    }
    if (last_.iterations >= options_.maxFsiIter) break;
    ScopedTimer timer(timers_, "coupling.acceleration");
    const InterfaceVector previous = x;
    const coupling::AccelerationReport ar = acceleration_->update(xt, x);
    last_.omega = ar.omega;
    last_.columns = ar.columns;
    if (limitUpdate(x, previous, t.dt)) ++last_.limited;
    setTrial(x);
  }
  {
    ScopedTimer timer(timers_, "coupling.acceleration");  // IQN-IMVJ updates its Jacobian here
    acceleration_->endStep();
  }
  // Converged (or explicit): the structure's last answer is committed; the fluid saw the mesh at x,
  // within fsiTol of it. Not converged: the last relaxed iterate, which the mesh and fluid match.
  if (!last_.converged && implicit) setTrial(x);
  endChamberStep(good);
  commitStructure();
  shiftChamberLevels();
  advanceLoadFilter();
  fluid_->endStep();
  for (Panel& p : panels_) p.module->sampleState();
  ++steps_;
  iterationsTotal_ += last_.iterations;
  maxIterations_ = std::max(maxIterations_, last_.iterations);
  cutBacksTotal_ += last_.cutBacks;
  limitedTotal_ += last_.limited;
  minJacobian_ = std::min(minJacobian_, last_.minScaledJacobian);
  if (implicit && !last_.converged) {
    ++unconvergedSteps_;
    if (++unconvergedInARow_ >= options_.maxUnconvergedSteps) {
      std::ostringstream os;
      os << "coupling: maxFsiIter = " << options_.maxFsiIter << " reached on " << unconvergedInARow_
         << " steps in a row (step to t = " << t1 << ": displacement residual " << last_.displacementResidual
         << ", load residual " << last_.forceResidual << ", fsiTol " << options_.fsiTol
         << "); try IQN-ILS (iqnMaxCols), a smaller time step or forceOmega < 1";
      throw DivergenceError(os.str());
    }
  } else {
    unconvergedInARow_ = 0;
  }
  if (!std::isfinite(last_.displacementResidual) || !std::isfinite(last_.forceResidual))
    throw DivergenceError("coupling: non-finite interface residual in the step to t = " + std::to_string(t1));
}

std::vector<std::string> FsiCoupling::stepColumns() const {
  std::vector<std::string> c{"iterations",        "displacementResidual", "forceResidual",    "omega",  "columns",
                             "minScaledJacobian", "cutBacks",             "motionIterations", "limited"};
  for (std::size_t k = 0; k < chambers_.size(); ++k) {
    for (const char* name : {"chamberVolumeStep", "chamberVolumeMiss", "chamberPressure"})
      c.push_back(chamberName(k, name));
    if (chambers_[k].walls.size() > 1)  // the share rounds and the multipliers' last disagreement
      for (const char* name : {"chamberShareRounds", "chamberMultiplierSpread"}) c.push_back(chamberName(k, name));
    if (chambers_[k].moving()) c.push_back(chamberName(k, "chamberSweeps"));  // the bodies' multiplier sweeps
  }
  return c;
}

void FsiCoupling::appendStepValues(std::vector<double>& v) const {
  v.insert(v.end(), {double(last_.iterations), last_.displacementResidual, last_.forceResidual, last_.omega,
                     double(last_.columns), last_.minScaledJacobian, double(last_.cutBacks),
                     double(last_.motionIterations), double(last_.limited)});
  for (const Chamber& c : chambers_) {
    v.insert(v.end(), {c.volumeStep, c.volumeMiss, c.pressure});
    if (c.walls.size() > 1) v.insert(v.end(), {double(c.rounds), c.spread});
    if (c.moving()) v.push_back(double(c.sweeps));
  }
}

void FsiCoupling::addMetrics(std::map<std::string, double>& m) const {
  m["coupling.steps"] = double(steps_);
  m["coupling.mean_iterations"] = steps_ > 0 ? double(iterationsTotal_) / double(steps_) : 0.0;
  m["coupling.max_iterations"] = maxIterations_;
  // Which rank solves each membrane (-1: every rank), and how many rank 0 solves.
  int solvedOnRank0 = 0;
  for (const Panel& p : panels_) {
    m["coupling." + p.module->name() + ".solved_on_rank"] = !domain_.distributed() ? 0 : p.owner;
    solvedOnRank0 += p.owner <= 0 ? 1 : 0;
  }
  m["coupling.membranes_solved_on_rank0"] = solvedOnRank0;
  if (options_.motion.columns) {  // how many membrane nodes carry a column (the rim's and the edges' do not)
    m["coupling.mesh_motion_columns"] = double(columns_);
    m["coupling.mesh_motion_column_feet"] = double(columnFeet_);
    m["coupling.mesh_motion_columns_across_ranks"] = double(smoother_->columnsAcrossRanks());
  }
  m["coupling.unconverged_steps"] = double(unconvergedSteps_);
  m["coupling.min_scaled_jacobian"] = minJacobian_;
  m["coupling.cut_backs"] = double(cutBacksTotal_);
  m["coupling.limited_updates"] = double(limitedTotal_);
  for (std::size_t k = 0; k < chambers_.size(); ++k) {
    const Chamber& c = chambers_[k];
    m[chamberName(k, "coupling.chamber_max_volume_miss")] = c.maxMissRun;
    m[chamberName(k, "coupling.chamber_volume")] = c.volumeStart;
    m[chamberName(k, "coupling.chamber_pressure")] = c.pressure;
    if (c.walls.size() > 1) m[chamberName(k, "coupling.chamber_max_share_rounds")] = c.maxRoundsRun;
    if (c.moving()) m[chamberName(k, "coupling.chamber_max_sweeps")] = c.maxSweepsRun;
  }
  const auto& all = timers_.all();
  auto seconds = [&](const char* k) {
    auto it = all.find(k);
    return it == all.end() ? 0.0 : it->second;
  };
  const double st = seconds("coupling.structure"), mo = seconds("coupling.motion"), fl = seconds("coupling.fluid"),
               ac = seconds("coupling.acceleration"), tr = seconds("coupling.transfer");
  const double total = st + mo + fl + ac + tr;
  m["coupling.time_structure_s"] = st;
  m["coupling.time_motion_s"] = mo;
  m["coupling.time_fluid_s"] = fl;
  m["coupling.time_acceleration_s"] = ac;
  m["coupling.time_transfer_s"] = tr;
  if (total > 0) m["coupling.share_motion_transfer_acceleration"] = (mo + ac + tr) / total;
}

ModuleEntry couplingModuleEntry() {
  return {"coupling", &couplingSchema, [](const SceneConfig& section, SimulationContext& ctx) {
            std::vector<std::unique_ptr<Module>> out;
            if (ctx.mesh == nullptr || ctx.built == nullptr)
              throw InputError(section.where(), "the coupling needs the scene's 'mesh' and 'fluid' sections");
            std::unique_ptr<FluidModule> fluid;
            std::vector<std::unique_ptr<MembraneModule>> membranes;
            std::unique_ptr<RigidModule> rigid;
            const CouplingOptions options = readCouplingOptions(section);
            std::vector<std::unique_ptr<Module>> rest;
            for (auto& m : *ctx.built) {
              if (auto* f = dynamic_cast<FluidModule*>(m.get())) {
                fluid.reset(f);
                m.release();
              } else if (auto* mm = dynamic_cast<MembraneModule*>(m.get());
                         mm != nullptr && (mm->panel().mesh.kind == MembraneMeshKind::Baffle ||
                                           mm->panel().mesh.kind == MembraneMeshKind::Patch)) {
                membranes.emplace_back(mm);
                m.release();
              } else if (auto* r = dynamic_cast<RigidModule*>(m.get()); r != nullptr && !options.bodyPatches.empty()) {
                rigid.reset(r);
                m.release();
              } else {
                rest.push_back(std::move(m));
              }
            }
            *ctx.built = std::move(rest);
            if (!fluid) throw InputError(section.where(), "the coupling needs the scene's 'fluid' section");
            out.push_back(std::make_unique<FsiCoupling>(options, section, *ctx.mesh, *ctx.timers, std::move(fluid),
                                                        std::move(membranes), std::move(rigid), ctx.domain));
            return out;
          }};
}

// The fluid, the membranes and the bodies write their own state (they are parts of the run);
// the coupling adds what it carries between steps: the loads in use (and filtered), the wall
// velocities, the mesh motion's warm start, the bodies' transforms, the acceleration's history
// (IQN-ILS columns reused across steps) and its counters.
void FsiCoupling::saveState(io::StateWriter& w) const {
  exec_.fence();
  for (std::size_t i = 0; i < panels_.size(); ++i) {
    const Panel& p = panels_[i];
    io::StateWriter pw = w.sub("panel" + std::to_string(i));
    pw.putView("load", p.load);
    pw.putView("loadPrevious", p.loadPrevious);
    pw.putView("force", p.force);
    pw.putView("forcePrevious", p.forcePrevious);
    pw.putView("faceVelocity", p.faceVelocity);
    pw.putView("filtered", p.filtered);
    pw.putBool("haveFiltered", p.haveFiltered);
    if (options_.extrapolatedPredictor) {
      pw.putView("loadLastStep", p.loadLastStep);
      pw.putBool("haveLastStep", p.haveLastStep);
    }
  }
  std::vector<double> tr;
  for (const auto& T : transforms_) {
    const std::array<real, 15> f = T.flat();  // origin, placed origin, rotation
    tr.insert(tr.end(), f.begin(), f.end());
  }
  w.put("transforms", tr);
  if (smoother_) {
    io::StateWriter sw = w.sub("meshMotion");
    smoother_->saveState(sw);
  }
  io::StateWriter aw = w.sub("acceleration");
  acceleration_->saveState(aw);
  const StepReport& l = last_;
  w.put("lastStep", std::vector<double>{double(l.iterations), double(l.structureSolves), double(l.converged),
                                        l.displacementResidual, l.forceResidual, l.omega, double(l.columns),
                                        l.minScaledJacobian, double(l.cutBacks), double(l.motionIterations),
                                        double(l.limited), stepEnd_, forceResidual_, minJacobian_});
  w.put("counters", std::vector<std::int64_t>{steps_, iterationsTotal_, unconvergedSteps_, unconvergedInARow_,
                                              cutBacksTotal_, limitedTotal_, maxIterations_});
  // The first chamber's as "chamber" (the checkpoints of a single chamber), the others' as
  // "chamber1", "chamber2", ...
  for (std::size_t k = 0; k < chambers_.size(); ++k) {
    const Chamber& c = chambers_[k];
    const std::string key = k == 0 ? std::string("chamber") : "chamber" + std::to_string(k);
    w.put(key, std::vector<double>{c.volumeStart, c.sweptLast, c.maxMissRun, c.volumeStep, c.volumeMiss, c.pressure});
    if (c.moving()) w.put(key + "Rigid", std::vector<double>{c.rigidStart, c.bodyLambda});
    if (c.walls.size() < 2 && !c.moving()) continue;
    // Several or moving walls: each one's start volume and compliance (the next step's split).
    std::vector<double> walls;
    for (const ChamberWall& cw : c.walls)
      walls.insert(walls.end(), {cw.volumeStart, double(memberSolver(cw).volumeConstraint().compliance)});
    w.put(key + "Walls", walls);
    w.put(key + "Rounds", std::vector<std::int64_t>{c.maxRoundsRun, c.maxSweepsRun});
  }
}

void FsiCoupling::loadState(const io::StateReader& r) {
  for (std::size_t i = 0; i < panels_.size(); ++i) {
    Panel& p = panels_[i];
    const io::StateReader pr = r.sub("panel" + std::to_string(i));
    pr.getView("load", p.load);
    pr.getView("loadPrevious", p.loadPrevious);
    pr.getView("force", p.force);
    pr.getView("forcePrevious", p.forcePrevious);
    pr.getView("faceVelocity", p.faceVelocity);
    // A load filter switched on at a restart (--allow-changes) starts afresh, as at a run's start
    // (its first step unfiltered, then from that step's load); one switched off leaves its state.
    const std::vector<std::size_t> stored = pr.shape("filtered");
    const bool filterStored = !stored.empty() && stored[0] > 0;
    if (p.filtered.extent(0) > 0 && filterStored) pr.getView("filtered", p.filtered);
    p.haveFiltered = p.filtered.extent(0) > 0 && filterStored && pr.boolean("haveFiltered");
    if (options_.extrapolatedPredictor) {
      pr.getView("loadLastStep", p.loadLastStep);
      p.haveLastStep = pr.boolean("haveLastStep");
    }
  }
  const auto tr = r.doubles("transforms", 15 * static_cast<long long>(transforms_.size()));
  for (std::size_t b = 0; b < transforms_.size(); ++b) transforms_[b] = RigidPlacement::fromFlat(tr.data() + 15 * b);
  if (!transforms_.empty())
    for (Panel& p : panels_)
      if (p.mounted) p.parents.setTransforms(transforms_);
  if (smoother_) smoother_->loadState(r.sub("meshMotion"));
  acceleration_->loadState(r.sub("acceleration"));
  const auto v = r.doubles("lastStep", 14);
  StepReport& l = last_;
  l.iterations = static_cast<int>(v[0]);
  l.structureSolves = static_cast<int>(v[1]);
  l.converged = v[2] != 0;
  l.displacementResidual = v[3];
  l.forceResidual = v[4];
  l.omega = v[5];
  l.columns = static_cast<int>(v[6]);
  l.minScaledJacobian = v[7];
  l.cutBacks = static_cast<int>(v[8]);
  l.motionIterations = static_cast<int>(v[9]);
  l.limited = static_cast<int>(v[10]);
  stepEnd_ = v[11];
  forceResidual_ = v[12];
  minJacobian_ = v[13];
  const auto c = r.ints("counters", 7);
  steps_ = c[0];
  iterationsTotal_ = c[1];
  unconvergedSteps_ = c[2];
  unconvergedInARow_ = c[3];
  cutBacksTotal_ = c[4];
  limitedTotal_ = c[5];
  maxIterations_ = static_cast<int>(c[6]);
  for (std::size_t k = 0; k < chambers_.size(); ++k) {
    Chamber& c = chambers_[k];
    const auto ch = r.doubles(k == 0 ? std::string("chamber") : "chamber" + std::to_string(k), 6);
    double* to[6] = {&c.volumeStart, &c.sweptLast, &c.maxMissRun, &c.volumeStep, &c.volumeMiss, &c.pressure};
    for (int j = 0; j < 6; ++j) *to[j] = ch[static_cast<std::size_t>(j)];
    const std::string key = k == 0 ? std::string("chamber") : "chamber" + std::to_string(k);
    if (c.moving()) {
      const auto rigid = r.doubles(key + "Rigid", 2);
      c.rigidStart = c.rigidNow = rigid[0];
      c.bodyLambda = c.bodyLambdaStart = rigid[1];
    }
    if (c.walls.size() < 2 && !c.moving()) {
      c.walls[0].volumeStart = c.volumeStart;
      continue;
    }
    const auto walls = r.doubles(key + "Walls", 2 * static_cast<long long>(c.walls.size()));
    for (std::size_t i = 0; i < c.walls.size(); ++i) {
      c.walls[i].volumeStart = walls[2 * i];
      memberSolver(c.walls[i]).volumeConstraint().compliance = walls[2 * i + 1];
    }
    const auto rounds = r.ints(key + "Rounds", 2);
    c.maxRoundsRun = static_cast<int>(rounds[0]);
    c.maxSweepsRun = static_cast<int>(rounds[1]);
  }
}

}  // namespace mfsi
