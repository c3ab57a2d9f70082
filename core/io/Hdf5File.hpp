#pragma once
/// \file
/// \brief One HDF5 file of results: datasets of doubles or 64-bit integers at slash paths
/// ("/mesh/points"), written whole, every call checked.
///
/// A file being written lives under a temporary name (`<path>.part`) and appears at its own path
/// only on `commit()`, so a crash, a signal or a full disk never leaves a truncated file that looks
/// complete. It is built in memory (as much memory as the file) and written into the temporary
/// file by `commit()`, so that a failed write (a full disk) fails in a checked write of ours rather
/// than inside HDF5, which cannot recover from one. Serial HDF5 calls on the library of Debian's
/// Open MPI build.
///
/// A file that several ranks write together (a decomposed mesh's field frame) is laid out by one
/// rank: it `reserve()`s the datasets whose rows the ranks hold (contiguous, their space allocated
/// at once, never filled), and `commitLayout()` writes everything else to `<path>.part` and says
/// where each reserved dataset lies; every rank then writes its rows there (io::writeRows), and the
/// file is renamed to its path once all have. HDF5 itself only ever sees the one rank's file in
/// memory, so a full disk again fails in a checked write of ours.
#include <cstdint>
#include <string>
#include <vector>

namespace mfsi::io {

/// \brief Where a reserved dataset's values lie in its file: `bytes` from `offset`, row-major.
struct ReservedDataset {
  std::string name;
  std::uint64_t offset = 0;
  std::uint64_t bytes = 0;
};

class Hdf5File {
 public:
  /// Start a new file that will appear at `path` on commit (an existing file there stays until
  /// then). Throws OutputError naming the path when the file cannot be created.
  static Hdf5File create(const std::string& path);
  /// As create(), for a file whose large datasets are reserve()d: its metadata is allocated in
  /// blocks of 64 KiB, so that it lies before the reserved values rather than among them.
  static Hdf5File createShared(const std::string& path);
  /// A file in memory alone, named `name` in messages: written and read like any other, never
  /// on disk (commit() refuses it). What a checkpoint carried to another decomposition is built in.
  static Hdf5File scratch(const std::string& name);
  /// Open an existing file for reading. Throws OutputError naming the path.
  static Hdf5File openRead(const std::string& path);

  Hdf5File(Hdf5File&& other) noexcept;
  Hdf5File& operator=(Hdf5File&& other) noexcept;
  Hdf5File(const Hdf5File&) = delete;
  Hdf5File& operator=(const Hdf5File&) = delete;
  /// Closes the file; a created file that was not committed is removed.
  ~Hdf5File();

  /// Write a dataset of `dims` (row-major; the product must equal the data's size); the groups on
  /// its path are created as needed. Throws OutputError naming file and dataset.
  void write(const std::string& dataset, const std::vector<double>& data, const std::vector<std::size_t>& dims);
  void write(const std::string& dataset, const std::vector<std::int64_t>& data, const std::vector<std::size_t>& dims);
  /// Create a dataset of `dims` (doubles, or 64-bit integers when `integers`) whose values are
  /// written into the file after commitLayout(), not through this object.
  void reserve(const std::string& dataset, const std::vector<std::size_t>& dims, bool integers);
  /// A scalar attribute on the root group.
  void writeAttribute(const std::string& name, double value);

  /// Read a whole dataset; `dims` (optional) receives its shape. Throws OutputError when absent.
  std::vector<double> readDoubles(const std::string& dataset, std::vector<std::size_t>* dims = nullptr) const;
  std::vector<std::int64_t> readInts(const std::string& dataset, std::vector<std::size_t>* dims = nullptr) const;
  double readAttribute(const std::string& name) const;
  bool has(const std::string& dataset) const;
  /// Every dataset of the file by its path ("/modules/fluid/U"), sorted.
  std::vector<std::string> datasets() const;
  /// Whether a dataset holds integers (else doubles). Throws OutputError when absent.
  bool holdsIntegers(const std::string& dataset) const;
  /// The shape of a dataset. Throws OutputError when absent.
  std::vector<std::size_t> shape(const std::string& dataset) const;

  /// Write the file to `<path>.part` and rename it to its path. Throws OutputError naming the path
  /// when any of it fails (nothing is then left at `<path>.part`, and a file already at `path`
  /// stays as it was).
  void commit();

  /// Write the file to `<path>.part` but for the reserved datasets' bytes (left for their
  /// writers), and say where those are, in the order they were reserved. The file stays at
  /// `<path>.part`, whole once every reserved byte is written; its writers then rename it. Throws
  /// OutputError naming the path (nothing is then left at `<path>.part`).
  std::vector<ReservedDataset> commitLayout();

  const std::string& path() const { return path_; }

 private:
  Hdf5File() = default;
  static Hdf5File createInMemory(const std::string& path, std::size_t metadataBlock);
  void close() noexcept;
  std::int64_t openDataset(const std::string& dataset, std::vector<std::size_t>* dims) const;

  std::int64_t file_ = -1;  ///< hid_t
  std::string path_;        ///< where the file appears
  std::string writing_;     ///< the temporary name while it is written ("" when reading)
  std::vector<std::string> reserved_;  ///< datasets reserve() created, in order
};

}  // namespace mfsi::io
