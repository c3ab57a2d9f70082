#include "core/io/Checkpoint.hpp"

#include <sstream>

namespace mfsi::io {

namespace {
std::string shapeText(const std::vector<std::size_t>& dims) {
  std::ostringstream os;
  for (std::size_t i = 0; i < dims.size(); ++i) os << (i ? " x " : "") << dims[i];
  return os.str();
}
}  // namespace

void StateWriter::put(const std::string& name, const std::vector<double>& values) {
  write(name, values, {values.size()});
}

void StateWriter::put(const std::string& name, const std::vector<std::int64_t>& values) {
  write(name, values, {values.size()});
}

void StateWriter::putText(const std::string& name, const std::string& text) {
  std::vector<std::int64_t> bytes;
  bytes.reserve(text.size());
  for (unsigned char c : text) bytes.push_back(c);
  put(name, bytes);
}

void StateWriter::write(const std::string& name, const std::vector<double>& v, const std::vector<std::size_t>& dims) {
  file_->write(group_ + "/" + name, v, dims);
}

void StateWriter::write(const std::string& name, const std::vector<std::int64_t>& v,
                        const std::vector<std::size_t>& dims) {
  file_->write(group_ + "/" + name, v, dims);
}

void StateWriter::tag(const std::string& name, Entity rows) {
  file_->write(entityTagPath(group_ + "/" + name), std::vector<std::int64_t>{static_cast<std::int64_t>(rows)}, {1});
}

bool StateReader::has(const std::string& name) const { return file_->has(group_ + "/" + name); }

std::vector<std::size_t> StateReader::shape(const std::string& name) const {
  if (!has(name)) throw InputError(where(name) + ": missing (a checkpoint of another scene or version?)");
  return file_->shape(group_ + "/" + name);
}

std::string StateReader::where(const std::string& name) const {
  return "checkpoint '" + file_->path() + "', '" + group_ + "/" + name + "'";
}

std::vector<double> StateReader::doubles(const std::string& name, long long expected) const {
  if (!has(name)) throw InputError(where(name) + ": missing (a checkpoint of another scene or version?)");
  auto v = file_->readDoubles(group_ + "/" + name);
  if (expected >= 0 && static_cast<long long>(v.size()) != expected)
    throw InputError(where(name) + ": " + std::to_string(v.size()) + " values, the run has " +
                     std::to_string(expected) + " (a checkpoint of another scene?)");
  return v;
}

std::vector<std::int64_t> StateReader::ints(const std::string& name, long long expected) const {
  if (!has(name)) throw InputError(where(name) + ": missing (a checkpoint of another scene or version?)");
  auto v = file_->readInts(group_ + "/" + name);
  if (expected >= 0 && static_cast<long long>(v.size()) != expected)
    throw InputError(where(name) + ": " + std::to_string(v.size()) + " values, the run has " +
                     std::to_string(expected) + " (a checkpoint of another scene?)");
  return v;
}

std::string StateReader::text(const std::string& name) const {
  std::string s;
  for (std::int64_t b : ints(name)) s.push_back(static_cast<char>(static_cast<unsigned char>(b)));
  return s;
}

template <class T>
std::vector<T> StateReader::read(const std::string& name, const std::vector<std::size_t>& dims) const {
  if (!has(name)) throw InputError(where(name) + ": missing (a checkpoint of another scene or version?)");
  std::vector<std::size_t> stored;
  std::vector<T> v;
  if constexpr (std::is_same_v<T, double>)
    v = file_->readDoubles(group_ + "/" + name, &stored);
  else
    v = file_->readInts(group_ + "/" + name, &stored);
  if (stored != dims)
    throw InputError(where(name) + ": shape " + shapeText(stored) + ", the run has " + shapeText(dims) +
                     " (a checkpoint of another mesh or scene?)");
  return v;
}

template std::vector<double> StateReader::read<double>(const std::string&, const std::vector<std::size_t>&) const;
template std::vector<std::int64_t> StateReader::read<std::int64_t>(const std::string&,
                                                                   const std::vector<std::size_t>&) const;

}  // namespace mfsi::io
