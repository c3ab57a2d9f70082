#include "structure/rigid/RigidConfig.hpp"

namespace mfsi {

namespace {

const std::vector<std::string> kAxes = {"Px", "Py", "Pz", "Rx", "Ry", "Rz"};

Schema timeFunctionSchema(const std::string& doc) {
  return Schema::map(doc + ": constant (value), linear (value + rate t) or sine (offset + amplitude sin(omega t + phase))")
      .key("type", Schema::choice("function kind", {"constant", "linear", "sine"}), Default("constant"))
      .key("value", Schema::real("constant value, or value at t = 0 (linear)", "m or rad"), Default(0.0))
      .key("rate", Schema::real("slope of a linear function", "1/s"), Default(0.0))
      .key("amplitude", Schema::real("sine amplitude", "m or rad"), Default(0.0))
      .key("omega", Schema::real("sine angular frequency", "rad/s"), Default(0.0))
      .key("phase", Schema::real("sine phase", "rad"), Default(0.0))
      .key("offset", Schema::real("sine offset", "m or rad"), Default(0.0));
}

RigidTimeFunction readTimeFunction(const SceneConfig& f) {
  const std::string type = f.get<std::string>("type");
  if (type == "linear") return RigidTimeFunction::linear(f.get<double>("value"), f.get<double>("rate"));
  if (type == "sine")
    return RigidTimeFunction::sine(f.get<double>("amplitude"), f.get<double>("omega"), f.get<double>("phase"),
                                   f.get<double>("offset"));
  return RigidTimeFunction::constant(f.get<double>("value"));
}

Eigen::Vector3d vec3(const SceneConfig& c, const std::string& key) {
  const auto a = c.get<std::array<double, 3>>(key);
  return {a[0], a[1], a[2]};
}

}  // namespace

Schema rigidSchema() {
  Schema joint = Schema::map("joint to the parent body (or the world)")
                     .key("type", Schema::choice("joint kind", {"fixed", "Px", "Py", "Pz", "Rx", "Ry", "Rz", "composite",
                                                                "prescribed"}))
                     .key("axes", Schema::list("composite/prescribed: elementary axes in order", Schema::choice("axis", kAxes)),
                          Presence::Optional)
                     .key("motion", Schema::list("prescribed: one function of time per axis", timeFunctionSchema("motion")),
                          Presence::Optional)
                     .key("origin", Schema::realVector(3, "joint location in the parent frame", "m"),
                          Default(std::array<double, 3>{0, 0, 0}))
                     .key("q0", Schema::list("initial coordinate per free axis", Schema::real("coordinate", "m or rad")),
                          Presence::Optional)
                     .key("qdot0", Schema::list("initial rate per free axis", Schema::real("rate", "m/s or rad/s")),
                          Presence::Optional);
  Schema body = Schema::map("a rigid body")
                    .key("parent", Schema::string("parent body, or world"), Default("world"))
                    .key("mass", Schema::real("mass", "kg").greaterThan(0))
                    .key("centreOfMass", Schema::realVector(3, "centre of mass in the body frame", "m"),
                         Default(std::array<double, 3>{0, 0, 0}))
                    .key("inertia", Schema::realVector(6, "Ixx Iyy Izz Ixy Ixz Iyz about the centre of mass", "kg m^2"),
                         Default(std::array<double, 6>{0, 0, 0, 0, 0, 0}))
                    .key("joint", joint);
  Schema restraint =
      Schema::map("a restraint acting on a body")
          .key("type", Schema::choice("restraint kind", {"linearSpring", "linearDamper", "angularDamper", "prescribedRotation"}))
          .key("body", Schema::string("body it acts on"))
          .key("anchor", Schema::realVector(3, "linearSpring: world anchor", "m"), Default(std::array<double, 3>{0, 0, 0}))
          .key("attachment", Schema::realVector(3, "linearSpring: point in the body frame", "m"),
               Default(std::array<double, 3>{0, 0, 0}))
          .key("stiffness", Schema::real("linearSpring: stiffness", "N/m").atLeast(0), Default(0.0))
          .key("damping", Schema::real("linearSpring: axial damping", "N s/m").atLeast(0), Default(0.0))
          .key("restLength", Schema::real("linearSpring: rest length", "m").atLeast(0), Default(0.0))
          .key("coefficient", Schema::real("linear/angularDamper: coefficient", "N s/m or N m s").atLeast(0), Default(0.0))
          .key("axis", Schema::integer("prescribedRotation: axis index in the joint (-1: first revolute)"), Default(-1))
          .key("angle", timeFunctionSchema("prescribedRotation: angle"), Presence::Optional)
          .key("frequency", Schema::real("prescribedRotation: drift-correction frequency (<= 0: 0.25/dt)", "rad/s"),
               Default(0.0))
          .key("dampingRatio", Schema::real("prescribedRotation: drift-correction damping ratio", "-").greaterThan(0),
               Default(1.0));
  Schema newmark =
      Schema::map("Newmark integration (OpenFOAM rigidBodyMotion semantics)")
          .key("gamma", Schema::real("Newmark gamma", "-").atLeast(0), Default(0.5))
          .key("beta", Schema::real("Newmark beta", "-").atLeast(0), Default(0.25))
          .key("accelerationRelaxation", Schema::real("under-relaxation of new accelerations", "-").greaterThan(0).atMost(1),
               Default(1.0))
          .key("accelerationDamping", Schema::real("factor on accelerations in the update (0 freezes)", "-").atLeast(0).atMost(1),
               Default(1.0))
          .key("iteration", Schema::choice("solution of the implicit step", {"newton", "fixedPoint"}), Default("newton"))
          .key("maxIterations", Schema::integer("iterations per step").atLeast(1), Default(20))
          .key("tolerance", Schema::real("relative tolerance on accelerations", "-").greaterThan(0), Default(1e-10));
  return Schema::map("rigid multi-body frames: bodies on joints, restraints, gravity")
      .key("gravity", Schema::realVector(3, "gravitational acceleration", "m/s^2"), Default(std::array<double, 3>{0, 0, 0}))
      .key("newmark", newmark, Presence::Optional)
      .key("members", Schema::freeMap("bodies by name, parents listed first", body))
      .key("restraints", Schema::freeMap("restraints by name", restraint), Presence::Optional);
}

RigidSystemOptions readRigidOptions(const SceneConfig& c) {
  RigidSystemOptions o;
  o.gravity = vec3(c, "gravity");
  o.solver.gamma = c.get<double>("newmark.gamma");
  o.solver.beta = c.get<double>("newmark.beta");
  o.solver.accelerationRelaxation = c.get<double>("newmark.accelerationRelaxation");
  o.solver.accelerationDamping = c.get<double>("newmark.accelerationDamping");
  o.solver.iteration =
      c.get<std::string>("newmark.iteration") == "newton" ? RigidIteration::Newton : RigidIteration::FixedPoint;
  o.solver.maxIterations = c.get<int>("newmark.maxIterations");
  o.solver.tolerance = c.get<double>("newmark.tolerance");

  for (const auto& name : c.keys("members")) {
    const SceneConfig b = c.child("members." + name);
    RigidBodyOptions bo;
    bo.name = name;
    bo.parent = b.get<std::string>("parent");
    bo.mass = b.get<double>("mass");
    bo.centreOfMass = vec3(b, "centreOfMass");
    const auto I = b.get<std::array<double, 6>>("inertia");
    bo.inertia << I[0], I[3], I[4], I[3], I[1], I[5], I[4], I[5], I[2];
    const SceneConfig j = b.child("joint");
    try {
      bo.joint.type = parseRigidJointType(j.get<std::string>("type"));
    } catch (const InputError& e) {
      throw InputError(j.where("type"), e.what());
    }
    for (const auto& a : j.get<std::vector<std::string>>("axes")) bo.joint.axes.push_back(parseRigidAxis(a));
    for (std::size_t k = 0; k < j.size("motion"); ++k)
      bo.joint.motion.push_back(readTimeFunction(j.child("motion." + std::to_string(k))));
    bo.joint.origin = vec3(j, "origin");
    bo.joint.q0 = j.get<std::vector<double>>("q0");
    bo.joint.qdot0 = j.get<std::vector<double>>("qdot0");
    const bool multi = bo.joint.type == RigidJointType::Composite || bo.joint.type == RigidJointType::Prescribed;
    if (multi && bo.joint.axes.empty()) throw InputError(j.where("type"), "a composite or prescribed joint needs 'axes'");
    if (!multi && !bo.joint.axes.empty()) throw InputError(j.where("axes"), "'axes' only applies to composite/prescribed joints");
    if (bo.joint.type == RigidJointType::Prescribed && bo.joint.motion.size() != bo.joint.axes.size())
      throw InputError(j.where("motion"), "a prescribed joint needs one 'motion' function per axis");
    std::size_t nFree = 0;
    if (bo.joint.type == RigidJointType::Composite) nFree = bo.joint.axes.size();
    if (bo.joint.type != RigidJointType::Composite && bo.joint.type != RigidJointType::Prescribed &&
        bo.joint.type != RigidJointType::Fixed)
      nFree = 1;
    if (!bo.joint.q0.empty() && bo.joint.q0.size() != nFree)
      throw InputError(j.where("q0"), "expected " + std::to_string(nFree) + " value(s), one per free axis");
    if (!bo.joint.qdot0.empty() && bo.joint.qdot0.size() != nFree)
      throw InputError(j.where("qdot0"), "expected " + std::to_string(nFree) + " value(s), one per free axis");
    o.bodies.push_back(bo);
  }

  for (const auto& name : c.keys("restraints")) {
    const SceneConfig r = c.child("restraints." + name);
    const std::string type = r.get<std::string>("type");
    const std::string body = r.get<std::string>("body");
    bool known = false;
    for (const auto& b : o.bodies) known = known || b.name == body;
    if (!known) throw InputError(r.where("body"), "no body named '" + body + "'");
    if (type == "linearSpring") {
      RigidLinearSpringOptions s;
      s.name = name;
      s.body = body;
      s.anchor = vec3(r, "anchor");
      s.attachment = vec3(r, "attachment");
      s.stiffness = r.get<double>("stiffness");
      s.damping = r.get<double>("damping");
      s.restLength = r.get<double>("restLength");
      o.linearSprings.push_back(s);
    } else if (type == "linearDamper") {
      o.linearDampers.push_back({name, body, r.get<double>("coefficient")});
    } else if (type == "angularDamper") {
      o.angularDampers.push_back({name, body, r.get<double>("coefficient")});
    } else {
      if (!r.has("angle")) throw InputError(r.where("type"), "a prescribedRotation needs 'angle'");
      RigidPrescribedRotationOptions p;
      p.name = name;
      p.body = body;
      p.axis = r.get<int>("axis");
      p.angle = readTimeFunction(r.child("angle"));
      p.frequency = r.get<double>("frequency");
      p.dampingRatio = r.get<double>("dampingRatio");
      o.prescribedRotations.push_back(p);
    }
  }
  return o;
}

}  // namespace mfsi
