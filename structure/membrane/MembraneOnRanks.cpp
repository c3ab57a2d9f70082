#include "structure/membrane/MembraneOnRanks.hpp"

#include "core/Error.hpp"
#include "core/parallel/ByteBuffer.hpp"
#include "core/parallel/FailureAgreement.hpp"

#include <vector>

namespace mfsi {

namespace {

void pack(const FluidSurfaceMembraneInput& s, ByteWriter& w) {
  w.string(s.mesh.source);
  w.vector(s.mesh.points);
  w.vector(s.mesh.elements);
  w.count(s.mesh.nodeSets.size());
  for (const auto& [name, nodes] : s.mesh.nodeSets) {
    w.string(name);
    w.vector(nodes);
  }
  w.vector(s.fluidNode);
  w.vector(s.masterFaceNodes);
  w.vector(s.slaveFaceNodes);
}

FluidSurfaceMembraneInput unpack(const std::vector<char>& bytes) {
  ByteReader r(bytes);
  FluidSurfaceMembraneInput s;
  s.mesh.source = r.string();
  r.vector(s.mesh.points);
  r.vector(s.mesh.elements);
  const std::uint64_t sets = r.count();
  for (std::uint64_t i = 0; i < sets; ++i) {
    const std::string name = r.string();
    r.vector(s.mesh.nodeSets[name]);
  }
  r.vector(s.fluidNode);
  r.vector(s.masterFaceNodes);
  r.vector(s.slaveFaceNodes);
  MFSI_CHECK(r.done(), "membrane surface: " << bytes.size() << " bytes received, not all read");
  return s;
}

FluidSurfaceMembraneInput cut(const HexMesh& mesh, const FluidSurfaceName& surface) {
  return surface.baffle ? membraneMeshFromBaffle(mesh, surface.name) : membraneMeshFromPatch(mesh, surface.name);
}

}  // namespace

FluidSurfaceMembraneInput cutMembraneOnRanks(const HexMesh& part, const FluidSurfaceName& surface, MPI_Comm comm) {
  int ranks = 1, rank = 0;
  MPI_Comm_size(comm, &ranks);
  MPI_Comm_rank(comm, &rank);
  // The faces this rank owns (through their cells): the owner owns them all.
  const int pi = part.findPatch(surface.baffle ? surface.name + "_master" : surface.name);
  long long mine = 0;
  if (pi >= 0) {
    auto own = Kokkos::create_mirror_view_and_copy(HostSpace(), part.faceOwner());
    const Patch& p = part.patches()[pi];
    for (lid_t f = p.start; f < p.start + p.size; ++f) mine += own(f) < part.nOwnedCells() ? 1 : 0;
  }
  std::vector<long long> owned(static_cast<std::size_t>(ranks));
  MPI_Allgather(&mine, 1, MPI_LONG_LONG, owned.data(), 1, MPI_LONG_LONG, comm);
  long long total = 0;
  int owner = -1;
  for (int r = 0; r < ranks; ++r) total += owned[r];
  for (int r = 0; r < ranks && owner < 0; ++r)
    if (owned[r] == total) owner = r;
  // No such surface, or one without faces: every rank's part says so alike (its cut throws the
  // whole mesh's message, every rank at once).
  if (total == 0) return cut(part, surface);
  const std::string what = std::string(surface.baffle ? "baffle '" : "patch '") + surface.name + "'";
  if (owner < 0) {
    std::string spread;
    for (int r = 0; r < ranks; ++r)
      if (owned[r] > 0) spread += (spread.empty() ? "" : ", ") + std::to_string(r);
    throw InputError(part.source() + ": the faces of " + what + " are owned by ranks " + spread +
                     "; a membrane's cells must stay on one rank");
  }
  // The owner cuts; a failure there reaches every rank as the same error.
  FluidSurfaceMembraneInput out;
  ByteWriter packed;
  runOnOneRank(comm, owner, [&] {
    out = cut(part, surface);
    pack(out, packed);
  });
  std::uint64_t size = packed.bytes().size();
  MPI_Bcast(&size, 1, MPI_UINT64_T, owner, comm);
  packed.bytes().resize(size);
  MPI_Bcast(packed.bytes().data(), static_cast<int>(size), MPI_CHAR, owner, comm);
  if (rank != owner) out = unpack(packed.bytes());
  return out;
}

}  // namespace mfsi
