#include "core/io/Hdf5File.hpp"

#include "core/Error.hpp"
#include "core/RunLog.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <memory>
#include <sstream>
#include <system_error>
#include <type_traits>

namespace mfsi::io {

static_assert(std::is_same_v<hid_t, std::int64_t>, "hid_t is kept as a 64-bit integer (HDF5 >= 1.10)");

namespace {

// A file being written is an image in memory (HDF5's core driver without a backing store), which
// commit() writes to disk itself. The memory comes through HDF5's file image callbacks: anonymous
// mappings, which may use transparent huge pages, grown in place where they can be; when the file
// is closed by commit(), its image is handed over to be written instead of freed. (Growing an image
// of tens of MB in 4 KiB pages costs more than writing it: a page fault each, slow in a virtual
// machine, 0.65 s against 0.03 s for 40 MB; in huge pages a frame or a checkpoint costs about what
// writing it through HDF5's default driver did.) The first page of a mapping holds its size.

/// The image grows by at least this much at a time.
constexpr std::size_t kCoreIncrement = std::size_t(1) << 20;
constexpr std::size_t kPage = 4096;
constexpr std::size_t kHugePage = std::size_t(2) << 20;

std::size_t roundToHugePages(std::size_t bytes) { return (bytes + kHugePage - 1) / kHugePage * kHugePage; }
char* mappingOf(void* image) { return static_cast<char*>(image) - kPage; }
std::size_t mappedBytes(void* image) { return *reinterpret_cast<std::size_t*>(mappingOf(image)); }

void* placeImage(void* mapping, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
  ::madvise(mapping, bytes, MADV_HUGEPAGE);  // a hint: without huge pages, the same in small ones
#endif
  *static_cast<std::size_t*>(mapping) = bytes;
  return static_cast<char*>(mapping) + kPage;
}

/// Memory for an image of at least `size` bytes; null when there is none.
void* mapImage(std::size_t size) {
  const std::size_t bytes = roundToHugePages(size + kPage);
  void* mapping = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  return mapping == MAP_FAILED ? nullptr : placeImage(mapping, bytes);
}

void unmapImage(void* image) {
  if (image != nullptr) ::munmap(mappingOf(image), mappedBytes(image));
}

void* imageMalloc(std::size_t size, H5FD_file_image_op_t, void*) { return mapImage(size); }

void* imageRealloc(void* image, std::size_t size, H5FD_file_image_op_t, void*) {
  if (image == nullptr) return mapImage(size);
  const std::size_t have = mappedBytes(image);
  if (size + kPage <= have) return image;
  const std::size_t want = roundToHugePages(std::max(size + kPage, have + have / 2));
  void* mapping = ::mremap(mappingOf(image), have, want, MREMAP_MAYMOVE);
  return mapping == MAP_FAILED ? nullptr : placeImage(mapping, want);
}

/// Where commit() takes the image of the file it closes (null: the image is freed).
thread_local void** committedImage = nullptr;

herr_t imageFree(void* image, H5FD_file_image_op_t op, void*) {
  if (committedImage != nullptr && op == H5FD_FILE_IMAGE_OP_FILE_CLOSE) {
    *committedImage = image;
    committedImage = nullptr;
  } else {
    unmapImage(image);
  }
  return 0;
}

/// A closed file's image, unmapped when it goes.
using ClosedImage = std::unique_ptr<void, void (*)(void*)>;

/// Close `file` (set to -1) and take its image in memory; `closed` says whether HDF5 closed it.
ClosedImage closeToImage(std::int64_t& file, bool& closed) {
  void* image = nullptr;
  committedImage = &image;
  closed = H5Fclose(file) >= 0;
  committedImage = nullptr;
  file = -1;
  return ClosedImage(image, unmapImage);
}

void* imageCopy(void* to, const void* from, std::size_t size, H5FD_file_image_op_t, void*) {
  return std::memcpy(to, from, size);
}

/// A shared file's metadata block (createShared): a frame's groups and dataset headers take a few KiB.
constexpr std::size_t kSharedMetadataBlock = std::size_t(64) << 10;

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

Hdf5File Hdf5File::create(const std::string& path) { return createInMemory(path, 0); }

Hdf5File Hdf5File::createShared(const std::string& path) { return createInMemory(path, kSharedMetadataBlock); }

Hdf5File Hdf5File::createInMemory(const std::string& path, std::size_t metadataBlock) {
  quietHdf5();
  Hdf5File f;
  f.path_ = path;
  f.writing_ = path + ".part";
  // The temporary file is there from the start (a folder that is missing or not writable fails
  // here, not once the file is built), empty until commit() writes the file into it.
  const int fd = ::open(f.writing_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw OutputError("cannot create '" + f.writing_ + "': " + std::strerror(errno) +
                      " (is the folder there and writable?)");
  ::close(fd);
  // Built in memory (the core driver without a backing store, in the mappings above), then
  // written out by commit(): a write that fails (a full disk) fails in our own checked write, never
  // inside HDF5, which after a failed write in 1.10 cannot close the file (H5Fclose fails and
  // leaves it half closed) and crashes when the library shuts down, in MPI_Finalize.
  H5FD_file_image_callbacks_t memory{};
  memory.image_malloc = imageMalloc;
  memory.image_memcpy = imageCopy;
  memory.image_realloc = imageRealloc;
  memory.image_free = imageFree;
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (fapl.id < 0 || H5Pset_fapl_core(fapl.id, kCoreIncrement, 0) < 0 ||
      H5Pset_file_image_callbacks(fapl.id, &memory) < 0 ||
      (metadataBlock > 0 && H5Pset_meta_block_size(fapl.id, metadataBlock) < 0))
    throw OutputError("cannot create '" + path + "' (HDF5: the in-memory file driver)");
  f.file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.id);
  if (f.file_ < 0) throw OutputError("cannot create '" + path + "' (HDF5)");
  return f;
}

Hdf5File Hdf5File::scratch(const std::string& name) {
  quietHdf5();
  Hdf5File f;
  f.path_ = name;
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (fapl.id < 0 || H5Pset_fapl_core(fapl.id, kCoreIncrement, 0) < 0)
    throw OutputError("cannot create '" + name + "' in memory (HDF5: the in-memory file driver)");
  f.file_ = H5Fcreate(name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.id);
  if (f.file_ < 0) throw OutputError("cannot create '" + name + "' in memory (HDF5)");
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

Hdf5File::Hdf5File(Hdf5File&& o) noexcept
    : file_(o.file_), path_(std::move(o.path_)), writing_(std::move(o.writing_)), reserved_(std::move(o.reserved_)) {
  o.file_ = -1;
  o.writing_.clear();
}

Hdf5File& Hdf5File::operator=(Hdf5File&& o) noexcept {
  if (this != &o) {
    close();
    file_ = o.file_;
    path_ = std::move(o.path_);
    writing_ = std::move(o.writing_);
    reserved_ = std::move(o.reserved_);
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
  writeDataset(file_, path_, dataset, data, dims, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE);  // messages name the file
}

void Hdf5File::write(const std::string& dataset, const std::vector<std::int64_t>& data,
                     const std::vector<std::size_t>& dims) {
  writeDataset(file_, path_, dataset, data, dims, H5T_STD_I64LE, H5T_NATIVE_INT64);
}

void Hdf5File::reserve(const std::string& dataset, const std::vector<std::size_t>& dims, bool integers) {
  const std::string& where = path_;
  if (dims.empty() || product(dims) == 0) fail(where, "reserve dataset '" + dataset + "' (no values)");
  std::vector<hsize_t> hd(dims.begin(), dims.end());
  Handle space(H5Screate_simple(static_cast<int>(hd.size()), hd.data(), nullptr), H5Sclose);
  Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  // Contiguous (the default layout), allocated now (so it has its offset), never filled: its
  // writers write every byte of it.
  if (space.id < 0 || lcpl.id < 0 || dcpl.id < 0 || H5Pset_create_intermediate_group(lcpl.id, 1) < 0 ||
      H5Pset_alloc_time(dcpl.id, H5D_ALLOC_TIME_EARLY) < 0 || H5Pset_fill_time(dcpl.id, H5D_FILL_TIME_NEVER) < 0)
    fail(where, "describe dataset '" + dataset + "'");
  Handle dset(H5Dcreate2(file_, dataset.c_str(), integers ? H5T_STD_I64LE : H5T_IEEE_F64LE, space.id, lcpl.id,
                         dcpl.id, H5P_DEFAULT),
              H5Dclose);
  if (dset.id < 0) fail(where, "create dataset '" + dataset + "'");
  reserved_.push_back(dataset);
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

bool Hdf5File::holdsIntegers(const std::string& dataset) const {
  Handle dset(openDataset(dataset, nullptr), H5Dclose);
  Handle type(H5Dget_type(dset.id), H5Tclose);
  if (type.id < 0) fail(path_, "read the type of dataset '" + dataset + "'");
  return H5Tget_class(type.id) == H5T_INTEGER;
}

double Hdf5File::readAttribute(const std::string& name) const {
  double v = 0;
  Handle attr(H5Aopen(file_, name.c_str(), H5P_DEFAULT), H5Aclose);
  if (attr.id < 0 || H5Aread(attr.id, H5T_NATIVE_DOUBLE, &v) < 0) fail(path_, "read attribute '" + name + "'");
  return v;
}

void Hdf5File::commit() {
  if (writing_.empty()) throw OutputError("'" + path_ + "' was not opened for writing");
  // The file's length (its end of allocation), then its image as HDF5 closed it, handed over by
  // imageFree: the file on disk is those bytes. (They equal the copy H5Fget_file_image makes, as
  // compared over every frame and checkpoint of the test suite when this was written.) Nothing here
  // writes to disk, so nothing fails for a full disk before writeBytesAtomically, which checks.
  const ssize_t size = H5Fflush(file_, H5F_SCOPE_GLOBAL) >= 0 ? H5Fget_file_image(file_, nullptr, 0) : -1;
  bool closed = false;
  const ClosedImage owned = closeToImage(file_, closed);
  void* image = owned.get();
  if (!closed || size <= 0 || image == nullptr) {
    close();
    throw OutputError("cannot finish writing '" + path_ + "' (HDF5: the file's image in memory)");
  }
  writing_.clear();  // writeBytesAtomically removes the temporary file when it fails
  writeBytesAtomically(path_, static_cast<const char*>(image), static_cast<std::size_t>(size));
}

namespace {
/// The end of the file as its superblock records it (where HDF5's reader expects the file's last
/// byte): version 0 and 1 superblocks hold it 40 and 44 bytes in, versions 2 and 3 at 28.
std::uint64_t recordedEnd(const unsigned char* image, std::size_t size) {
  static const unsigned char kSignature[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
  if (size < 48 || std::memcmp(image, kSignature, 8) != 0) return 0;
  const unsigned version = image[8];
  std::size_t at = 0;
  if (version == 0 || version == 1) {
    if (image[13] != 8) return 0;  // 8-byte addresses
    at = version == 0 ? 40 : 44;
  } else if (version == 2 || version == 3) {
    if (image[9] != 8) return 0;
    at = 28;
  } else {
    return 0;
  }
  std::uint64_t end = 0;
  for (int b = 7; b >= 0; --b) end = (end << 8) | image[at + static_cast<std::size_t>(b)];  // little endian
  return end;
}
}  // namespace

std::vector<ReservedDataset> Hdf5File::commitLayout() {
  if (writing_.empty()) throw OutputError("'" + path_ + "' was not opened for writing");
  std::vector<ReservedDataset> layout;
  for (const std::string& name : reserved_) {
    Handle dset(H5Dopen2(file_, name.c_str(), H5P_DEFAULT), H5Dclose);
    const haddr_t offset = dset.id >= 0 ? H5Dget_offset(dset.id) : HADDR_UNDEF;
    if (offset == HADDR_UNDEF) {
      close();
      fail(path_, "find the place of dataset '" + name + "'");
    }
    layout.push_back({name, static_cast<std::uint64_t>(offset), static_cast<std::uint64_t>(H5Dget_storage_size(dset.id))});
  }
  // Closed without a flush first: a flush would zero the whole length of the file in memory,
  // reserved values and all; closing writes the metadata alone into the image.
  bool closed = false;
  const ClosedImage owned = closeToImage(file_, closed);
  void* image = owned.get();
  const std::size_t held = image ? mappedBytes(image) - kPage : 0;  // bytes beyond are zero
  const std::uint64_t end = image ? recordedEnd(static_cast<const unsigned char*>(image), held) : 0;
  if (!closed || image == nullptr || end == 0) {
    close();
    throw OutputError("cannot finish writing '" + path_ + "' (HDF5: the file's image in memory)");
  }
  std::vector<ReservedDataset> byOffset = layout;
  std::sort(byOffset.begin(), byOffset.end(),
            [](const ReservedDataset& a, const ReservedDataset& b) { return a.offset < b.offset; });
  std::uint64_t length = end;
  for (const auto& r : byOffset) length = std::max(length, r.offset + r.bytes);
  // The image's bytes between the reserved datasets; what lies beyond the image is zeros (a hole).
  // The file ends where its last byte outside the reserved datasets does (the reserved bytes'
  // writers extend it over theirs).
  std::uint64_t tail = 0, at = 0;
  for (const auto& r : byOffset) {
    if (r.offset > at) tail = r.offset;
    at = std::max(at, r.offset + r.bytes);
  }
  if (length > at) tail = length;
  const int fd = ::open(writing_.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  int err = fd < 0 ? errno : 0;
  if (err == 0 && ::ftruncate(fd, static_cast<off_t>(tail)) != 0) err = errno;
  auto put = [&](std::uint64_t from, std::uint64_t to) {
    to = std::min<std::uint64_t>(to, held);
    const char* bytes = static_cast<const char*>(image);
    while (err == 0 && from < to) {
      const ssize_t n = ::pwrite(fd, bytes + from, static_cast<std::size_t>(std::min<std::uint64_t>(to - from, 1u << 20)),
                                 static_cast<off_t>(from));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) err = n == 0 ? EIO : errno;
      else from += static_cast<std::uint64_t>(n);
    }
  };
  std::uint64_t cursor = 0;
  for (const auto& r : byOffset) {
    put(cursor, r.offset);
    cursor = std::max(cursor, r.offset + r.bytes);
  }
  put(cursor, length);
  if (fd >= 0 && ::close(fd) != 0 && err == 0) err = errno;
  if (err != 0) {
    close();
    throw OutputError("cannot write '" + path_ + "': " + std::strerror(err) + " (is the disk full?)");
  }
  writing_.clear();  // the file's writers rename or remove it
  reserved_.clear();
  return layout;
}

}  // namespace mfsi::io
