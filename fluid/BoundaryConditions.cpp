#include "fluid/BoundaryConditions.hpp"

#include "core/Error.hpp"
#include "core/parallel/LocalMesh.hpp"

#include <algorithm>
#include <cmath>

namespace mfsi::fluid {

const char* toString(FaceKind k) {
  switch (k) {
    case kFaceVelocity:
      return "velocity";
    case kFaceWall:
      return "wall";
    case kFaceSlip:
      return "slip";
    case kFaceEmpty:
      return "empty";
    case kFacePressure:
      return "pressure";
  }
  return "?";
}

namespace {

FaceKind faceKindOf(BoundaryType t) {
  switch (t) {
    case BoundaryType::FixedVelocity:
    case BoundaryType::FlowRate:
      return kFaceVelocity;
    case BoundaryType::Wall:
      return kFaceWall;
    case BoundaryType::Slip:
      return kFaceSlip;
    case BoundaryType::Empty:
      return kFaceEmpty;
    case BoundaryType::FixedPressure:
    case BoundaryType::Resistance:
      return kFacePressure;
    case BoundaryType::Auto:
      break;
  }
  return kFaceWall;
}

// Parabolic shape factor in [0, 1] at x (1 for a uniform profile).
real shapeAt(const ResolvedPatch& rp, const real x[3]) {
  if (rp.bc.profile != Profile::Parabolic && rp.bc.profile != Profile::Linear) return 1.0;
  real s = 1.0;
  for (int d = 0; d < 3; ++d) {
    if (!rp.bc.parabolicAxes[d]) continue;
    real lo = rp.bc.parabolicMin[d], hi = rp.bc.parabolicMax[d];
    if (!(hi > lo)) {
      lo = rp.boxMin[d];
      hi = rp.boxMax[d];
    }
    const real xi = (x[d] - lo) / (hi - lo);
    s *= rp.bc.profile == Profile::Linear ? std::clamp(xi, 0.0, 1.0) : std::max(0.0, 4.0 * xi * (1.0 - xi));
  }
  return s;
}

}  // namespace

BoundaryConditions::BoundaryConditions(const HexMesh& mesh, const FluidOptions& opt, const SolverComm& comm)
    : mesh_(&mesh), comm_(comm), nIn_(mesh.nInternalFaces()), nOwned_(mesh.nOwnedCells()) {
  {
    auto own = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceOwner());
    ghostFace_.resize(mesh.nFaces() - nIn_);
    for (lid_t f = nIn_; f < mesh.nFaces(); ++f) ghostFace_[f - nIn_] = own(f) >= nOwned_;
  }
  const auto& mp = mesh.patches();
  std::vector<const PatchBC*> given(mp.size(), nullptr);
  for (const auto& [name, bc] : opt.boundaries) {
    int idx = mesh.findPatch(name);
    if (idx >= 0) {
      given[idx] = &bc;
      continue;
    }
    const int m = mesh.findPatch(name + "_master"), s = mesh.findPatch(name + "_slave");
    if (m >= 0 && s >= 0) {
      given[m] = given[s] = &bc;
      continue;
    }
    mesh.patchIndex(name);  // throws with the list of patches and a suggestion
  }

  auto hPts = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.referencePoints());
  auto hFn = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.faceNodes());
  for (std::size_t i = 0; i < mp.size(); ++i) {
    ResolvedPatch rp;
    rp.name = mp[i].name;
    rp.index = static_cast<int>(i);
    rp.start = mp[i].start;
    rp.size = mp[i].size;
    if (given[i]) rp.bc = *given[i];
    // The faces of ghost cells that lead to cells of other ranks: no row of this rank reads
    // them (the ghosts' values come from their owners), so they take the condition that reads
    // nothing and adds nothing.
    if (rp.name == kProcessorPatch && mp[i].kind == PatchKind::Patch) rp.bc.type = BoundaryType::Empty;
    if (rp.bc.type == BoundaryType::Auto) {
      switch (mp[i].kind) {
        case PatchKind::Wall:
          rp.bc.type = BoundaryType::Wall;
          break;
        case PatchKind::Symmetry:
          rp.bc.type = BoundaryType::Slip;
          break;
        case PatchKind::Empty:
          rp.bc.type = BoundaryType::Empty;
          break;
        case PatchKind::BaffleMaster:
        case PatchKind::BaffleSlave:
          rp.bc.type = BoundaryType::Wall;
          if (!given[i]) rp.bc.wallMotion = WallMotion::External;
          break;
        case PatchKind::Patch:
          MFSI_CHECK(false, "fluid: patch '" << rp.name << "' of mesh '" << mesh.source()
                                             << "' has no boundary condition (key fluid.boundaries." << rp.name << ")");
      }
    }
    rp.type = rp.bc.type;
    MFSI_CHECK(!(rp.type == BoundaryType::FlowRate && rp.bc.profile == Profile::Function),
               "fluid: patch '" << rp.name << "': a flow-rate inlet takes a uniform or parabolic profile");
    MFSI_CHECK(
        !(rp.type == BoundaryType::FixedVelocity && rp.bc.profile == Profile::Function && !rp.bc.velocityFunction),
        "fluid: patch '" << rp.name << "': profile 'function' needs a velocity function");
    MFSI_CHECK(!(rp.bc.timeFunction.kind != TimeFunction::Kind::Constant &&
                 rp.bc.timeFunction.kind != TimeFunction::Kind::Function && !(rp.bc.timeFunction.period > 0)),
               "fluid: patch '" << rp.name << "': time function period must be positive");
    if (rp.bc.timeFunction.kind == TimeFunction::Kind::HalfPowerSine) {
      const TimeFunction& tf = rp.bc.timeFunction;
      MFSI_CHECK(tf.pulseDuration >= 0 && tf.pulseDuration <= tf.period,
                 "fluid: patch '" << rp.name << "': half-power sine pulse duration " << tf.pulseDuration
                                  << " must be in (0, period = " << tf.period << "] (0: period / 2)");
      MFSI_CHECK(tf.exponent > 0,
                 "fluid: patch '" << rp.name << "': half-power sine exponent must be positive, got " << tf.exponent);
    }
    if (rp.type == BoundaryType::FixedPressure || rp.type == BoundaryType::Resistance) fixesPressure_ = true;
    // Bounding box of the patch nodes (reference configuration).
    rp.boxMin = {1e300, 1e300, 1e300};
    rp.boxMax = {-1e300, -1e300, -1e300};
    for (lid_t f = rp.start; f < rp.start + rp.size; ++f)
      for (int a = 0; a < 4; ++a)
        for (int d = 0; d < 3; ++d) {
          rp.boxMin[d] = std::min(rp.boxMin[d], hPts(hFn(f, a), d));
          rp.boxMax[d] = std::max(rp.boxMax[d], hPts(hFn(f, a), d));
        }
    for (int d = 0; d < 3; ++d) {
      rp.boxMin[d] = -comm.globalMax(-rp.boxMin[d]);
      rp.boxMax[d] = comm.globalMax(rp.boxMax[d]);
    }
    patches_.push_back(rp);
  }

  const lid_t nB = mesh.nBoundaryFaces();
  kind_ = IndexView("mfsi::fluid::bc::kind", nB);
  velocity_ = Real3View("mfsi::fluid::bc::velocity", nB);
  pressure_ = RealView("mfsi::fluid::bc::pressure", nB);
  external_ = Real3View("mfsi::fluid::bc::externalWallVelocity", nB);
  hVelocity_ = Kokkos::create_mirror_view(velocity_);
  hPressure_ = Kokkos::create_mirror_view(pressure_);
  hKind_ = Kokkos::create_mirror_view(kind_);
  for (const auto& rp : patches_) {
    for (lid_t f = rp.start; f < rp.start + rp.size; ++f) hKind_(f - nIn_) = faceKindOf(rp.type);
    hasValves_ = hasValves_ || rp.bc.valve.period > 0;
  }
  Kokkos::deep_copy(kind_, hKind_);
}

std::vector<int> BoundaryConditions::find(const std::string& name) const {
  std::vector<int> out;
  for (const auto& rp : patches_)
    if (rp.name == name || rp.name == name + "_master" || rp.name == name + "_slave") out.push_back(rp.index);
  return out;
}

void BoundaryConditions::update(const ExecSpace& exec, real t, const MeshGeometry& geo,
                                const ConstReal3View& faceMeshVelocity) {
  time_ = t;
  // Host evaluation of profiles: boundary-sized transfers only.
  auto hSf = Kokkos::create_mirror_view(geo.faceArea);
  auto hFc = Kokkos::create_mirror_view(geo.faceCentroid);
  bool needGeometry = false;
  for (const auto& rp : patches_)
    needGeometry = needGeometry || rp.type == BoundaryType::FixedVelocity || rp.type == BoundaryType::FlowRate;
  if (needGeometry) {
    Kokkos::deep_copy(hSf, geo.faceArea);
    Kokkos::deep_copy(hFc, geo.faceCentroid);
  }
  if (hasValves_) {
    // Valves: a closed one's faces are no-slip walls (no flow), an open one's the pressure condition.
    bool changed = false, anyOpen = false, anyPressure = false;
    for (auto& rp : patches_) {
      if (rp.type != BoundaryType::FixedPressure && rp.type != BoundaryType::Resistance) continue;
      anyPressure = true;
      const bool open = rp.bc.valve.open(t);
      anyOpen = anyOpen || open;
      if (open == rp.open) continue;
      changed = true;
      rp.open = open;
      if (!open) rp.currentFlowRate = 0;
      for (lid_t f = rp.start; f < rp.start + rp.size; ++f) {
        hKind_(f - nIn_) = open ? kFacePressure : kFaceWall;
        for (int d = 0; d < 3; ++d) hVelocity_(f - nIn_, d) = 0;
      }
    }
    // On a decomposed mesh a rank may hold no face of the pressure patches: the check is the
    // options', not the faces'.
    MFSI_CHECK(!anyPressure || anyOpen || !fixesPressure_,
               "fluid: at t = " << t << " every pressure boundary's valve is closed: the pressure level is undefined "
                                << "(give the valves overlapping open times, or a pressure boundary without a valve)");
    if (changed) Kokkos::deep_copy(exec, kind_, hKind_);
  }
  for (auto& rp : patches_) {
    const real ft = rp.bc.timeFunction(t);
    if (!rp.open) continue;  // a closed valve: a fixed wall
    switch (rp.type) {
      case BoundaryType::FixedVelocity:
        for (lid_t f = rp.start; f < rp.start + rp.size; ++f) {
          const real x[3] = {hFc(f, 0), hFc(f, 1), hFc(f, 2)};
          Vec3 u = rp.bc.velocity;
          if (rp.bc.profile == Profile::Function) {
            u = rp.bc.velocityFunction({x[0], x[1], x[2]}, t);
          } else {
            const real s = shapeAt(rp, x);
            for (int d = 0; d < 3; ++d) u[d] *= s;
          }
          for (int d = 0; d < 3; ++d) hVelocity_(f - nIn_, d) = ft * u[d];
        }
        break;
      case BoundaryType::FlowRate: {
        // Scale the shape so the discrete inflow sum_f u_f . S_f is exactly -Q(t).
        // Over the faces of every rank (a ghost cell's face is its owner's).
        real sum = 0;
        for (lid_t f = rp.start; f < rp.start + rp.size; ++f) {
          if (ghostFace_[f - nIn_]) continue;
          const real x[3] = {hFc(f, 0), hFc(f, 1), hFc(f, 2)};
          const real mag = std::sqrt(hSf(f, 0) * hSf(f, 0) + hSf(f, 1) * hSf(f, 1) + hSf(f, 2) * hSf(f, 2));
          sum += shapeAt(rp, x) * mag;
        }
        sum = comm_.globalSum(sum);
        MFSI_CHECK(sum > 0, "fluid: flow-rate patch '" << rp.name << "' has zero profile area");
        const real scale = rp.bc.flowRate * ft / sum;
        for (lid_t f = rp.start; f < rp.start + rp.size; ++f) {
          const real x[3] = {hFc(f, 0), hFc(f, 1), hFc(f, 2)};
          const real mag = std::sqrt(hSf(f, 0) * hSf(f, 0) + hSf(f, 1) * hSf(f, 1) + hSf(f, 2) * hSf(f, 2));
          const real s = shapeAt(rp, x);
          for (int d = 0; d < 3; ++d) hVelocity_(f - nIn_, d) = -scale * s * hSf(f, d) / mag;
        }
        break;
      }
      case BoundaryType::Wall:
        for (lid_t f = rp.start; f < rp.start + rp.size; ++f)
          for (int d = 0; d < 3; ++d)
            hVelocity_(f - nIn_, d) = rp.bc.wallMotion == WallMotion::Fixed ? ft * rp.bc.velocity[d] : 0.0;
        break;
      case BoundaryType::FixedPressure:
        rp.currentPressure = ft * rp.bc.pressure;
        for (lid_t f = rp.start; f < rp.start + rp.size; ++f) hPressure_(f - nIn_) = rp.currentPressure;
        break;
      case BoundaryType::Resistance:
        rp.currentPressure = rp.bc.resistance * rp.currentFlowRate + ft * rp.bc.pressure;
        for (lid_t f = rp.start; f < rp.start + rp.size; ++f) hPressure_(f - nIn_) = rp.currentPressure;
        break;
      default:
        break;
    }
  }
  Kokkos::deep_copy(exec, velocity_, hVelocity_);
  Kokkos::deep_copy(exec, pressure_, hPressure_);
  for (const auto& rp : patches_) {
    if (rp.type != BoundaryType::Wall || rp.bc.wallMotion == WallMotion::Fixed || rp.size == 0) continue;
    const auto range = Kokkos::make_pair(rp.start - nIn_, rp.start - nIn_ + rp.size);
    auto dst = Kokkos::subview(velocity_, range, Kokkos::ALL());
    if (rp.bc.wallMotion == WallMotion::External)
      Kokkos::deep_copy(exec, dst, Kokkos::subview(external_, range, Kokkos::ALL()));
    else
      Kokkos::deep_copy(exec, dst, Kokkos::subview(faceMeshVelocity, range, Kokkos::ALL()));
  }
  exec.fence();
}

void BoundaryConditions::updateResistance(const ExecSpace& exec, const ConstRealView& phi) {
  for (auto& rp : patches_) {
    if (rp.type != BoundaryType::Resistance || !rp.open) continue;
    real q = 0;
    const lid_t start = rp.start, nOwned = nOwned_;
    auto own = mesh_->faceOwner();
    Kokkos::parallel_reduce(
        "mfsi::fluid::bc::resistanceFlowRate", RangePolicy(exec, 0, rp.size),
        KOKKOS_LAMBDA(lid_t i, real & acc) {
          if (own(start + i) < nOwned) acc += phi(start + i);  // a ghost's face is its owner's
        },
        q);
    q = comm_.globalSum(q);
    rp.currentFlowRate = q;
    rp.currentPressure = rp.bc.resistance * q + rp.bc.timeFunction(time_) * rp.bc.pressure;
    Kokkos::deep_copy(exec, Kokkos::subview(pressure_, Kokkos::make_pair(start - nIn_, start - nIn_ + rp.size)),
                      rp.currentPressure);
  }
}

void BoundaryConditions::setWallVelocity(const std::string& name, const ConstReal3View& v) {
  const auto idx = find(name);
  MFSI_CHECK(!idx.empty(), "fluid: setWallVelocity: no patch or baffle named '" << name << "'");
  for (int i : idx) {
    auto& rp = patches_[i];
    MFSI_CHECK(rp.type == BoundaryType::Wall && rp.bc.wallMotion == WallMotion::External,
               "fluid: setWallVelocity: patch '" << rp.name << "' is not a wall with external motion");
    MFSI_CHECK(static_cast<lid_t>(v.extent(0)) == rp.size,
               "fluid: setWallVelocity: patch '" << rp.name << "' has " << rp.size << " faces, got " << v.extent(0));
    const auto range = Kokkos::make_pair(rp.start - nIn_, rp.start - nIn_ + rp.size);
    Kokkos::deep_copy(Kokkos::subview(external_, range, Kokkos::ALL()), v);
    // Take effect immediately (the solver re-reads the prescribed values every outer iteration).
    Kokkos::deep_copy(Kokkos::subview(velocity_, range, Kokkos::ALL()), v);
  }
}

void BoundaryConditions::saveState(io::StateWriter& w) const {
  w.putReal("time", time_);
  w.putView("velocity", velocity_, io::Entity::BoundaryFaces);
  w.putView("pressure", pressure_, io::Entity::BoundaryFaces);
  w.putView("external", external_, io::Entity::BoundaryFaces);
  // One pair per patch of the whole mesh (a rank's processor patch is its own, and a restart on
  // another rank count has another), in the mesh's patch order.
  std::vector<double> patchValues;
  for (const ResolvedPatch& rp : patches_)
    if (rp.name != kProcessorPatch) patchValues.insert(patchValues.end(), {rp.currentPressure, rp.currentFlowRate});
  w.put("patchPressureAndFlowRate", patchValues);
}

void BoundaryConditions::loadState(const io::StateReader& r) {
  time_ = r.real("time");
  r.getView("velocity", velocity_);
  r.getView("pressure", pressure_);
  r.getView("external", external_);
  Kokkos::deep_copy(hVelocity_, velocity_);
  Kokkos::deep_copy(hPressure_, pressure_);
  long long named = 0;
  for (const ResolvedPatch& rp : patches_) named += rp.name != kProcessorPatch;
  const auto patchValues = r.doubles("patchPressureAndFlowRate", 2 * named);
  std::size_t i = 0;
  for (ResolvedPatch& rp : patches_) {
    if (rp.name == kProcessorPatch) continue;
    rp.currentPressure = patchValues[2 * i];
    rp.currentFlowRate = patchValues[2 * i + 1];
    ++i;
  }
}

}  // namespace mfsi::fluid
