#pragma once
/// \file
/// \brief Set-up data over the copies of shared entries (the nodes several ranks hold), on the
/// host: each rank computes what it can see on its own part (the boundary faces at a node, the
/// patches it lies on), and these put the copies together: each ghost copy's values folded into
/// its owner, the owner's result copied back to every copy, and small sets of rows (a patch's
/// points) gathered by global id onto every rank. None of it needs the whole mesh.
#include "core/Types.hpp"
#include "core/parallel/LocalMesh.hpp"

#include <mpi.h>

#include <functional>
#include <vector>

namespace mfsi {

/// \brief Every rank's values of its ghost entries [plan.nOwned, plan.nLocal) (`components` per
/// entry, entry-major over the rank's local entries) sent to their owners; on the owner,
/// `fold(owned index, the copy's values)` for each copy: neighbour by neighbour in ascending rank,
/// each neighbour's entries in the plan's order, so the same order on every run. Collective.
void foldGhostsIntoOwners(MPI_Comm comm, const HaloPlan& plan, int components, const std::vector<double>& values,
                          const std::function<void(lid_t, const double*)>& fold);

/// \brief The ghost entries of `values` <- their owners' values (the halo exchange, for set-up
/// data on the host). Collective.
void copyOwnersToGhosts(MPI_Comm comm, const HaloPlan& plan, int components, std::vector<double>& values);

/// \brief Rows by global id, the same on every rank: ids ascending, each once.
struct GatheredRows {
  std::vector<gid_t> ids;
  std::vector<double> values;  ///< `components` per id, in the order of ids
};

/// \brief Every rank's rows (`ids`, and `components` values each) onto every rank, sorted by id;
/// an id that several ranks give is kept once, the lowest rank's copy (the copies of a shared
/// node's reference position are the same bits). Collective.
GatheredRows gatherRowsEverywhere(MPI_Comm comm, const std::vector<gid_t>& ids, const std::vector<double>& values,
                                  int components);

}  // namespace mfsi
