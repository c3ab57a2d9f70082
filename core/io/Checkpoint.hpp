#pragma once
/// \file
/// \brief The state of a run in a checkpoint file: each module writes the arrays and numbers it
/// needs to continue *bitwise* under a group of its own, and reads them back on restart.
///
/// A checkpoint is one HDF5 file (core/io/Hdf5File: written under a temporary name and renamed,
/// so it is never half-written). Values are stored exactly (IEEE doubles, 64-bit integers); a
/// View is stored with its extents, and reading it back into a View of other extents is an
/// InputError naming the checkpoint and the dataset (a restart with another mesh or membrane).
#include "core/Error.hpp"
#include "core/Types.hpp"
#include "core/io/Hdf5File.hpp"

#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace mfsi::io {

/// \brief What the rows of a checkpointed array belong to, so that a checkpoint written on one
/// decomposition of the mesh can continue on another (core/io/Redistribute): a tagged array is
/// carried by global id, an untagged one is the same on every rank and copied as it is.
enum class Entity {
  Cells,          ///< one row per local cell (owned, then ghosts)
  FaceFluxes,     ///< one row per local face, oriented: the sign changes with the face's direction
  BoundaryFaces,  ///< one row per local boundary face (face nInternalFaces + row), outward
  Nodes,          ///< one row per local node
  Part,           ///< depends on how the mesh is cut (a matrix's values): rebuilt on another one
  RankOwn         ///< may differ between ranks and steers nothing (a wall time): rank 0's is carried
};

/// Where a checkpoint records the Entity of the dataset at `path` ("/modules/fluid/solver/U").
inline std::string entityTagPath(const std::string& path) { return "/entities" + path; }

/// \brief Writes named values under one group of a checkpoint.
class StateWriter {
 public:
  StateWriter(Hdf5File& file, std::string group) : file_(&file), group_(std::move(group)) {}
  /// The writer of a sub-group `<group>/<name>`.
  StateWriter sub(const std::string& name) const { return StateWriter(*file_, group_ + "/" + name); }

  void put(const std::string& name, const std::vector<double>& values);
  void put(const std::string& name, const std::vector<std::int64_t>& values);
  void putReal(const std::string& name, double value) { put(name, std::vector<double>{value}); }
  void putInt(const std::string& name, long long value) { put(name, std::vector<std::int64_t>{value}); }
  void putBool(const std::string& name, bool value) { putInt(name, value ? 1 : 0); }
  /// Text as its bytes (a scene, a list of names).
  void putText(const std::string& name, const std::string& text);

  /// A View of rank 1 to 3 (any memory space) with its extents; unallocated Views store no values.
  template <class View>
  void putView(const std::string& name, const View& v) {
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
    std::vector<std::size_t> dims;
    for (unsigned r = 0; r < View::rank; ++r) dims.push_back(v.extent(r));
    using T = std::remove_const_t<typename View::value_type>;
    if constexpr (std::is_floating_point_v<T>) {
      std::vector<double> out;
      flatten(h, out);
      write(name, out, dims);
    } else {
      std::vector<std::int64_t> out;
      flatten(h, out);
      write(name, out, dims);
    }
  }

  /// The same, with the Entity its rows belong to (recorded beside it, see entityTagPath).
  template <class View>
  void putView(const std::string& name, const View& v, Entity rows) {
    putView(name, v);
    tag(name, rows);
  }

  /// Record the Entity of a dataset written under this group (what putView with one does).
  void tag(const std::string& name, Entity rows);

  const std::string& group() const { return group_; }

 private:
  template <class H, class T>
  static void flatten(const H& h, std::vector<T>& out) {
    constexpr unsigned rank = H::rank;
    static_assert(rank >= 1 && rank <= 3, "checkpoint Views have rank 1 to 3");
    const std::size_t n0 = h.extent(0), n1 = rank > 1 ? h.extent(1) : 1, n2 = rank > 2 ? h.extent(2) : 1;
    out.reserve(n0 * n1 * n2);
    for (std::size_t i = 0; i < n0; ++i)
      for (std::size_t j = 0; j < n1; ++j)
        for (std::size_t k = 0; k < n2; ++k) {
          if constexpr (rank == 1) out.push_back(static_cast<T>(h(i)));
          else if constexpr (rank == 2) out.push_back(static_cast<T>(h(i, j)));
          else out.push_back(static_cast<T>(h(i, j, k)));
        }
  }
  void write(const std::string& name, const std::vector<double>& v, const std::vector<std::size_t>& dims);
  void write(const std::string& name, const std::vector<std::int64_t>& v, const std::vector<std::size_t>& dims);

  Hdf5File* file_;
  std::string group_;
};

/// \brief Reads what a StateWriter wrote. Every missing dataset or wrong size is an InputError
/// that names the checkpoint file and the dataset.
class StateReader {
 public:
  StateReader(const Hdf5File& file, std::string group) : file_(&file), group_(std::move(group)) {}
  StateReader sub(const std::string& name) const { return StateReader(*file_, group_ + "/" + name); }

  bool has(const std::string& name) const;
  /// The stored shape of a dataset (InputError when it is missing).
  std::vector<std::size_t> shape(const std::string& name) const;
  /// All values of a dataset; with `expected` >= 0 its size must be that.
  std::vector<double> doubles(const std::string& name, long long expected = -1) const;
  std::vector<std::int64_t> ints(const std::string& name, long long expected = -1) const;
  double real(const std::string& name) const { return doubles(name, 1)[0]; }
  long long integer(const std::string& name) const { return ints(name, 1)[0]; }
  bool boolean(const std::string& name) const { return integer(name) != 0; }
  std::string text(const std::string& name) const;

  /// Fill an allocated View (or leave an unallocated one) from a dataset of the same extents.
  template <class View>
  void getView(const std::string& name, const View& v) const {
    std::vector<std::size_t> dims;
    for (unsigned r = 0; r < View::rank; ++r) dims.push_back(v.extent(r));
    auto h = Kokkos::create_mirror_view(Kokkos::HostSpace(), v);
    using T = typename View::value_type;
    if constexpr (std::is_floating_point_v<T>) {
      fill(h, read<double>(name, dims));
    } else {
      fill(h, read<std::int64_t>(name, dims));
    }
    Kokkos::deep_copy(v, h);
  }

  const std::string& group() const { return group_; }
  /// "checkpoint '<file>', '<group>/<name>'": for messages.
  std::string where(const std::string& name) const;

 private:
  template <class H, class T>
  static void fill(const H& h, const std::vector<T>& in) {
    constexpr unsigned rank = H::rank;
    const std::size_t n0 = h.extent(0), n1 = rank > 1 ? h.extent(1) : 1, n2 = rank > 2 ? h.extent(2) : 1;
    std::size_t at = 0;
    for (std::size_t i = 0; i < n0; ++i)
      for (std::size_t j = 0; j < n1; ++j)
        for (std::size_t k = 0; k < n2; ++k) {
          using V = typename H::value_type;
          if constexpr (rank == 1) h(i) = static_cast<V>(in[at++]);
          else if constexpr (rank == 2) h(i, j) = static_cast<V>(in[at++]);
          else h(i, j, k) = static_cast<V>(in[at++]);
        }
  }
  /// The dataset's values, checked to have exactly the shape `dims`.
  template <class T>
  std::vector<T> read(const std::string& name, const std::vector<std::size_t>& dims) const;

  const Hdf5File* file_;
  std::string group_;
};

}  // namespace mfsi::io
