#pragma once
/// \file
/// \brief Rows of one file written by every rank at once: each rank's part of a decomposed
/// dataset, at the rows its global ids name (MPI-IO: the file opened collectively, each rank's
/// runs of consecutive rows written through a file view, independently: Open MPI's collective
/// write reports success when its aggregating rank's write failed).
///
/// The field output of a decomposed mesh lays its frame out on one rank (Hdf5File::reserve and
/// commitLayout) and has every rank write its rows of the mesh's datasets here: no rank gathers
/// or writes the whole mesh's values.
#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace mfsi::io {

/// \brief A rank's rows of one dataset: `nRows` rows of `width` 8-byte values (`values`, local
/// row-major), local row r to global row `rows[r]` of the dataset that starts `offset` bytes into
/// the file.
struct RowPiece {
  std::uint64_t offset = 0;
  std::size_t width = 1;
  const std::int64_t* rows = nullptr;
  std::size_t nRows = 0;
  const void* values = nullptr;
};

/// \brief Every rank's verdict on a step that each rank may fail with a message (`mine`, "" for
/// success). Collective over `comm`: "" on every rank when all succeeded, else on every rank the
/// message of the lowest rank that failed.
std::string agreeOnFailure(MPI_Comm comm, const std::string& mine);

/// \brief Write every rank's pieces into the existing file `path`. Collective over `comm`: returns
/// "" on every rank when every rank wrote all of its rows, else on every rank the message of the
/// lowest rank that could not (naming the file, or `shownAs` when given: the name the file is
/// published under, and asking whether the disk is full).
std::string writeRows(MPI_Comm comm, const std::string& path, const std::vector<RowPiece>& pieces,
                      const std::string& shownAs = {});

}  // namespace mfsi::io
