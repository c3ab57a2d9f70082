#pragma once
/// \file
/// \brief Config layer of the `membranes` section: its schema, and per panel the plain option
/// structs it describes (mesh generator, `MembraneOptions`, `MembraneLoads`, boundary by node-set
/// names). The membrane solver never sees the scene.
///
/// \code{.yaml}
/// membranes:
///   - name: sail                       # module "membrane.sail" (default: "membrane" or "membrane.<index>")
///     mesh: {disc: {radius: 1, core: 8, rings: 8}}   # exactly one of rectangle, disc, annulus, sphere
///     material: {E: 1e9, nu: 0.3, thickness: 1e-3, density: 1000, preStress: 0}
///     wrinkling: tensionField          # none | tensionField
///     analysis: static                 # static | dynamic
///     solver: {method: newton, tolerance: 1e-8}
///     loads: {pressure: 100, time: {shape: ramp, rampTime: 0.5}}
///     boundary: {clamp: [boundary]}
///     reference: hencky                # analytic comparison reported as metrics
/// \endcode
#include "core/HexMesh.hpp"
#include "core/SceneConfig.hpp"
#include "structure/membrane/MembraneMesh.hpp"
#include "structure/membrane/MembraneOptions.hpp"

#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

namespace mfsi {

/// Mesh generator of a panel.
enum class MembraneMeshKind { Rectangle, Disc, Annulus, Sphere, Gmsh, Baffle, Patch };

struct FluidSurfaceMembraneInput;  // structure/membrane/MembraneMeshImport

/// \brief Which generator builds a panel's mesh, with its parameters (only the chosen one is used).
struct MembraneMeshSpec {
  MembraneMeshKind kind = MembraneMeshKind::Rectangle;
  MembraneRectangleSpec rectangle;
  MembraneDiscSpec disc;
  MembraneAnnulusSpec annulus;
  MembraneSphereSpec sphere;
  std::string gmshFile;       ///< Gmsh: surface mesh file (absolute or relative to the working folder)
  std::string gmshGroup;      ///< Gmsh: physical surface group ("" = every surface element)
  std::string baffle;         ///< Baffle: baffle name in the fluid mesh (without _master/_slave)
  std::string patch;          ///< Patch: one-sided boundary patch of the fluid mesh
  const HexMesh* fluidMesh = nullptr;  ///< Baffle, Patch: the scene's fluid mesh (not owned)
  /// Baffle, Patch on a decomposed fluid mesh (fluidMesh: this rank's part): the surface, cut by
  /// the rank that holds it (structure/membrane/MembraneOnRanks).
  std::shared_ptr<const FluidSurfaceMembraneInput> surface;
};

/// \brief Host mesh description of a spec (node sets included; "boundary" and "centre" are added
/// by buildMembraneMesh when the generator does not give them).
MembraneMeshInput generateMembraneMesh(const MembraneMeshSpec& spec);

/// Shape of a load multiplier in time.
enum class MembraneTimeShape {
  Constant,  ///< 1
  Ramp,      ///< min(1, t / rampTime)
  Sine,      ///< offset + amplitude sin(omega t + phase)
  Pulse      ///< 1 for t < duration, then 0
};

/// \brief Dimensionless load multiplier f(t).
struct MembraneTimeFunction {
  MembraneTimeShape shape = MembraneTimeShape::Constant;
  real rampTime = 0;   ///< s
  real duration = 0;   ///< s
  real amplitude = 0;  ///< -
  real omega = 0;      ///< rad/s
  real phase = 0;      ///< rad
  real offset = 0;     ///< -
  real operator()(real t) const;
};

/// \brief Springs from every node of a node set to its reference position (or along the line to it).
struct MembraneSetSprings {
  std::string nodeSet;
  real stiffness = 0;    ///< N/m per node
  real restLength = -1;  ///< m; < 0: the reference distance (zero-length isotropic spring at the node)
};

/// \brief Axial bars along a node set: "boundary" follows each closed boundary loop, another set
/// is an open chain in its stored order.
struct MembraneSetBeams {
  std::string nodeSet;
  real axialStiffness = 0;  ///< EA (N)
  bool tensionOnly = false;
};

/// \brief A clamped node set that moves: each node to X + translation f(t).
struct MembraneClampMotion {
  std::string nodeSet;
  std::array<real, 3> translation{0, 0, 0};  ///< m, at f = 1
  MembraneTimeFunction time;                 ///< f(t) (constant 1 by default)
};

/// \brief Boundary conditions by node-set name (resolved against the mesh by resolveMembraneBoundary).
struct MembraneBoundarySpec {
  std::vector<std::string> clamp{"boundary"};
  std::vector<MembraneClampMotion> clampMotion;
  std::vector<std::string> constrainToNormal;
  std::vector<MembraneSetSprings> springs;
  std::vector<MembraneSetBeams> edgeBeams;
  std::array<real, 3> motionPlaneNormal{0, 0, 0};  ///< see MembraneBoundary
};

/// \brief Node ids of a boundary spec on a mesh. Throws InputError for unknown node sets.
MembraneBoundary resolveMembraneBoundary(const MembraneBoundarySpec& spec, const MembraneMesh& mesh);

/// Static equilibrium per step, or implicit dynamics.
enum class MembraneAnalysis { Static, Dynamic };

/// Initial displacement of a panel.
enum class MembraneInitialShape {
  Flat,     ///< u = 0
  SineMode  ///< rectangle: w = A sin(m pi x / lx) sin(n pi y / ly) along the normal
};

struct MembraneInitialSpec {
  MembraneInitialShape shape = MembraneInitialShape::Flat;
  std::array<int, 2> mode{1, 1};
  real amplitude = 0;  ///< m
};

/// Analytic solution a panel is compared with (reported as metrics).
enum class MembraneReference {
  None,
  Hencky,          ///< clamped disc under uniform pressure, no pre-stress: centre deflection
  SquareFrequency  ///< clamped pre-stressed square, free vibration: period of the initial sine mode
};

/// \brief Everything one panel of the `membranes` section describes.
struct MembranePanelOptions {
  std::string name;  ///< module name: "membrane", "membrane.<name>" or "membrane.<index>"
  MembraneMeshSpec mesh;
  MembraneOptions options;
  MembraneLoads loads;  ///< pressureTime is filled from `pressureTime`
  MembraneTimeFunction pressureTime;
  MembraneBoundarySpec boundary;
  MembraneAnalysis analysis = MembraneAnalysis::Static;
  MembraneInitialSpec initial;
  MembraneReference reference = MembraneReference::None;
};

/// Schema of the `membranes` section (a list of panels).
Schema membraneSchema();

/// Options of every panel of a view of the `membranes` section. Throws InputError naming the key
/// on semantic errors (no or two mesh generators, unknown node set, duplicate name, a reference
/// solution that does not match the panel).
/// `fluidMesh` is the scene's fluid mesh (null without a `mesh` section); panels taken from
/// baffles need it. On several ranks (`fluidComm`; collective) it is this rank's part, and each
/// panel cut from it is cut by the rank that holds its surface and sent to the others.
std::vector<MembranePanelOptions> readMembraneOptions(const SceneConfig& membranes, const HexMesh* fluidMesh = nullptr,
                                                      MPI_Comm fluidComm = MPI_COMM_NULL);

/// \brief Hencky's coefficient C_w(nu) of w0 = C_w a (p a / (E h))^(1/3), exact for any nu in
/// (-1, 0.5] (structure/membrane/HenckySolution.hpp). Throws InputError outside.
double henckyCoefficient(double nu);

/// \brief Exact f_mn (Hz) of a clamped rectangle lx x ly under isotropic tension T0 (N/m) with areal
/// density rho h: (1/2) sqrt(T0 / (rho h)) sqrt((m/lx)^2 + (n/ly)^2).
double rectangleMembraneFrequency(double T0, double rhoH, double lx, double ly, int m, int n);

}  // namespace mfsi
