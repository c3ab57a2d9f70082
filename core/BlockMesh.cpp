#include "core/BlockMesh.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <tuple>

namespace mfsi {

namespace {

std::vector<real> gradedCoordinates(real a, real b, int n, real ratio) {
  std::vector<real> x(n + 1);
  if (n == 1 || std::abs(ratio - 1.0) < 1e-14) {
    for (int i = 0; i <= n; ++i) x[i] = a + (b - a) * i / n;
  } else {
    const real q = std::pow(ratio, 1.0 / (n - 1));
    real sum = 0, s = 1;
    for (int i = 0; i < n; ++i, s *= q) sum += s;
    real pos = a, h = (b - a) / sum;
    x[0] = a;
    for (int i = 1; i <= n; ++i, h *= q) x[i] = (pos += h);
    x[n] = b;
  }
  return x;
}

/// Nodes closer than this (per coordinate) are merged: `mergeTolerance` times the diagonal of the
/// bounding box of all blocks.
real mergeDistance(const BlockMeshSpec& spec) {
  std::array<real, 3> lo = spec.blocks[0].min, hi = spec.blocks[0].max;
  for (const auto& bl : spec.blocks)
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], bl.min[d]);
      hi[d] = std::max(hi[d], bl.max[d]);
    }
  const real diag = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                              (hi[2] - lo[2]) * (hi[2] - lo[2]));
  return spec.mergeTolerance * diag;
}

bool validBlock(const BlockSpec& bl) {
  for (int d = 0; d < 3; ++d)
    if (bl.cells[d] < 1 || !(bl.max[d] > bl.min[d]) || !(bl.grading[d] > 0)) return false;
  return true;
}

/// The node coordinates of a block along `dir`.
std::vector<real> gridLine(const BlockSpec& bl, int dir) {
  return gradedCoordinates(bl.min[dir], bl.max[dir], bl.cells[dir], bl.grading[dir]);
}

/// How the upper (`upperOfA`) or lower side of block a along `dir` meets the opposite side of block
/// b, which lies on the same plane: nothing when they share no area or their grids match there.
std::optional<BlockMismatch> compareContact(const BlockMeshSpec& spec, std::size_t a, std::size_t b, int dir,
                                            bool upperOfA, real tol) {
  const BlockSpec& A = spec.blocks[a];
  const BlockSpec& B = spec.blocks[b];
  const int along[2] = {dir == 0 ? 1 : 0, dir == 2 ? 1 : 2};
  real lo[2], hi[2];
  for (int t = 0; t < 2; ++t) {
    const int e = along[t];
    lo[t] = std::max(A.min[e], B.min[e]);
    hi[t] = std::min(A.max[e], B.max[e]);
    if (hi[t] - lo[t] <= tol) return std::nullopt;  // an edge or a corner, or apart: nothing to glue
  }
  BlockMismatch m;
  m.block = {a, b};
  m.side = {static_cast<BoxSide>(2 * dir + (upperOfA ? 1 : 0)), static_cast<BoxSide>(2 * dir + (upperOfA ? 0 : 1))};
  m.along = {along[0], along[1]};
  bool conforming = true, sameCells = true, wholeFaces = true;
  for (int t = 0; t < 2; ++t) {
    const int e = along[t];
    // Grid lines of each block on the shared part [lo, hi], and the cells that touch it.
    std::array<std::vector<real>, 2> lines;
    for (int k = 0; k < 2; ++k) {
      const auto x = gridLine(spec.blocks[m.block[k]], e);
      long long touching = 0;
      for (std::size_t i = 0; i < x.size(); ++i) {
        if (x[i] >= lo[t] - tol && x[i] <= hi[t] + tol) lines[k].push_back(x[i]);
        if (i + 1 < x.size() && x[i + 1] > lo[t] + tol && x[i] < hi[t] - tol) ++touching;
      }
      m.cells[k][t] = touching;
    }
    sameCells = sameCells && m.cells[0][t] == m.cells[1][t];
    wholeFaces = wholeFaces && std::abs(A.min[e] - B.min[e]) <= tol && std::abs(A.max[e] - B.max[e]) <= tol;
    bool match = lines[0].size() == lines[1].size() && !lines[0].empty() && std::abs(lines[0].front() - lo[t]) <= tol &&
                 std::abs(lines[0].back() - hi[t]) <= tol;
    for (std::size_t i = 0; match && i < lines[0].size(); ++i) match = std::abs(lines[0][i] - lines[1][i]) <= tol;
    conforming = conforming && match;
  }
  if (conforming) return std::nullopt;
  m.cause = !sameCells ? BlockMismatch::Cause::Cells
                       : (wholeFaces ? BlockMismatch::Cause::Grading : BlockMismatch::Cause::Extent);
  return m;
}

}  // namespace

double BlockMeshCounts::largest() const { return std::max({cells, nodes, faces}); }

BlockMeshCounts countBlock(const BlockSpec& block) {
  const double nx = block.cells[0], ny = block.cells[1], nz = block.cells[2];
  BlockMeshCounts c;
  c.cells = nx * ny * nz;
  c.nodes = (nx + 1) * (ny + 1) * (nz + 1);
  c.faces = (nx + 1) * ny * nz + nx * (ny + 1) * nz + nx * ny * (nz + 1);
  return c;
}

BlockMeshCounts countBlockMesh(const BlockMeshSpec& spec) {
  BlockMeshCounts total;
  for (const auto& bl : spec.blocks) {
    const BlockMeshCounts c = countBlock(bl);
    total.cells += c.cells;
    total.nodes += c.nodes;
    total.faces += c.faces;
  }
  return total;
}

const char* sideName(BoxSide side) {
  static const char* const names[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};
  return names[static_cast<int>(side)];
}

std::string BlockMismatch::describe(const std::string& name0, const std::string& name1) const {
  std::ostringstream os;
  const char* xyz = "xyz";
  auto grid = [&](int k) { return std::to_string(cells[k][0]) + "x" + std::to_string(cells[k][1]); };
  const std::string dirs = std::string("(") + xyz[along[0]] + " x " + xyz[along[1]] + ")";
  os << name0 << " face " << sideName(side[0]) << " and " << name1 << " face " << sideName(side[1]);
  switch (cause) {
    case Cause::Cells:
      os << " touch but their grids differ: " << grid(0) << " cells against " << grid(1) << " cells " << dirs
         << "; give both the same cells on the shared face";
      break;
    case Cause::Grading:
      os << " touch with the same " << grid(0) << " cells " << dirs
         << " but their grids differ (different grading), so their nodes do not meet; give both the same grading "
            "along the shared face";
      break;
    case Cause::Extent:
      os << " touch on part of their faces but their grids differ there (" << grid(0) << " cells against " << grid(1)
         << " cells " << dirs
         << " meet the shared part); make the shared part end on grid lines of both, with the same cells across it";
      break;
  }
  return os.str();
}

std::optional<BlockMismatch> findMismatchedContact(const BlockMeshSpec& spec) {
  if (spec.blocks.empty()) return std::nullopt;
  const real tol = mergeDistance(spec);
  for (std::size_t a = 0; a < spec.blocks.size(); ++a) {
    if (!validBlock(spec.blocks[a])) continue;
    for (std::size_t b = a + 1; b < spec.blocks.size(); ++b) {
      if (!validBlock(spec.blocks[b])) continue;
      const BlockSpec& A = spec.blocks[a];
      const BlockSpec& B = spec.blocks[b];
      for (int d = 0; d < 3; ++d) {
        std::optional<BlockMismatch> m;
        if (std::abs(A.max[d] - B.min[d]) <= tol) m = compareContact(spec, a, b, d, true, tol);
        if (!m && std::abs(A.min[d] - B.max[d]) <= tol) m = compareContact(spec, a, b, d, false, tol);
        if (m) return m;
      }
    }
  }
  return std::nullopt;
}

void refineBlocks(BlockMeshSpec& spec, real factor) {
  if (!(factor > 0) || !std::isfinite(factor))
    throw InputError("the refinement factor must be a positive number, not " + std::to_string(factor));
  std::array<bool, 3> flat{true, true, true};  // one cell in every block: a 2D scene's thickness
  for (const auto& b : spec.blocks)
    for (int d = 0; d < 3; ++d) flat[d] = flat[d] && b.cells[d] == 1;
  for (std::size_t i = 0; i < spec.blocks.size(); ++i) {
    auto& cells = spec.blocks[i].cells;
    for (int d = 0; d < 3; ++d) {
      if (flat[d]) continue;
      const double n = std::round(cells[d] * factor);
      if (n > std::numeric_limits<int>::max()) {
        std::ostringstream os;
        os << "refining block " << i << " by " << factor << " gives " << n << " cells in one direction, more than "
           << std::numeric_limits<int>::max();
        throw InputError(os.str());
      }
      cells[d] = std::max(1, static_cast<int>(n));
    }
  }
}

BlockMeshSpec boxSpec(std::array<real, 3> min, std::array<real, 3> max, std::array<int, 3> cells) {
  BlockMeshSpec s;
  BlockSpec b;
  b.min = min;
  b.max = max;
  b.cells = cells;
  s.blocks.push_back(b);
  return s;
}

HexMeshInput generateBlockMesh(const BlockMeshSpec& spec) {
  MFSI_CHECK(!spec.blocks.empty(), "blockMesh: no blocks");
  HexMeshInput out;
  out.source = "blockMesh";
  out.defaultPatch = spec.defaultPatch;

  for (std::size_t b = 0; b < spec.blocks.size(); ++b) {
    const auto& bl = spec.blocks[b];
    for (int d = 0; d < 3; ++d) {
      MFSI_CHECK(bl.cells[d] >= 1, "blockMesh: block " << b << " needs at least one cell in direction " << d);
      MFSI_CHECK(bl.max[d] > bl.min[d], "blockMesh: block " << b << " has max <= min in direction " << d);
      MFSI_CHECK(bl.grading[d] > 0, "blockMesh: block " << b << " has non-positive grading in direction " << d);
    }
  }
  // Before allocating anything: every count must fit the index type.
  const BlockMeshCounts counts = countBlockMesh(spec);
  MFSI_CHECK(counts.largest() <= static_cast<double>(std::numeric_limits<lid_t>::max()),
             "blockMesh: the blocks make " << counts.cells << " cells, " << counts.nodes << " nodes and "
                                           << counts.faces << " faces, more than the "
                                           << std::numeric_limits<lid_t>::max() << " one rank can index (lid_t)");
  if (const auto m = findMismatchedContact(spec))
    throw InputError("blockMesh: " +
                     m->describe("block " + std::to_string(m->block[0]), "block " + std::to_string(m->block[1])));
  const real tol = mergeDistance(spec);

  // Merge coincident nodes through a quantised-coordinate map.
  std::map<std::tuple<long long, long long, long long>, lid_t> nodeOf;
  auto addPoint = [&](real x, real y, real z) -> lid_t {
    auto qz = [&](real v) { return static_cast<long long>(std::llround(v / (tol > 0 ? tol : 1e-300) / 4.0)); };
    // Look in the neighbouring quantisation cells too, so points straddling a cell edge merge.
    const auto base = std::make_tuple(qz(x), qz(y), qz(z));
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = nodeOf.find({std::get<0>(base) + dx, std::get<1>(base) + dy, std::get<2>(base) + dz});
          if (it == nodeOf.end()) continue;
          const auto& p = out.points[it->second];
          if (std::abs(p[0] - x) <= tol && std::abs(p[1] - y) <= tol && std::abs(p[2] - z) <= tol) return it->second;
        }
    const lid_t id = static_cast<lid_t>(out.points.size());
    out.points.push_back({x, y, z});
    nodeOf.emplace(base, id);
    return id;
  };

  std::map<std::string, std::size_t> patchOf;
  for (std::size_t b = 0; b < spec.blocks.size(); ++b) {
    const auto& bl = spec.blocks[b];
    const int nx = bl.cells[0], ny = bl.cells[1], nz = bl.cells[2];
    const auto xs = gradedCoordinates(bl.min[0], bl.max[0], nx, bl.grading[0]);
    const auto ys = gradedCoordinates(bl.min[1], bl.max[1], ny, bl.grading[1]);
    const auto zs = gradedCoordinates(bl.min[2], bl.max[2], nz, bl.grading[2]);
    std::vector<lid_t> nid(static_cast<std::size_t>(nx + 1) * (ny + 1) * (nz + 1));
    auto at = [&](int i, int j, int k) -> lid_t& { return nid[(static_cast<std::size_t>(k) * (ny + 1) + j) * (nx + 1) + i]; };
    for (int k = 0; k <= nz; ++k)
      for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) at(i, j, k) = addPoint(xs[i], ys[j], zs[k]);

    const lid_t cell0 = static_cast<lid_t>(out.cells.size());
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i)
          out.cells.push_back({at(i, j, k), at(i + 1, j, k), at(i + 1, j + 1, k), at(i, j + 1, k), at(i, j, k + 1),
                               at(i + 1, j, k + 1), at(i + 1, j + 1, k + 1), at(i, j + 1, k + 1)});
    auto cellAt = [&](int i, int j, int k) { return cell0 + (k * ny + j) * nx + i; };

    // Side faces (local hex face ids: z- 0, z+ 1, y- 2, y+ 3, x- 4, x+ 5).
    const int sideLocal[6] = {4, 5, 2, 3, 0, 1};
    for (int side = 0; side < 6; ++side) {
      const std::string& name = bl.patches[side];
      if (name.empty()) continue;
      auto it = patchOf.find(name);
      if (it == patchOf.end()) {
        HexMeshInput::PatchSpec ps;
        ps.name = name;
        auto kit = spec.patchKinds.find(name);
        if (kit != spec.patchKinds.end()) ps.kind = kit->second;
        it = patchOf.emplace(name, out.patches.size()).first;
        out.patches.push_back(ps);
      }
      auto& faces = out.patches[it->second].faces;
      const int dir = side / 2;
      const bool upper = side % 2 == 1;
      for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
          for (int i = 0; i < nx; ++i) {
            const int idx[3] = {i, j, k};
            const int n[3] = {nx, ny, nz};
            if (idx[dir] != (upper ? n[dir] - 1 : 0)) continue;
            const auto& cn = out.cells[cellAt(i, j, k)];
            std::array<lid_t, 4> q;
            for (int a = 0; a < 4; ++a) q[a] = cn[kHexFaces[sideLocal[side]][a]];
            faces.push_back(q);
          }
    }
  }

  // Drop patch faces that gluing made internal.
  {
    // Sorted keys of every cell face: a key seen twice is an internal face.
    std::vector<std::array<lid_t, 4>> keys;
    keys.reserve(out.cells.size() * 6);
    for (const auto& c : out.cells)
      for (const auto& lf : kHexFaces) {
        std::array<lid_t, 4> q = {c[lf[0]], c[lf[1]], c[lf[2]], c[lf[3]]};
        std::sort(q.begin(), q.end());
        keys.push_back(q);
      }
    std::sort(keys.begin(), keys.end());
    auto count = [&keys](const std::array<lid_t, 4>& k) {
      const auto r = std::equal_range(keys.begin(), keys.end(), k);
      return static_cast<int>(r.second - r.first);
    };
    for (auto& p : out.patches) {
      std::vector<std::array<lid_t, 4>> keep;
      for (const auto& q : p.faces) {
        auto k = q;
        std::sort(k.begin(), k.end());
        if (count(k) == 1) keep.push_back(q);
      }
      p.faces.swap(keep);
    }
    std::vector<HexMeshInput::PatchSpec> nonEmpty;
    for (auto& p : out.patches)
      if (!p.faces.empty()) nonEmpty.push_back(std::move(p));
    out.patches.swap(nonEmpty);

    // Baffles: cell faces looking along +axis that lie on the plane inside the rectangle.
    const int plusFace[3] = {5, 3, 1};
    for (const auto& br : spec.baffles) {
      MFSI_CHECK(br.axis >= 0 && br.axis <= 2, "blockMesh: baffle '" << br.name << "' axis must be 0, 1 or 2");
      HexMeshInput::BaffleSpec bs;
      bs.name = br.name;
      for (const auto& c : out.cells) {
        std::array<lid_t, 4> q;
        real ctr[3] = {0, 0, 0};
        bool onPlane = true;
        for (int a = 0; a < 4; ++a) {
          q[a] = c[kHexFaces[plusFace[br.axis]][a]];
          const auto& p = out.points[q[a]];
          onPlane = onPlane && std::abs(p[br.axis] - br.position) <= std::max(tol, 1e-12);
          for (int d = 0; d < 3; ++d) ctr[d] += 0.25 * p[d];
        }
        if (!onPlane) continue;
        bool inside = true;
        for (int d = 0; d < 3; ++d)
          if (d != br.axis) inside = inside && ctr[d] >= br.min[d] - tol && ctr[d] <= br.max[d] + tol;
        if (!inside) continue;
        auto k = q;
        std::sort(k.begin(), k.end());
        if (count(k) == 2) bs.faces.push_back(q);
      }
      MFSI_CHECK(!bs.faces.empty(), "blockMesh: baffle '" << br.name << "' selects no internal face (plane "
                                                          << "xyz"[br.axis] << " = " << br.position << ")");
      out.baffles.push_back(std::move(bs));
    }
  }
  return out;
}

}  // namespace mfsi
