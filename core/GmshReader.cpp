#include "core/GmshReader.hpp"

#include "core/Error.hpp"
#include "core/GmshText.hpp"
#include "core/HexGeometry.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <sstream>
#include <vector>

namespace mfsi {

namespace {

using gmsh::Lexer;

struct RawHex {
  std::array<lid_t, 8> nodes;  // indices into the file's node list
  long long tag;
  int line;
};

struct RawQuad {
  std::array<lid_t, 4> nodes;
  int physical;
  long long tag;
  int line;
};

/// The hexahedra and the quadrangles of physical surfaces, before renumbering.
struct HexElements {
  std::vector<RawHex> hexes;
  std::vector<RawQuad> quads;
};

void readHexBlock(Lexer& lx, const gmsh::MshData& d, const gmsh::ElementBlock& block, HexElements& el) {
  const int dim = block.dim, type = block.type, n = block.size;
  if (type == 5 && dim != 3) lx.fail("hexahedra (type 5) in an element block of dimension " + std::to_string(dim));
  if (dim == 3 && type != 5) {
    if (n == 0) return;
    const long long tag = lx.integer("an element tag");
    lx.fail("non-hex cell: element " + std::to_string(tag) + " is a " + gmsh::elementTypeName(type) +
            " (Gmsh element type " + std::to_string(type) + "); only 8-node hexahedra (type 5) are supported");
  }
  if (dim == 3) {
    for (int i = 0; i < n; ++i) {
      RawHex h;
      h.tag = lx.integer("an element tag");
      h.line = lx.line();
      lx.setElement(h.tag);
      for (auto& v : h.nodes) v = gmsh::readElementNode(lx, d, h.tag, "a node tag");
      lx.expectLineEnd("the 8 node tags");
      lx.setElement(-1);
      el.hexes.push_back(h);
    }
    return;
  }
  const std::vector<int>* phys = dim == 2 ? d.physicalsOf(2, block.entity) : nullptr;
  if (!phys) {
    // Not a boundary patch: 0D/1D elements and surfaces outside any physical group.
    gmsh::skipElements(lx, n);
    return;
  }
  if (phys->size() > 1)
    lx.failAt(block.line, "surface entity " + std::to_string(block.entity) + " belongs to " +
                              std::to_string(phys->size()) +
                              " physical groups; a boundary face can only be in one patch");
  if (type != 3) {
    if (n == 0) return;
    const long long tag = lx.integer("an element tag");
    lx.fail("boundary element " + std::to_string(tag) + " on physical surface " + std::to_string((*phys)[0]) +
            " is a " + gmsh::elementTypeName(type) +
            "; the boundary of a hex mesh is made of 4-node quadrangles (type 3)");
  }
  for (int i = 0; i < n; ++i) {
    RawQuad q;
    q.tag = lx.integer("an element tag");
    q.line = lx.line();
    q.physical = (*phys)[0];
    lx.setElement(q.tag);
    for (auto& v : q.nodes) v = gmsh::readElementNode(lx, d, q.tag, "a node tag");
    lx.expectLineEnd("the 4 node tags");
    lx.setElement(-1);
    el.quads.push_back(q);
  }
}

}  // namespace

HexMeshInput readGmsh(const std::string& path) {
  ScopedRegion region("mfsi::core::io::readGmsh");
  Lexer lx = Lexer::fromFile(path);
  gmsh::MshData d;
  HexElements el;
  gmsh::readMsh41(lx, d, [&](const gmsh::ElementBlock& block) { readHexBlock(lx, d, block, el); });
  MFSI_CHECK(!el.hexes.empty(), path << ": no 8-node hexahedra (Gmsh element type 5) in the mesh");

  // Reject non-hex and inverted cells here, where the element tag and line are known.
  for (const auto& h : el.hexes) {
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < a; ++b)
        if (h.nodes[a] == h.nodes[b])
          lx.failAt(h.line, "non-hex cell: element " + std::to_string(h.tag) + " repeats node tag " +
                                std::to_string(d.nodeTag[h.nodes[a]]) + " (degenerate hexahedron)");
    double x[8][3];
    for (int a = 0; a < 8; ++a)
      for (int k = 0; k < 3; ++k) x[a][k] = d.coords[h.nodes[a]][k];
    const double jmin = geom::hexMinScaledJacobian(x);
    if (!(jmin > 0.0)) {
      std::ostringstream os;
      os << "element " << h.tag << " is an inverted or degenerate hexahedron (minimum scaled corner Jacobian " << jmin
         << " <= 0; check its node order)";
      lx.failAt(h.line, os.str());
    }
  }

  // Keep only the nodes of hexahedra, numbered in file order.
  std::vector<lid_t> newIndex(d.coords.size(), -1);
  for (const auto& h : el.hexes)
    for (const lid_t v : h.nodes) newIndex[v] = 0;
  HexMeshInput out;
  out.source = path;
  for (std::size_t v = 0; v < d.coords.size(); ++v)
    if (newIndex[v] == 0) {
      newIndex[v] = static_cast<lid_t>(out.points.size());
      out.points.push_back(d.coords[v]);
    }
  out.cells.reserve(el.hexes.size());
  for (const auto& h : el.hexes) {
    std::array<lid_t, 8> c;
    for (int a = 0; a < 8; ++a) c[a] = newIndex[h.nodes[a]];
    out.cells.push_back(c);
  }

  // One patch per physical name, in physical-tag order.
  std::map<int, std::size_t> patchOfPhysical;
  for (const auto& q : el.quads) patchOfPhysical.emplace(q.physical, 0);
  for (auto& [tag, index] : patchOfPhysical) {
    const auto named = d.physicalNames.find({2, tag});
    const std::string name = named != d.physicalNames.end() ? named->second : "patch" + std::to_string(tag);
    const auto same = std::find_if(out.patches.begin(), out.patches.end(),
                                   [&](const HexMeshInput::PatchSpec& p) { return p.name == name; });
    index = static_cast<std::size_t>(same - out.patches.begin());
    if (same == out.patches.end()) {
      HexMeshInput::PatchSpec p;
      p.name = name;
      out.patches.push_back(p);
    }
  }
  for (const auto& q : el.quads) {
    std::array<lid_t, 4> f;
    for (int a = 0; a < 4; ++a) {
      f[a] = newIndex[q.nodes[a]];
      if (f[a] < 0)
        lx.failAt(q.line, "boundary element " + std::to_string(q.tag) + " uses node tag " +
                              std::to_string(d.nodeTag[q.nodes[a]]) + ", which belongs to no hexahedron");
    }
    out.patches[patchOfPhysical[q.physical]].faces.push_back(f);
  }
  // Groups of internal faces are baffles.
  std::map<std::array<lid_t, 4>, int> faceUses;
  const int hexFace[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  auto key = [](std::array<lid_t, 4> q) {
    std::sort(q.begin(), q.end());
    return q;
  };
  for (const auto& c : out.cells)
    for (const auto& hf : hexFace) ++faceUses[key({c[hf[0]], c[hf[1]], c[hf[2]], c[hf[3]]})];
  std::vector<HexMeshInput::PatchSpec> patches;
  for (auto& p : out.patches) {
    std::size_t internal = 0;
    for (const auto& f : p.faces) {
      const auto it = faceUses.find(key(f));
      internal += it != faceUses.end() && it->second == 2 ? 1 : 0;
    }
    if (internal == 0) {
      patches.push_back(std::move(p));
    } else if (internal == p.faces.size()) {
      out.baffles.push_back({p.name, std::move(p.faces)});
    } else {
      throw InputError(path + ": physical surface '" + p.name + "' has " + std::to_string(internal) +
                       " internal faces and " + std::to_string(p.faces.size() - internal) +
                       " boundary faces: a group is a boundary patch or a baffle, not both");
    }
  }
  out.patches = std::move(patches);
  return out;
}

}  // namespace mfsi
