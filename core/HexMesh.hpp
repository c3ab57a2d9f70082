#pragma once
/// \file
/// \brief Unstructured hexahedral mesh: nodes, 8-node cells, 4-node faces with owner/neighbour,
/// named boundary patches, baffles, and CSR adjacency, all as labelled device Views.
///
/// Layout conventions (the whole code relies on them):
///  - Hex node order is VTK/Gmsh/OpenFOAM: bottom quad 0-1-2-3 counter-clockwise seen from +z of
///    the reference cell, top quad 4-5-6-7 above it. `kHexFaces` lists the six faces with
///    outward normals (right-hand rule).
///  - Faces: internal faces first (owner < neighbour, sorted by owner then neighbour), then the
///    boundary faces grouped patch by patch. A face's node order gives a normal that points out of
///    its owner (into the neighbour for internal faces).
///  - Owned entities come first, ghosts (copies of a neighbour rank's entities) after them:
///    `nOwnedCells() <= nCells()`. On one rank there are no ghosts.
///  - A baffle is an internal face set turned into two boundary patches that share nodes:
///    "<name>_master" (the face whose outward normal is the baffle's declared normal) and
///    "<name>_slave"; face i of one pairs with face i of the other. This is how a membrane sits
///    inside the fluid.
#include "core/Types.hpp"

#include <array>
#include <string>
#include <vector>

namespace mfsi {

/// Local node lists of the six faces of a hex, outward normals.
inline constexpr int kHexFaces[6][4] = {
    {0, 3, 2, 1},  // z-
    {4, 5, 6, 7},  // z+
    {0, 1, 5, 4},  // y-
    {2, 3, 7, 6},  // y+
    {0, 4, 7, 3},  // x-
    {1, 2, 6, 5},  // x+
};

/// Local node pairs of the twelve edges of a hex.
inline constexpr int kHexEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                         {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

enum class PatchKind { Patch, Wall, Symmetry, Empty, BaffleMaster, BaffleSlave };

const char* toString(PatchKind kind);

/// \brief A named range of boundary faces.
struct Patch {
  std::string name;
  PatchKind kind = PatchKind::Patch;
  lid_t start = 0;       ///< first face (index into the mesh's face arrays)
  lid_t size = 0;        ///< number of faces
  int pairedPatch = -1;  ///< baffles: index of the other side
};

/// \brief Host-side description of a hex mesh, produced by generators and readers and turned
/// into a `HexMesh` by `buildHexMesh`. Readers and generators only fill this.
struct HexMeshInput {
  struct PatchSpec {
    std::string name;
    PatchKind kind = PatchKind::Patch;
    std::vector<std::array<lid_t, 4>> faces;  ///< boundary faces as node quads (any rotation/orientation)
  };
  struct BaffleSpec {
    std::string name;
    /// Internal faces as node quads; the node order of each quad sets the baffle normal, which
    /// points out of the master side.
    std::vector<std::array<lid_t, 4>> faces;
  };

  std::string source;  ///< file or generator name, for messages
  std::vector<std::array<real, 3>> points;
  std::vector<std::array<lid_t, 8>> cells;
  std::vector<PatchSpec> patches;
  std::vector<BaffleSpec> baffles;
  /// Name of the patch that collects boundary faces no patch claims. Empty: such faces are an error.
  std::string defaultPatch = "defaultFaces";
  /// One rank's part of a decomposed mesh (core/parallel/LocalMesh): the global ids of its cells
  /// and nodes (empty: 0, 1, 2, ...) and how many of each it owns (-1: all); owned ones come first.
  std::vector<gid_t> cellGlobalIds;
  std::vector<gid_t> nodeGlobalIds;
  lid_t nOwnedCells = -1;
  lid_t nOwnedNodes = -1;
};

/// \brief The mesh. Topology is fixed after construction; `points()` moves (ALE).
class HexMesh {
 public:
  HexMesh() = default;

  lid_t nNodes() const { return static_cast<lid_t>(points_.extent(0)); }
  lid_t nCells() const { return static_cast<lid_t>(cellNodes_.extent(0)); }
  lid_t nFaces() const { return static_cast<lid_t>(faceNodes_.extent(0)); }
  lid_t nInternalFaces() const { return nInternalFaces_; }
  lid_t nBoundaryFaces() const { return nFaces() - nInternalFaces_; }
  lid_t nOwnedCells() const { return nOwnedCells_; }
  lid_t nOwnedNodes() const { return nOwnedNodes_; }

  /// Current node positions (moved by mesh motion).
  Real3View points() const { return points_; }
  /// Reference (undeformed) node positions.
  ConstReal3View referencePoints() const { return points0_; }
  ConstHex8View cellNodes() const { return cellNodes_; }
  ConstQuad4View faceNodes() const { return faceNodes_; }
  ConstIndexView faceOwner() const { return faceOwner_; }
  /// Neighbour cell of internal faces; -1 on boundary faces (size nFaces()).
  ConstIndexView faceNeighbour() const { return faceNeighbour_; }
  /// CSR cell -> faces: faces of cell c are cellFaces()[cellFaceOffsets()[c] .. [c+1]).
  ConstIndexView cellFaceOffsets() const { return cellFaceOffsets_; }
  ConstIndexView cellFaces() const { return cellFaces_; }
  /// CSR node -> neighbouring nodes (along cell edges), sorted, without the node itself.
  ConstIndexView nodeNodeOffsets() const { return nodeNodeOffsets_; }
  ConstIndexView nodeNodes() const { return nodeNodes_; }
  /// Boundary face -> patch index (size nFaces(); -1 for internal faces).
  ConstIndexView facePatch() const { return facePatch_; }
  Kokkos::View<const gid_t*, MemSpace> cellGlobalIds() const { return cellGid_; }
  Kokkos::View<const gid_t*, MemSpace> nodeGlobalIds() const { return nodeGid_; }

  const std::vector<Patch>& patches() const { return patches_; }
  /// Index of the patch with that name, or -1.
  int findPatch(const std::string& name) const;
  /// Index of the patch with that name; throws InputError listing the patches (and a close match).
  int patchIndex(const std::string& name) const;
  /// The patch names, in patch order.
  std::vector<std::string> patchNames() const;
  /// "the mesh has no patch 'name'; did you mean '...'?; patches: a, b, c": for an InputError of a
  /// config layer, which adds the file, line and key.
  std::string noPatchMessage(const std::string& name) const;
  const std::string& source() const { return source_; }

  /// Put the nodes back at their reference positions.
  void resetPoints() const;

 private:
  friend HexMesh buildHexMesh(const HexMeshInput& in);

  std::string source_;
  lid_t nInternalFaces_ = 0;
  lid_t nOwnedCells_ = 0;
  lid_t nOwnedNodes_ = 0;
  Real3View points_;
  Real3View points0_;
  Hex8View cellNodes_;
  Quad4View faceNodes_;
  IndexView faceOwner_;
  IndexView faceNeighbour_;
  IndexView cellFaceOffsets_;
  IndexView cellFaces_;
  IndexView nodeNodeOffsets_;
  IndexView nodeNodes_;
  IndexView facePatch_;
  GlobalIndexView cellGid_;
  GlobalIndexView nodeGid_;
  std::vector<Patch> patches_;
};

/// \brief Build faces, patches, baffles and adjacency from cells. Throws InputError (naming the
/// source and the cell) for out-of-range or repeated node ids (non-hex cells), inverted or
/// degenerate cells, faces shared by more than two cells, and patch faces that are not on the
/// boundary.
HexMesh buildHexMesh(const HexMeshInput& in);

}  // namespace mfsi
