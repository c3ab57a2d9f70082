#pragma once
/// \file
/// \brief Three levels of checking:
///  - `MFSI_CHECK(cond, msg)`: always on; throws `mfsi::InputError` for user errors (bad scene,
///    bad mesh). Messages name file, line and key where known.
///  - `MFSI_ASSERT(cond, msg)`: debug builds only; programmer errors, with rank and location.
///  - inside kernels: `KOKKOS_ASSERT` / `Kokkos::abort`.
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>

namespace mfsi {

/// \brief Where in an input something sits: file, line and column are 1-based; 0 means unknown.
struct SourceLocation {
  std::string file;
  int line = 0;
  int column = 0;
  std::string key;  ///< dotted key path, e.g. "fluid.viscosity"

  std::string str() const {
    std::ostringstream os;
    os << (file.empty() ? "<input>" : file);
    if (line > 0) os << ":" << line;
    if (column > 0) os << ":" << column;
    if (!key.empty()) os << ": key '" << key << "'";
    return os.str();
  }
};

/// \brief A user error: bad scene, bad mesh file, bad value. Always carries a readable message.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& msg) : std::runtime_error(msg) {}
  InputError(const SourceLocation& where, const std::string& msg)
      : std::runtime_error(where.str() + ": " + msg), where_(where) {}
  const SourceLocation& where() const { return where_; }

 private:
  SourceLocation where_;
};

/// \brief The simulation left its stable range (NaN, blow-up, no convergence).
class DivergenceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// \brief A result could not be saved (a failed write, a full disk, an unreadable results file): the
/// run stops rather than report work it could not keep.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace detail {
[[noreturn]] void assertFail(const char* cond, const char* file, int line, const std::string& msg);
}  // namespace detail

}  // namespace mfsi

#define MFSI_CHECK(cond, msg)                   \
  do {                                          \
    if (!(cond)) {                              \
      std::ostringstream mfsi_check_os_;        \
      mfsi_check_os_ << msg;                    \
      throw ::mfsi::InputError(mfsi_check_os_.str()); \
    }                                           \
  } while (0)

#define MFSI_CHECK_AT(cond, where, msg)         \
  do {                                          \
    if (!(cond)) {                              \
      std::ostringstream mfsi_check_os_;        \
      mfsi_check_os_ << msg;                    \
      throw ::mfsi::InputError((where), mfsi_check_os_.str()); \
    }                                           \
  } while (0)

#ifdef NDEBUG
#define MFSI_ASSERT(cond, msg) \
  do {                         \
  } while (0)
#else
#define MFSI_ASSERT(cond, msg)                                                 \
  do {                                                                         \
    if (!(cond)) {                                                             \
      std::ostringstream mfsi_assert_os_;                                      \
      mfsi_assert_os_ << msg;                                                  \
      ::mfsi::detail::assertFail(#cond, __FILE__, __LINE__, mfsi_assert_os_.str()); \
    }                                                                          \
  } while (0)
#endif
