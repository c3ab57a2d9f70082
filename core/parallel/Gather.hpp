#pragma once
/// \file
/// \brief Results of a decomposed mesh put back together on one rank: each rank's owned entries,
/// by global id, into one array in the whole mesh's order (for the field output, which one rank
/// writes).
#include "core/Types.hpp"

#include <mpi.h>

#include <cstddef>
#include <vector>

namespace mfsi {

/// \brief On `root`: the `components` values of every global entry [0, nGlobal), each from the
/// rank that owns it (`ids` and `values` are this rank's owned entries, values entry-major). On
/// the other ranks: empty. Collective over `comm`. Throws when the ranks' entries do not cover
/// [0, nGlobal) exactly once.
std::vector<double> gatherByGlobalId(MPI_Comm comm, int root, const std::vector<gid_t>& ids,
                                     const std::vector<double>& values, int components, std::size_t nGlobal);

}  // namespace mfsi
