#include "core/io/Hdf5File.hpp"

#include "core/Error.hpp"

#include <hdf5.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <system_error>
#include <type_traits>

namespace mfsi::io {

static_assert(std::is_same_v<hid_t, std::int64_t>, "hid_t is kept as a 64-bit integer (HDF5 >= 1.10)");

namespace {

/// HDF5 prints its own error stack by default; every call here is checked and reported instead.
void quietHdf5() {
  static const bool quiet = [] { return H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr) >= 0; }();
  (void)quiet;
}

[[noreturn]] void fail(const std::string& file, const std::string& what) {
  throw OutputError("cannot " + what + " in '" + file + "' (HDF5)");
}

/// Closes an HDF5 handle when it leaves scope.
struct Handle {
  hid_t id;
  herr_t (*closer)(hid_t);
  Handle(hid_t i, herr_t (*c)(hid_t)) : id(i), closer(c) {}
  ~Handle() {
    if (id >= 0) closer(id);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
};

std::size_t product(const std::vector<std::size_t>& dims) {
  std::size_t n = 1;
  for (std::size_t d : dims) n *= d;
  return n;
}

template <class T>
void writeDataset(hid_t file, const std::string& path, const std::string& dataset, const std::vector<T>& data,
                  const std::vector<std::size_t>& dims, hid_t fileType, hid_t memType) {
  if (product(dims) != data.size() || dims.empty()) {
    std::ostringstream os;
    os << "write dataset '" << dataset << "' (" << data.size() << " values for its shape)";
    fail(path, os.str());
  }
  std::vector<hsize_t> hd(dims.begin(), dims.end());
  Handle space(H5Screate_simple(static_cast<int>(hd.size()), hd.data(), nullptr), H5Sclose);
  Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  if (space.id < 0 || lcpl.id < 0 || H5Pset_create_intermediate_group(lcpl.id, 1) < 0)
    fail(path, "describe dataset '" + dataset + "'");
  Handle dset(H5Dcreate2(file, dataset.c_str(), fileType, space.id, lcpl.id, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  if (dset.id < 0) fail(path, "create dataset '" + dataset + "'");
  if (!data.empty() && H5Dwrite(dset.id, memType, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
    fail(path, "write dataset '" + dataset + "'");
}

}  // namespace

Hdf5File Hdf5File::create(const std::string& path) {
  quietHdf5();
  Hdf5File f;
  f.path_ = path;
  f.writing_ = path + ".part";
  f.file_ = H5Fcreate(f.writing_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (f.file_ < 0) throw OutputError("cannot create '" + f.writing_ + "' (HDF5): is the folder there and writable?");
  return f;
}

Hdf5File Hdf5File::openRead(const std::string& path) {
  quietHdf5();
  Hdf5File f;
  f.path_ = path;
  f.file_ = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f.file_ < 0) throw OutputError("cannot open '" + path + "' as an HDF5 file");
  return f;
}

Hdf5File::Hdf5File(Hdf5File&& o) noexcept : file_(o.file_), path_(std::move(o.path_)), writing_(std::move(o.writing_)) {
  o.file_ = -1;
  o.writing_.clear();
}

Hdf5File& Hdf5File::operator=(Hdf5File&& o) noexcept {
  if (this != &o) {
    close();
    file_ = o.file_;
    path_ = std::move(o.path_);
    writing_ = std::move(o.writing_);
    o.file_ = -1;
    o.writing_.clear();
  }
  return *this;
}

Hdf5File::~Hdf5File() { close(); }

void Hdf5File::close() noexcept {
  if (file_ >= 0) H5Fclose(file_);
  file_ = -1;
  if (!writing_.empty()) {
    std::error_code ec;
    std::filesystem::remove(writing_, ec);  // never committed: leave nothing that looks like a result
    writing_.clear();
  }
}

void Hdf5File::write(const std::string& dataset, const std::vector<double>& data, const std::vector<std::size_t>& dims) {
  writeDataset(file_, writing_, dataset, data, dims, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE);
}

void Hdf5File::write(const std::string& dataset, const std::vector<std::int64_t>& data,
                     const std::vector<std::size_t>& dims) {
  writeDataset(file_, writing_, dataset, data, dims, H5T_STD_I64LE, H5T_NATIVE_INT64);
}

void Hdf5File::writeAttribute(const std::string& name, double value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(file_, name.c_str(), H5T_IEEE_F64LE, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (space.id < 0 || attr.id < 0 || H5Awrite(attr.id, H5T_NATIVE_DOUBLE, &value) < 0)
    fail(writing_, "write attribute '" + name + "'");
}

bool Hdf5File::has(const std::string& dataset) const {
  // H5Lexists fails (rather than answering no) when a group on the way is missing: walk the path.
  std::string sofar;
  std::istringstream parts(dataset);
  for (std::string part; std::getline(parts, part, '/');) {
    if (part.empty()) continue;
    sofar += "/" + part;
    if (H5Lexists(file_, sofar.c_str(), H5P_DEFAULT) <= 0) return false;
  }
  return !sofar.empty();
}

std::int64_t Hdf5File::openDataset(const std::string& dataset, std::vector<std::size_t>* dims) const {
  if (!has(dataset)) throw OutputError("'" + path_ + "' has no dataset '" + dataset + "'");
  const hid_t dset = H5Dopen2(file_, dataset.c_str(), H5P_DEFAULT);
  if (dset < 0) fail(path_, "open dataset '" + dataset + "'");
  Handle space(H5Dget_space(dset), H5Sclose);
  const int rank = space.id >= 0 ? H5Sget_simple_extent_ndims(space.id) : -1;
  if (rank < 0) {
    H5Dclose(dset);
    fail(path_, "read the shape of '" + dataset + "'");
  }
  std::vector<hsize_t> hd(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space.id, hd.data(), nullptr);
  if (dims) dims->assign(hd.begin(), hd.end());
  return dset;
}

namespace {
/// H5Ovisit's callback: collect the paths of datasets (the signature changed in HDF5 1.12).
#if H5_VERSION_GE(1, 12, 0)
herr_t collectDataset(hid_t, const char* name, const H5O_info2_t* info, void* out) {
#else
herr_t collectDataset(hid_t, const char* name, const H5O_info_t* info, void* out) {
#endif
  if (info->type == H5O_TYPE_DATASET) static_cast<std::vector<std::string>*>(out)->push_back(std::string("/") + name);
  return 0;
}
}  // namespace

std::vector<std::string> Hdf5File::datasets() const {
  std::vector<std::string> names;
#if H5_VERSION_GE(1, 12, 0)
  const herr_t ok = H5Ovisit3(file_, H5_INDEX_NAME, H5_ITER_INC, collectDataset, &names, H5O_INFO_BASIC);
#else
  const herr_t ok = H5Ovisit2(file_, H5_INDEX_NAME, H5_ITER_INC, collectDataset, &names, H5O_INFO_BASIC);
#endif
  if (ok < 0) fail(path_, "list the datasets");
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<std::size_t> Hdf5File::shape(const std::string& dataset) const {
  std::vector<std::size_t> dims;
  Handle dset(openDataset(dataset, &dims), H5Dclose);
  return dims;
}

std::vector<double> Hdf5File::readDoubles(const std::string& dataset, std::vector<std::size_t>* dims) const {
  std::vector<std::size_t> shape;
  Handle dset(openDataset(dataset, &shape), H5Dclose);
  std::vector<double> data(product(shape));
  if (!data.empty() && H5Dread(dset.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
    fail(path_, "read dataset '" + dataset + "'");
  if (dims) *dims = shape;
  return data;
}

std::vector<std::int64_t> Hdf5File::readInts(const std::string& dataset, std::vector<std::size_t>* dims) const {
  std::vector<std::size_t> shape;
  Handle dset(openDataset(dataset, &shape), H5Dclose);
  std::vector<std::int64_t> data(product(shape));
  if (!data.empty() && H5Dread(dset.id, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
    fail(path_, "read dataset '" + dataset + "'");
  if (dims) *dims = shape;
  return data;
}

double Hdf5File::readAttribute(const std::string& name) const {
  double v = 0;
  Handle attr(H5Aopen(file_, name.c_str(), H5P_DEFAULT), H5Aclose);
  if (attr.id < 0 || H5Aread(attr.id, H5T_NATIVE_DOUBLE, &v) < 0) fail(path_, "read attribute '" + name + "'");
  return v;
}

void Hdf5File::commit() {
  if (writing_.empty()) throw OutputError("'" + path_ + "' was not opened for writing");
  const bool flushed = H5Fflush(file_, H5F_SCOPE_GLOBAL) >= 0;
  const bool closed = H5Fclose(file_) >= 0;
  file_ = -1;
  if (!flushed || !closed) {
    close();
    throw OutputError("cannot finish writing '" + path_ + "' (HDF5 flush or close failed: is the disk full?)");
  }
  std::error_code ec;
  std::filesystem::rename(writing_, path_, ec);
  if (ec) {
    close();
    throw OutputError("cannot rename '" + writing_ + "' to '" + path_ + "': " + ec.message());
  }
  writing_.clear();
}

}  // namespace mfsi::io
