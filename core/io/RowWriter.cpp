#include "core/io/RowWriter.hpp"

#include <algorithm>
#include <climits>
#include <cstring>

namespace mfsi::io {

namespace {

/// One run of consecutive rows: `words` 8-byte values from `from` to the file's byte `at`.
struct RowRun {
  std::uint64_t at;
  std::uint64_t words;
  const char* from;
};

std::string mpiWriteFailure(const std::string& path, const char* what, int rc) {
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(rc, text, &len);
  return "cannot write '" + path + "' (MPI-IO " + what + ": " + std::string(text, static_cast<std::size_t>(len)) +
         ") (is the disk full?)";
}

}  // namespace

std::string agreeOnFailure(MPI_Comm comm, const std::string& mine) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int first = mine.empty() ? size : rank;
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size) return "";
  char text[1024] = {};
  if (rank == first) std::strncpy(text, mine.c_str(), sizeof text - 1);
  MPI_Bcast(text, sizeof text, MPI_CHAR, first, comm);
  return text;
}

std::string writeRows(MPI_Comm comm, const std::string& path, const std::vector<RowPiece>& pieces,
                      const std::string& shownAs) {
  const std::string& name = shownAs.empty() ? path : shownAs;  // what the messages call the file
  // The runs of consecutive rows, in the file's order (a file view must not go backwards).
  std::vector<RowRun> blocks;
  for (const RowPiece& p : pieces) {
    const char* values = static_cast<const char*>(p.values);
    const std::uint64_t rowBytes = 8 * static_cast<std::uint64_t>(p.width);
    for (std::size_t r = 0; r < p.nRows;) {
      std::size_t e = r + 1;
      while (e < p.nRows && p.rows[e] == p.rows[e - 1] + 1) ++e;
      blocks.push_back({p.offset + static_cast<std::uint64_t>(p.rows[r]) * rowBytes,
                        static_cast<std::uint64_t>(e - r) * p.width, values + r * rowBytes});
      r = e;
    }
  }
  std::sort(blocks.begin(), blocks.end(), [](const RowRun& a, const RowRun& b) { return a.at < b.at; });
  std::uint64_t total = 0;
  for (const RowRun& b : blocks) total += b.words;
  std::vector<double> buffer(static_cast<std::size_t>(total));
  std::vector<int> lengths;
  std::vector<MPI_Aint> displacements;
  std::uint64_t filled = 0;
  constexpr std::uint64_t kMaxRun = std::uint64_t(1) << 30;  // words per file-view block (an int)
  for (const RowRun& b : blocks) {
    std::memcpy(buffer.data() + filled, b.from, 8 * b.words);
    filled += b.words;
    for (std::uint64_t done = 0; done < b.words; done += kMaxRun) {
      const std::uint64_t at = b.at + 8 * done;
      const auto n = static_cast<int>(std::min(kMaxRun, b.words - done));
      if (!lengths.empty() && static_cast<std::uint64_t>(displacements.back()) + 8 * std::uint64_t(lengths.back()) == at &&
          std::uint64_t(lengths.back()) + n <= kMaxRun) {
        lengths.back() += n;  // rows of two pieces that meet in the file
      } else {
        lengths.push_back(n);
        displacements.push_back(static_cast<MPI_Aint>(at));
      }
    }
  }
  std::string failure;
  if (total > static_cast<std::uint64_t>(INT_MAX) || lengths.size() > static_cast<std::size_t>(INT_MAX))
    failure = "cannot write '" + name + "': this rank's part of it (" + std::to_string(8 * total) +
              " bytes) is larger than one MPI-IO call writes (16 GiB)";
  // Each collective call is made on every rank; a rank that failed before it takes part with
  // nothing to write, and the verdict is agreed at the end.
  MPI_File fh = MPI_FILE_NULL;
  int rc = MPI_File_open(comm, path.c_str(), MPI_MODE_WRONLY, MPI_INFO_NULL, &fh);
  if (rc != MPI_SUCCESS && failure.empty()) failure = mpiWriteFailure(name, "open", rc);
  const std::string opened = agreeOnFailure(comm, rc == MPI_SUCCESS ? "" : "x");
  if (!opened.empty()) {
    if (fh != MPI_FILE_NULL) MPI_File_close(&fh);
    const std::string verdict = agreeOnFailure(comm, failure);
    return verdict.empty() ? "cannot open '" + name + "' on every rank (MPI-IO)" : verdict;
  }
  MPI_Datatype word = MPI_DATATYPE_NULL, view = MPI_DATATYPE_NULL;
  MPI_Type_contiguous(8, MPI_BYTE, &word);
  MPI_Type_commit(&word);
  const bool writes = failure.empty() && !lengths.empty();
  if (writes) {
    MPI_Type_create_hindexed(static_cast<int>(lengths.size()), lengths.data(), displacements.data(), word, &view);
    MPI_Type_commit(&view);
  }
  rc = MPI_File_set_view(fh, 0, word, writes ? view : word, "native", MPI_INFO_NULL);
  if (rc != MPI_SUCCESS && failure.empty()) failure = mpiWriteFailure(name, "set_view", rc);
  MPI_Status status;
  const int count = writes && rc == MPI_SUCCESS ? static_cast<int>(total) : 0;
  // Independent writes: Open MPI's collective writes (ompio's two-phase aggregation) report
  // success and the full count when their aggregator's write failed (a full disk, EFBIG); its
  // independent writes report the short count.
  rc = count > 0 ? MPI_File_write(fh, buffer.data(), count, word, &status) : MPI_SUCCESS;
  if (rc != MPI_SUCCESS && failure.empty()) failure = mpiWriteFailure(name, "write", rc);
  if (rc == MPI_SUCCESS && failure.empty() && count > 0) {
    int written = 0;
    MPI_Get_count(&status, word, &written);
    if (written != count) failure = "cannot write '" + name + "': " + std::to_string(written) + " of " +
                                    std::to_string(count) + " values written (is the disk full?)";
  }
  rc = MPI_File_close(&fh);
  if (rc != MPI_SUCCESS && failure.empty()) failure = mpiWriteFailure(name, "close", rc);
  if (view != MPI_DATATYPE_NULL) MPI_Type_free(&view);
  MPI_Type_free(&word);
  return agreeOnFailure(comm, failure);
}

}  // namespace mfsi::io
