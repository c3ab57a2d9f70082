#include "core/MeshConfig.hpp"

#include "core/BlockMesh.hpp"
#include "core/GmshReader.hpp"
#include "core/PolyMeshReader.hpp"

#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>

#include <unistd.h>

namespace mfsi {

namespace {

const char* kSides[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};

Schema blockSchema() {
  Schema patches = Schema::map("patch name of each side; an unnamed side joins the default patch");
  for (const char* s : kSides) patches.key(s, Schema::string(std::string("patch name of the ") + s + " side"), Default(""));
  return Schema::map("a box of hex cells")
      .key("min", Schema::realVector(3, "lower corner", "m"))
      .key("max", Schema::realVector(3, "upper corner", "m"))
      .key("cells", Schema::intVector(3, "cells per direction").atLeast(1))
      .key("grading", Schema::realVector(3, "last/first cell size ratio per direction", "-").greaterThan(0),
           Default(std::array<double, 3>{1, 1, 1}))
      .key("patches", patches, Presence::Optional);
}

Schema baffleSchema() {
  return Schema::map("internal faces on a grid plane turned into a baffle (<name>_master/<name>_slave)")
      .key("name", Schema::string("baffle name"))
      .key("axis", Schema::choice("normal direction of the plane (the baffle normal is +axis)", {"x", "y", "z"}))
      .key("position", Schema::real("plane coordinate along axis", "m"))
      .key("min", Schema::realVector(3, "rectangle lower corner (axis component ignored)", "m"))
      .key("max", Schema::realVector(3, "rectangle upper corner (axis component ignored)", "m"));
}

/// Rough peak memory of a run per mesh entity, for refusing meshes this machine cannot hold before
/// allocating them: per node and per face the generator's and the mesh's arrays and geometry, per cell
/// the solver's fields, matrices and multigrid levels. For a large box (a node and three faces per
/// cell) that is 4.9 kB per cell; peaks measured with `mfsi run` (max RSS): membrane-channel at
/// 96x32x32 and 144x48x48 cells 5.2 kB per cell, cavity at 256x256x1 3.7 kB per cell.
constexpr double kBytesPerNode = 100;
constexpr double kBytesPerFace = 100;
constexpr double kBytesPerCell = 4500;

/// Physical memory of this machine in bytes; 0 when unknown.
double physicalMemory() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long pageSize = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && pageSize > 0 ? static_cast<double>(pages) * static_cast<double>(pageSize) : 0.0;
}

std::string bytesText(double bytes) {
  const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  int u = 0;
  for (; u < 6 && bytes >= 1000; ++u) bytes /= 1000;
  std::ostringstream os;
  os << std::setprecision(3) << bytes << " " << units[u];
  return os.str();
}

std::string countText(double n) {
  std::ostringstream os;
  if (n < 1e12)
    os << std::fixed << std::setprecision(0) << n;
  else
    os << std::setprecision(3) << n;
  return os.str();
}

/// Refuse block meshes whose counts overflow lid_t or whose estimated memory exceeds the machine's,
/// before anything is allocated. Names the cells of the largest block.
void checkBlockMeshSize(const SceneConfig& mesh, const BlockMeshSpec& spec) {
  std::size_t largest = 0;
  for (std::size_t i = 1; i < spec.blocks.size(); ++i)
    if (countBlock(spec.blocks[i]).cells > countBlock(spec.blocks[largest]).cells) largest = i;
  const BlockMeshCounts total = countBlockMesh(spec);
  const auto& c = spec.blocks[largest].cells;
  std::ostringstream what;
  what << "cells [" << c[0] << ", " << c[1] << ", " << c[2] << "]";
  if (spec.blocks.size() > 1) what << " (the largest of " << spec.blocks.size() << " blocks)";
  if (const double refine = mesh.get<double>("refine"); refine != 1) what << " (after mesh.refine = " << refine << ")";
  what << " make a mesh of " << countText(total.cells) << " cells, " << countText(total.nodes) << " nodes and "
       << countText(total.faces) << " faces";
  const SourceLocation where = mesh.where("blocks." + std::to_string(largest) + ".cells");
  const double maxIndex = std::numeric_limits<lid_t>::max();
  if (total.largest() > maxIndex)
    throw InputError(where, what.str() + ", more than the " + countText(maxIndex) +
                                " entities one rank can index (lid_t is 32-bit); use fewer cells");
  const double bytes = kBytesPerNode * total.nodes + kBytesPerFace * total.faces + kBytesPerCell * total.cells;
  const double memory = physicalMemory();
  if (memory > 0 && bytes > memory)
    throw InputError(where, what.str() + ", which needs about " + bytesText(bytes) +
                                " (mesh and solver fields, ~5 kB per cell), more than the " + bytesText(memory) +
                                " of memory of this machine; use fewer cells");
}

/// The scene key to fix for a mismatch, relative to the block.
const char* mismatchKey(BlockMismatch::Cause cause) {
  switch (cause) {
    case BlockMismatch::Cause::Cells:
      return "cells";
    case BlockMismatch::Cause::Grading:
      return "grading";
    case BlockMismatch::Cause::Extent:
      return "";
  }
  return "";
}

PatchKind patchKindOf(const std::string& s) {
  if (s == "wall") return PatchKind::Wall;
  if (s == "symmetry") return PatchKind::Symmetry;
  if (s == "empty") return PatchKind::Empty;
  return PatchKind::Patch;
}

}  // namespace

Schema meshSchema() {
  return Schema::map("the fluid mesh: generated blocks, or a file")
      .key("blocks", Schema::list("boxes glued where they touch (touching sides need the same grid)", blockSchema(), 1),
           Presence::OptionalSection)
      .key("baffles", Schema::list("baffles declared on grid planes (blocks only)", baffleSchema()),
           Presence::Optional)
      .key("file", Schema::path("Gmsh .msh 4.1 file or OpenFOAM polyMesh folder, relative to the scene"),
           Presence::OptionalSection)
      .key("format", Schema::choice("mesh file format", {"auto", "gmsh", "polyMesh"}), Default("auto"))
      .key("patchTypes", Schema::freeMap("kind per patch name", Schema::choice("patch kind", {"patch", "wall", "symmetry", "empty"})),
           Presence::Optional)
      .key("defaultPatch", Schema::string("patch collecting boundary faces no other patch claims"),
           Default("defaultFaces"))
      .key("refine",
           Schema::real("factor multiplying every block's cells (rounded, at least 1; a direction with one cell "
                        "in every block, a 2D scene's thickness, stays one cell; blocks only)",
                        "-")
               .greaterThan(0),
           Default(1.0));
}

HexMesh buildMesh(const SceneConfig& mesh) {
  const bool hasBlocks = mesh.has("blocks");
  const bool hasFile = mesh.has("file");
  if (hasBlocks == hasFile)
    throw InputError(mesh.where(), hasBlocks ? "give either 'blocks' or 'file', not both"
                                             : "give the mesh as 'blocks' (generated) or 'file' (Gmsh / polyMesh)");
  HexMeshInput in;
  if (hasBlocks) {
    BlockMeshSpec spec;
    spec.defaultPatch = mesh.get<std::string>("defaultPatch");
    for (std::size_t i = 0; i < mesh.size("blocks"); ++i) {
      const SceneConfig b = mesh.child("blocks." + std::to_string(i));
      BlockSpec bs;
      bs.min = b.get<std::array<double, 3>>("min");
      bs.max = b.get<std::array<double, 3>>("max");
      bs.cells = b.get<std::array<int, 3>>("cells");
      bs.grading = b.get<std::array<double, 3>>("grading");
      for (int s = 0; s < 6; ++s) bs.patches[s] = b.get<std::string>(std::string("patches.") + kSides[s]);
      for (int d = 0; d < 3; ++d)
        if (!(bs.max[d] > bs.min[d])) throw InputError(b.where("max"), "max must exceed min in every direction");
      spec.blocks.push_back(bs);
    }
    for (std::size_t i = 0; i < mesh.size("baffles"); ++i) {
      const SceneConfig b = mesh.child("baffles." + std::to_string(i));
      BaffleRect br;
      br.name = b.get<std::string>("name");
      br.axis = b.get<std::string>("axis")[0] - 'x';
      br.position = b.get<double>("position");
      br.min = b.get<std::array<double, 3>>("min");
      br.max = b.get<std::array<double, 3>>("max");
      spec.baffles.push_back(br);
    }
    for (const auto& name : mesh.keys("patchTypes"))
      spec.patchKinds[name] = patchKindOf(mesh.get<std::string>("patchTypes." + name));
    try {
      refineBlocks(spec, mesh.get<double>("refine"));
    } catch (const InputError& e) {
      throw InputError(mesh.where("refine"), e.what());
    }
    checkBlockMeshSize(mesh, spec);
    if (const auto m = findMismatchedContact(spec)) {
      // Point at the first block's key to fix, and say where the second one's is.
      const std::string key = mismatchKey(m->cause);
      std::array<std::string, 2> name;
      std::array<SourceLocation, 2> at;
      for (int k = 0; k < 2; ++k) {
        const std::string block = "blocks." + std::to_string(m->block[k]);
        name[k] = mesh.where(block).key;
        at[k] = mesh.where(key.empty() ? block : block + "." + key);
      }
      SourceLocation other = at[1];
      other.key.clear();
      throw InputError(at[0], m->describe(name[0], name[1]) + "; " + at[1].key + " is at " + other.str());
    }
    try {
      in = generateBlockMesh(spec);
    } catch (const InputError& e) {
      throw InputError(mesh.where("blocks"), e.what());
    }
  } else {
    if (mesh.size("baffles") > 0)
      throw InputError(mesh.where("baffles"), "baffles on grid planes need generated 'blocks'");
    if (mesh.get<double>("refine") != 1)
      throw InputError(mesh.where("refine"),
                       "refine multiplies the cells of generated 'blocks'; a mesh file is "
                       "refined by making a finer file");
    std::filesystem::path p = mesh.get<std::string>("file");
    if (p.is_relative()) p = std::filesystem::path(mesh.file()).parent_path() / p;
    if (!std::filesystem::exists(p)) throw InputError(mesh.where("file"), "mesh file not found: " + p.string());
    std::string fmt = mesh.get<std::string>("format");
    if (fmt == "auto") fmt = std::filesystem::is_directory(p) ? "polyMesh" : "gmsh";
    in = fmt == "gmsh" ? readGmsh(p.string()) : readPolyMesh(p.string());
    in.defaultPatch = mesh.get<std::string>("defaultPatch");
    for (auto& ps : in.patches)
      if (mesh.has("patchTypes." + ps.name)) ps.kind = patchKindOf(mesh.get<std::string>("patchTypes." + ps.name));
  }
  return buildHexMesh(in);
}

}  // namespace mfsi
