#pragma once
/// \file
/// \brief Structured block generator: boxes with per-direction cell counts and grading, glued
/// where they touch (touching sides must have the same grid there), named patches per side, and
/// baffles declared as rectangles on grid planes. Produces the same unstructured `HexMeshInput` as
/// the file readers.
#include "core/HexMesh.hpp"

#include <map>
#include <optional>
#include <string>

namespace mfsi {

/// Sides of a block, in the order of `BlockSpec::patches`.
enum class BoxSide { XMin = 0, XMax = 1, YMin = 2, YMax = 3, ZMin = 4, ZMax = 5 };

struct BlockSpec {
  std::array<real, 3> min{0, 0, 0};
  std::array<real, 3> max{1, 1, 1};
  std::array<int, 3> cells{1, 1, 1};
  /// Ratio of the last to the first cell size in each direction (1 = uniform).
  std::array<real, 3> grading{1, 1, 1};
  /// Patch name of each side (xmin, xmax, ymin, ymax, zmin, zmax); "" = the default patch.
  /// A named side that ends up glued to another block is internal and ignored.
  std::array<std::string, 6> patches;
};

/// A baffle: the internal faces on the plane x[axis] = position whose centroids lie in the
/// rectangle [min, max] (the axis component of min/max is ignored). Its normal is +axis.
struct BaffleRect {
  std::string name;
  int axis = 2;
  real position = 0;
  std::array<real, 3> min{0, 0, 0};
  std::array<real, 3> max{0, 0, 0};
};

struct BlockMeshSpec {
  std::vector<BlockSpec> blocks;
  std::vector<BaffleRect> baffles;
  std::map<std::string, PatchKind> patchKinds;  ///< optional kind per patch name
  std::string defaultPatch = "defaultFaces";
  /// Nodes closer than this times the bounding-box diagonal are merged (gluing).
  real mergeTolerance = 1e-9;
};

/// \brief Entity counts of a block, or of a whole spec before gluing (an upper bound of the glued
/// mesh). Doubles, so that absurd cell counts are counted exactly enough to be refused instead of
/// overflowing.
struct BlockMeshCounts {
  double cells = 0;
  double nodes = 0;
  double faces = 0;
  /// The largest of the three counts: what must fit the local index type lid_t.
  double largest() const;
};

/// Counts of one block.
BlockMeshCounts countBlock(const BlockSpec& block);
/// Counts of all blocks together, shared interfaces counted twice.
BlockMeshCounts countBlockMesh(const BlockMeshSpec& spec);

/// \brief Two block sides that touch (coplanar, opposite outward normals, overlapping in area) but
/// whose grids differ on the shared part, so their nodes cannot be merged and the blocks would stay
/// unglued (an internal boundary). `block[0] < block[1]`.
struct BlockMismatch {
  /// What differs; the config layer names the scene key to fix from it.
  enum class Cause {
    Cells,    ///< the cell counts across the shared part differ
    Grading,  ///< same faces and cell counts, but the node positions (grading) differ
    Extent    ///< the shared part is not bounded by grid lines of both blocks (partial overlap)
  };
  std::array<std::size_t, 2> block{0, 0};
  std::array<BoxSide, 2> side{BoxSide::XMin, BoxSide::XMin};
  /// The two in-plane directions (0 = x, 1 = y, 2 = z), in increasing order.
  std::array<int, 2> along{0, 0};
  /// Cells of each block that touch the shared part, along `along[0]` and `along[1]`.
  std::array<std::array<long long, 2>, 2> cells{};
  Cause cause = Cause::Cells;

  /// A readable account naming the blocks `name0` and `name1`, e.g. "mesh.blocks.0 face +x and
  /// mesh.blocks.1 face -x touch but their grids differ: 32x8 cells against 10x10 cells (y x z);
  /// give both the same cells on the shared face".
  std::string describe(const std::string& name0, const std::string& name1) const;
};

/// Short name of a side: "-x", "+x", ..., "+z".
const char* sideName(BoxSide side);

/// \brief The first pair of touching block sides whose grids differ, if any (O(blocks^2) box tests,
/// plus the grid coordinates of the touching sides).
std::optional<BlockMismatch> findMismatchedContact(const BlockMeshSpec& spec);

/// Generate the mesh description. Throws InputError for invalid specs (non-positive counts or sizes,
/// more cells, nodes or faces than lid_t indexes, touching blocks whose grids differ, baffles that
/// select no face).
HexMeshInput generateBlockMesh(const BlockMeshSpec& spec);

/// \brief Multiply every block's cell counts by `factor` (rounded to the nearest integer, at least
/// 1), for studies of mesh convergence that need not know each block's cells. A direction in which
/// every block has one cell (the thickness of a 2D scene) stays at one cell. Gradings are kept (the
/// last/first size ratio of each block), so the refined grid resolves the same geometry; touching
/// blocks that shared a grid still do. Throws InputError when `factor` is not positive and finite
/// or when a refined count exceeds what an int holds.
void refineBlocks(BlockMeshSpec& spec, real factor);

/// Convenience: a single box.
BlockMeshSpec boxSpec(std::array<real, 3> min, std::array<real, 3> max, std::array<int, 3> cells);

}  // namespace mfsi
