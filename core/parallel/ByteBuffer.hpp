#pragma once
/// \file
/// \brief A flat byte buffer for sending set-up data of many shapes in one message (a mesh part,
/// a membrane surface): vectors of trivially copyable values, strings and counts, written and read
/// back in the same order. Host only; both ends are the same build, so no byte-order conversion.
#include "core/Error.hpp"

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

namespace mfsi {

class ByteWriter {
 public:
  void count(std::uint64_t n) { raw(&n, sizeof(n)); }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>, "ByteWriter: trivially copyable values only");
    raw(&v, sizeof(T));
  }
  template <class T>
  void vector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>, "ByteWriter: trivially copyable values only");
    count(v.size());
    raw(v.data(), v.size() * sizeof(T));
  }
  void string(const std::string& s) {
    count(s.size());
    raw(s.data(), s.size());
  }
  std::vector<char>& bytes() { return bytes_; }

 private:
  void raw(const void* p, std::size_t n) {
    const char* c = static_cast<const char*>(p);
    bytes_.insert(bytes_.end(), c, c + n);
  }
  std::vector<char> bytes_;
};

class ByteReader {
 public:
  explicit ByteReader(const std::vector<char>& bytes) : bytes_(bytes) {}
  std::uint64_t count() {
    std::uint64_t n = 0;
    raw(&n, sizeof(n));
    return n;
  }
  template <class T>
  T value() {
    T v;
    raw(&v, sizeof(T));
    return v;
  }
  template <class T>
  void vector(std::vector<T>& v) {
    const std::uint64_t n = count();
    MFSI_CHECK(n <= (bytes_.size() - at_) / (sizeof(T) > 0 ? sizeof(T) : 1), "ByteReader: a vector past the end");
    v.resize(n);
    raw(v.data(), n * sizeof(T));
  }
  std::string string() {
    const std::uint64_t n = count();
    MFSI_CHECK(n <= bytes_.size() - at_, "ByteReader: a string past the end");
    std::string s(bytes_.data() + at_, n);
    at_ += n;
    return s;
  }
  bool done() const { return at_ == bytes_.size(); }

 private:
  void raw(void* p, std::size_t n) {
    MFSI_CHECK(n <= bytes_.size() - at_, "ByteReader: read past the end");
    if (n > 0) std::memcpy(p, bytes_.data() + at_, n);
    at_ += n;
  }
  const std::vector<char>& bytes_;
  std::size_t at_ = 0;
};

}  // namespace mfsi
