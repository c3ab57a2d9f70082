#pragma once
/// \file
/// \brief Set-up-time (host) communication of distributed sparse matrices: sparse rows sent along
/// a halo plan (an owner's rows to the ranks that hold the entry as a ghost), and halo plans built
/// from the ghosts a rank asks for. Used by the distributed AMG's Galerkin products
/// (kernels/DistributedAmg); one rank (a null or one-rank communicator) needs no MPI at all.
#include "core/Types.hpp"
#include "core/parallel/LocalMesh.hpp"

#include <mpi.h>

#include <vector>

namespace mfsi {

/// \brief Host sparse rows with global column ids.
struct GlobalRows {
  std::vector<lid_t> ptr{0};
  std::vector<gid_t> col;
  std::vector<double> val;
  lid_t size() const { return static_cast<lid_t>(ptr.size()) - 1; }
  void push(const std::vector<std::pair<gid_t, double>>& row) {
    for (const auto& [c, v] : row) {
      col.push_back(c);
      val.push_back(v);
    }
    ptr.push_back(static_cast<lid_t>(col.size()));
  }
};

/// \brief Ranks and rank of `comm` (1 and 0 for MPI_COMM_NULL).
int commSize(MPI_Comm comm);
int commRank(MPI_Comm comm);

/// \brief The rows of the ghosts of `plan` (in ghost order), each received from its owner, which
/// sends `owned` rows (indexed by local owned index) for the entries in its send lists.
GlobalRows exchangeRows(MPI_Comm comm, const HaloPlan& plan, const GlobalRows& owned);

/// \brief The halo plan of a rank that owns `nOwned` entries with global ids
/// [ownedStart, ownedStart + nOwned) and holds `ghosts` (global ids, sorted by owner rank then id,
/// owners given in `ghostOwner`): each owner learns which of its entries each rank asks for.
HaloPlan planFromGhosts(MPI_Comm comm, gid_t ownedStart, lid_t nOwned, const std::vector<gid_t>& ghosts,
                        const std::vector<int>& ghostOwner);

}  // namespace mfsi
