#include "core/io/Redistribute.hpp"

#include "core/Error.hpp"
#include "core/parallel/LocalMesh.hpp"

#include <cstring>
#include <string>

namespace mfsi::io {

PartIds partIds(const HexMesh& part, const HexMesh& global) {
  return partIds(part, globalFaceIds(part, global), MeshCounts::of(global));
}

PartIds partIds(const HexMesh& part, const std::vector<std::int64_t>& globalFaces, const MeshCounts& global) {
  PartIds ids;
  auto cells = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), part.cellGlobalIds());
  auto nodes = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), part.nodeGlobalIds());
  ids.cells.assign(cells.data(), cells.data() + cells.extent(0));
  ids.nodes.assign(nodes.data(), nodes.data() + nodes.extent(0));
  MFSI_CHECK(static_cast<lid_t>(globalFaces.size()) == part.nFaces(),
             "partIds: " << globalFaces.size() << " global faces for " << part.nFaces() << " faces");
  ids.faces = globalFaces;
  // A face is written by the rank that owns its global owner cell: the local owner when the face
  // points the global way, else the local neighbour (a processor face's other cell is elsewhere).
  auto own = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), part.faceOwner());
  auto nb = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), part.faceNeighbour());
  const lid_t nOwned = part.nOwnedCells();
  ids.ownedFaces.resize(ids.faces.size());
  for (std::size_t f = 0; f < ids.faces.size(); ++f) {
    const lid_t globalOwner = ids.faces[f] >= 0 ? own(f) : nb(f);
    ids.ownedFaces[f] = globalOwner >= 0 && globalOwner < nOwned ? 1 : 0;
  }
  ids.ownedCells = part.nOwnedCells();
  ids.ownedNodes = part.nOwnedNodes();
  ids.internalFaces = part.nInternalFaces();
  ids.globalCells = global.cells;
  ids.globalNodes = global.nodes;
  ids.globalFaces = global.faces;
  ids.globalInternalFaces = global.internalFaces;
  return ids;
}

void writePartIds(StateWriter& w, const PartIds& ids) {
  w.put("cells", ids.cells);
  w.put("nodes", ids.nodes);
  w.put("faces", ids.faces);
  w.put("ownedFaces", ids.ownedFaces);
  w.put("counts", std::vector<std::int64_t>{ids.ownedCells, ids.ownedNodes, ids.internalFaces, ids.globalCells,
                                            ids.globalNodes, ids.globalFaces, ids.globalInternalFaces});
}

PartIds wholeMeshIds(const MeshCounts& global) {
  PartIds ids;
  ids.globalCells = ids.ownedCells = global.cells;
  ids.globalNodes = ids.ownedNodes = global.nodes;
  ids.globalFaces = global.faces;
  ids.globalInternalFaces = ids.internalFaces = global.internalFaces;
  for (long long c = 0; c < ids.globalCells; ++c) ids.cells.push_back(c);
  for (long long n = 0; n < ids.globalNodes; ++n) ids.nodes.push_back(n);
  for (long long f = 0; f < ids.globalFaces; ++f) ids.faces.push_back(f);
  ids.ownedFaces.assign(ids.faces.size(), 1);
  return ids;
}

PartIds readPartIds(const StateReader& r, const MeshCounts& global) {
  PartIds ids;
  ids.globalCells = global.cells;
  ids.globalNodes = global.nodes;
  ids.globalFaces = global.faces;
  ids.globalInternalFaces = global.internalFaces;
  const auto counts = r.ints("counts", 7);
  const long long expected[] = {ids.globalCells, ids.globalNodes, ids.globalFaces, ids.globalInternalFaces};
  for (int k = 0; k < 4; ++k)
    if (counts[3 + k] != expected[k])
      throw InputError(r.where("counts") + ": written for a mesh of " + std::to_string(counts[3]) + " cells, " +
                       std::to_string(counts[4]) + " nodes and " + std::to_string(counts[5]) +
                       " faces; this run's has " + std::to_string(ids.globalCells) + ", " +
                       std::to_string(ids.globalNodes) + " and " + std::to_string(ids.globalFaces));
  ids.ownedCells = counts[0];
  ids.ownedNodes = counts[1];
  ids.internalFaces = counts[2];
  ids.cells = r.ints("cells");
  ids.nodes = r.ints("nodes");
  ids.faces = r.ints("faces");
  ids.ownedFaces = r.ints("ownedFaces", static_cast<long long>(ids.faces.size()));
  auto inRange = [&](const std::vector<std::int64_t>& v, long long n, const char* name, bool signedFaces) {
    for (std::int64_t x : v) {
      const std::int64_t g = signedFaces && x < 0 ? -x - 1 : x;
      if (g < 0 || g >= n)
        throw InputError(r.where(name) + ": global id " + std::to_string(x) + " out of range (the mesh has " +
                         std::to_string(n) + ")");
    }
  };
  inRange(ids.cells, ids.globalCells, "cells", false);
  inRange(ids.nodes, ids.globalNodes, "nodes", false);
  inRange(ids.faces, ids.globalFaces, "faces", true);
  if (ids.ownedCells < 0 || ids.ownedCells > static_cast<long long>(ids.cells.size()) || ids.ownedNodes < 0 ||
      ids.ownedNodes > static_cast<long long>(ids.nodes.size()) || ids.internalFaces < 0 ||
      ids.internalFaces > static_cast<long long>(ids.faces.size()))
    throw InputError(r.where("counts") + ": owned or internal counts beyond the part's entities");
  return ids;
}

namespace {

std::string where(const Hdf5File& f, const std::string& dataset) {
  return "checkpoint '" + f.path() + "', '" + dataset + "'";
}

/// The rows of a part that hold `rows` entities, and the whole mesh's count of them.
long long localRows(const PartIds& p, Entity e) {
  switch (e) {
    case Entity::Cells: return static_cast<long long>(p.cells.size());
    case Entity::Nodes: return static_cast<long long>(p.nodes.size());
    case Entity::FaceFluxes: return static_cast<long long>(p.faces.size());
    case Entity::BoundaryFaces: return static_cast<long long>(p.faces.size()) - p.internalFaces;
    case Entity::Part:
    case Entity::RankOwn: break;
  }
  return 0;
}

long long globalRows(const PartIds& p, Entity e) {
  switch (e) {
    case Entity::Cells: return p.globalCells;
    case Entity::Nodes: return p.globalNodes;
    case Entity::FaceFluxes:
    case Entity::BoundaryFaces: return p.globalFaces;  // boundary rows by global face id
    case Entity::Part:
    case Entity::RankOwn: break;
  }
  return 0;
}

/// The global row of local row `i`, its sign, and whether the part writes it for everyone;
/// -1 when the row has no global counterpart (a processor face of a boundary-face array).
struct Row {
  long long global = -1;
  double sign = 1;
  bool owned = false;
};

Row rowOf(const PartIds& p, Entity e, long long i) {
  Row r;
  auto decode = [&](std::int64_t code) {
    r.global = code >= 0 ? code : -code - 1;
    r.sign = code >= 0 ? 1.0 : -1.0;
  };
  switch (e) {
    case Entity::Cells:
      r.global = p.cells[i];
      r.owned = i < p.ownedCells;
      break;
    case Entity::Nodes:
      r.global = p.nodes[i];
      r.owned = i < p.ownedNodes;
      break;
    case Entity::FaceFluxes:
      decode(p.faces[i]);
      r.owned = p.ownedFaces[i] != 0;
      break;
    case Entity::BoundaryFaces: {
      const long long f = p.internalFaces + i;
      decode(p.faces[f]);
      r.sign = 1.0;  // outward on both sides: a boundary face has one cell
      if (r.global < p.globalInternalFaces) r.global = -1;
      r.owned = r.global >= 0 && p.ownedFaces[f] != 0;
      break;
    }
    case Entity::Part:
    case Entity::RankOwn: break;
  }
  return r;
}

void copyUntagged(const std::vector<const Hdf5File*>& parts, const std::string& d, Hdf5File& out) {
  std::vector<std::size_t> dims;
  if (parts[0]->holdsIntegers(d)) {
    const auto v = parts[0]->readInts(d, &dims);
    for (std::size_t r = 1; r < parts.size(); ++r)
      if (parts[r]->readInts(d) != v)
        throw InputError(where(*parts[r], d) + ": differs from rank 0's, and is not marked as a part's own "
                         "values: the checkpoint cannot be carried to another decomposition");
    out.write(d, v, dims);
    return;
  }
  const auto v = parts[0]->readDoubles(d, &dims);
  for (std::size_t r = 1; r < parts.size(); ++r) {
    const auto w = parts[r]->readDoubles(d);
    if (w.size() != v.size() || (!v.empty() && std::memcmp(w.data(), v.data(), v.size() * sizeof(double)) != 0))
      throw InputError(where(*parts[r], d) + ": differs from rank 0's, and is not marked as a part's own "
                       "values: the checkpoint cannot be carried to another decomposition");
  }
  out.write(d, v, dims);
}

void carryRows(const std::vector<const Hdf5File*>& parts, const std::vector<PartIds>& old, const PartIds& mine,
               const std::string& d, Entity e, Hdf5File& out) {
  std::vector<std::size_t> dims;
  std::vector<double> values = parts[0]->readDoubles(d, &dims);
  std::size_t width = 1;
  for (std::size_t k = 1; k < dims.size(); ++k) width *= dims[k];
  std::vector<std::size_t> outDims = dims;
  if (dims[0] == 0) {  // an array not allocated (yet): the same on every rank
    for (std::size_t r = 1; r < parts.size(); ++r)
      if (parts[r]->shape(d)[0] != 0)
        throw InputError(where(*parts[r], d) + ": has rows where rank 0's has none");
    out.write(d, values, outDims);
    return;
  }
  const long long nGlobal = globalRows(mine, e);
  std::vector<double> whole(static_cast<std::size_t>(nGlobal) * width, 0.0);
  std::vector<char> have(static_cast<std::size_t>(nGlobal), 0);
  for (std::size_t r = 0; r < parts.size(); ++r) {
    std::vector<std::size_t> rd;
    if (r > 0) values = parts[r]->readDoubles(d, &rd);
    else rd = dims;
    if (static_cast<long long>(rd[0]) != localRows(old[r], e) || rd.size() != dims.size() ||
        values.size() != rd[0] * width)
      throw InputError(where(*parts[r], d) + ": " + std::to_string(rd[0]) + " rows, the rank's part has " +
                       std::to_string(localRows(old[r], e)) + " (a checkpoint of another mesh?)");
    for (long long i = 0; i < static_cast<long long>(rd[0]); ++i) {
      const Row row = rowOf(old[r], e, i);
      if (!row.owned) continue;
      for (std::size_t k = 0; k < width; ++k) whole[row.global * width + k] = row.sign * values[i * width + k];
      have[row.global] = 1;
    }
  }
  const long long n = localRows(mine, e);
  outDims[0] = static_cast<std::size_t>(n);
  std::vector<double> local(static_cast<std::size_t>(n) * width, 0.0);
  for (long long i = 0; i < n; ++i) {
    const Row row = rowOf(mine, e, i);
    if (row.global < 0) continue;  // a processor face: no boundary value
    if (!have[row.global])
      throw InputError(where(*parts[0], d) + ": no rank of the checkpoint wrote global row " +
                       std::to_string(row.global) + " (its files do not belong together)");
    for (std::size_t k = 0; k < width; ++k) local[i * width + k] = row.sign * whole[row.global * width + k];
  }
  out.write(d, local, outDims);
}

}  // namespace

void redistribute(const std::vector<const Hdf5File*>& parts, const std::vector<PartIds>& old, const PartIds& mine,
                  Hdf5File& out) {
  MFSI_CHECK(!parts.empty() && parts.size() == old.size(),
             "redistribute: " << parts.size() << " files for " << old.size() << " parts");
  for (const std::string& d : parts[0]->datasets()) {
    const bool carried = d.rfind("/modules/", 0) == 0 || (d.rfind("/mesh/", 0) == 0 && parts[0]->has(entityTagPath(d)));
    if (!carried) continue;
    for (const Hdf5File* p : parts)
      if (!p->has(d)) throw InputError(where(*p, d) + ": missing (rank 0's file has it)");
    const std::string tag = entityTagPath(d);
    if (!parts[0]->has(tag)) {
      copyUntagged(parts, d, out);
      continue;
    }
    const auto e = static_cast<Entity>(parts[0]->readInts(tag).at(0));
    if (e == Entity::Part) continue;
    if (e == Entity::RankOwn) {
      copyUntagged({parts[0]}, d, out);
      continue;
    }
    if (e != Entity::Cells && e != Entity::Nodes && e != Entity::FaceFluxes && e != Entity::BoundaryFaces)
      throw InputError(where(*parts[0], tag) + ": unknown kind of rows " + std::to_string(static_cast<int>(e)));
    carryRows(parts, old, mine, d, e, out);
  }
}

}  // namespace mfsi::io
