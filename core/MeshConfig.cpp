#include "core/MeshConfig.hpp"

#include "core/BlockMesh.hpp"
#include "core/GmshReader.hpp"
#include "core/PolyMeshReader.hpp"

#include <filesystem>

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

PatchKind patchKindOf(const std::string& s) {
  if (s == "wall") return PatchKind::Wall;
  if (s == "symmetry") return PatchKind::Symmetry;
  if (s == "empty") return PatchKind::Empty;
  return PatchKind::Patch;
}

}  // namespace

Schema meshSchema() {
  return Schema::map("the fluid mesh: generated blocks, or a file")
      .key("blocks", Schema::list("boxes glued where they touch", blockSchema(), 1), Presence::OptionalSection)
      .key("baffles", Schema::list("baffles declared on grid planes (blocks only)", baffleSchema()),
           Presence::Optional)
      .key("file", Schema::string("Gmsh .msh 4.1 file or OpenFOAM polyMesh folder, relative to the scene"),
           Presence::OptionalSection)
      .key("format", Schema::choice("mesh file format", {"auto", "gmsh", "polyMesh"}), Default("auto"))
      .key("patchTypes", Schema::freeMap("kind per patch name", Schema::choice("patch kind", {"patch", "wall", "symmetry", "empty"})),
           Presence::Optional)
      .key("defaultPatch", Schema::string("patch collecting boundary faces no other patch claims"),
           Default("defaultFaces"));
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
      in = generateBlockMesh(spec);
    } catch (const InputError& e) {
      throw InputError(mesh.where("blocks"), e.what());
    }
  } else {
    if (mesh.size("baffles") > 0)
      throw InputError(mesh.where("baffles"), "baffles on grid planes need generated 'blocks'");
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
