#include "core/parallel/Gather.hpp"

#include "core/Error.hpp"

#include <numeric>

namespace mfsi {

std::vector<double> gatherByGlobalId(MPI_Comm comm, int root, const std::vector<gid_t>& ids,
                                     const std::vector<double>& values, int components, std::size_t nGlobal) {
  MFSI_CHECK(values.size() == ids.size() * static_cast<std::size_t>(components),
             "gather: " << values.size() << " values for " << ids.size() << " entries of " << components);
  int ranks = 1, rank = 0;
  MPI_Comm_size(comm, &ranks);
  MPI_Comm_rank(comm, &rank);
  const int n = static_cast<int>(ids.size());
  std::vector<int> counts(rank == root ? ranks : 0), offsets;
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, root, comm);
  std::vector<long long> myIds(ids.begin(), ids.end()), allIds;
  std::vector<double> allValues;
  std::vector<int> valueCounts, valueOffsets;
  if (rank == root) {
    offsets.resize(ranks);
    std::exclusive_scan(counts.begin(), counts.end(), offsets.begin(), 0);
    allIds.resize(static_cast<std::size_t>(offsets.back()) + counts.back());
    for (int r = 0; r < ranks; ++r) {
      valueCounts.push_back(counts[r] * components);
      valueOffsets.push_back(offsets[r] * components);
    }
    allValues.resize(allIds.size() * components);
  }
  MPI_Gatherv(myIds.data(), n, MPI_LONG_LONG, allIds.data(), counts.data(), offsets.data(), MPI_LONG_LONG, root, comm);
  MPI_Gatherv(values.data(), n * components, MPI_DOUBLE, allValues.data(), valueCounts.data(), valueOffsets.data(),
              MPI_DOUBLE, root, comm);
  if (rank != root) return {};
  MFSI_CHECK(allIds.size() == nGlobal, "gather: the ranks own " << allIds.size() << " entries, not " << nGlobal);
  std::vector<double> out(nGlobal * components);
  std::vector<char> seen(nGlobal, 0);
  for (std::size_t i = 0; i < allIds.size(); ++i) {
    const long long g = allIds[i];
    MFSI_CHECK(g >= 0 && static_cast<std::size_t>(g) < nGlobal && !seen[g], "gather: entry " << g << " twice or out of range");
    seen[g] = 1;
    for (int k = 0; k < components; ++k) out[g * components + k] = allValues[i * components + k];
  }
  return out;
}

}  // namespace mfsi
