#pragma once
/// \file
/// \brief Structured block generator: boxes with per-direction cell counts and grading, glued
/// where they touch, named patches per side, and baffles declared as rectangles on grid planes.
/// Produces the same unstructured `HexMeshInput` as the file readers.
#include "core/HexMesh.hpp"

#include <map>

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

/// Generate the mesh description. Throws InputError for invalid specs (non-positive counts or sizes,
/// baffles that select no face).
HexMeshInput generateBlockMesh(const BlockMeshSpec& spec);

/// Convenience: a single box.
BlockMeshSpec boxSpec(std::array<real, 3> min, std::array<real, 3> max, std::array<int, 3> cells);

}  // namespace mfsi
