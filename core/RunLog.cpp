#include "core/RunLog.hpp"

#include "core/Error.hpp"
#include "core/Timers.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace mfsi {

namespace {

/// The length of the well-formed UTF-8 sequence that starts at `s[i]` (Unicode 15, table 3-7:
/// no overlong forms, no surrogates, nothing above U+10FFFF), 0 when none does.
std::size_t utf8Sequence(const std::string& s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char lead = byte(i);
  if (lead < 0x80) return 1;
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // the range of the second byte
  if (lead >= 0xC2 && lead <= 0xDF) {
    n = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    n = 3;
    if (lead == 0xE0) lo = 0xA0;
    if (lead == 0xED) hi = 0x9F;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    n = 4;
    if (lead == 0xF0) lo = 0x90;
    if (lead == 0xF4) hi = 0x8F;
  } else {
    return 0;
  }
  if (i + n > s.size() || byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k)
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  return n;
}

}  // namespace

std::string jsonEscape(const std::string& s) {
  static const char* const hex = "0123456789abcdef";
  std::string o;
  o.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      case '\r': o += "\\r"; break;
      case '\t': o += "\\t"; break;
      default:
        if (c < 0x20) {
          o += "\\u00";
          o += hex[c >> 4];
          o += hex[c & 0xF];
        } else if (const std::size_t n = utf8Sequence(s, i); n > 0) {
          o.append(s, i, n);
          i += n;
          continue;
        } else {
          o += "\\ufffd";
        }
    }
    ++i;
  }
  return o;
}

namespace {
std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  std::ostringstream os;
  os << std::setprecision(17) << v;
  return os.str();
}
std::string str(const std::string& s) { return "\"" + jsonEscape(s) + "\""; }
std::string object(const std::map<std::string, double>& m) {
  std::string o = "{";
  bool first = true;
  for (const auto& [k, v] : m) {
    o += (first ? "\n    " : ",\n    ") + str(k) + ": " + num(v);
    first = false;
  }
  return o + (first ? "}" : "\n  }");
}
}  // namespace

std::string toJson(const RunSummary& s) {
  std::ostringstream os;
  os << "{\n"
     << "  \"scene\": " << str(s.scene) << ",\n"
     << "  \"status\": " << str(s.status) << ",\n"
     << "  \"error\": " << (s.error.empty() ? std::string("null") : str(s.error)) << ",\n"
     << "  \"wall_s\": " << num(s.wallSeconds) << ",\n"
     << "  \"steps\": " << s.steps << ",\n"
     << "  \"sim_time\": " << num(s.simTime) << ",\n"
     << "  \"cells\": " << s.cells << ",\n"
     << "  \"nodes\": " << s.nodes << ",\n"
     << "  \"ranks\": " << s.ranks << ",\n"
     << "  \"threads\": " << s.threads << ",\n"
     << "  \"backend\": " << str(s.backend) << ",\n"
     << "  \"timers\": " << object(s.timers) << ",\n"
     << "  \"metrics\": " << object(s.metrics) << "\n"
     << "}\n";
  return os.str();
}

namespace {

/// Write all of `data` to `fd` (a short write is continued; a write the system refuses ends it).
/// False, with errno set, when it fails. Large data goes in pieces of 1 MiB: one write() of a
/// 130 MB checkpoint took 0.3-0.5 s against 0.02-0.07 s in pieces (Linux 6.18, ext4, a VM).
bool writeAll(int fd, const char* data, std::size_t size) {
  constexpr std::size_t kPiece = std::size_t(1) << 20;
  while (size > 0) {
    const ssize_t n = ::write(fd, data, std::min(size, kPiece));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = EIO;
      return false;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

std::string writeFailure(const std::string& path, int err) {
  return "cannot write '" + path + "': " + std::strerror(err) + " (is the disk full?)";
}

}  // namespace

void writeBytesAtomically(const std::string& path, const char* data, std::size_t size) {
  const std::string tmp = path + ".part";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw OutputError("cannot create '" + tmp + "': " + std::strerror(errno) + " (is the folder there and writable?)");
  const bool written = writeAll(fd, data, size);
  int err = written ? 0 : errno;
  if (::close(fd) != 0 && err == 0) err = errno;  // a deferred write error (NFS, quota) shows here
  std::error_code ec;
  if (err != 0) {
    std::filesystem::remove(tmp, ec);
    throw OutputError(writeFailure(path, err));
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw OutputError("cannot rename '" + tmp + "' to '" + path + "': " + ec.message());
  }
}

void writeTextAtomically(const std::string& path, const std::string& text) {
  writeBytesAtomically(path, text.data(), text.size());
}

void writeSummary(const std::string& dir, const RunSummary& s) {
  std::filesystem::create_directories(dir);
  writeTextAtomically(dir + "/summary.json", toJson(s));
}

namespace {
std::string csvHeader(const std::vector<std::string>& columns) {
  std::string header;
  for (std::size_t i = 0; i < columns.size(); ++i) header += (i ? "," : "") + columns[i];
  return header;
}
}  // namespace

AppendFile AppendFile::create(const std::string& path, const std::string& header) {
  writeTextAtomically(path, header);
  return open(path);
}

AppendFile AppendFile::open(const std::string& path) {
  AppendFile f;
  f.path_ = path;
  f.fd_ = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  struct stat st {};
  if (f.fd_ < 0 || ::fstat(f.fd_, &st) != 0) {
    const int err = errno;
    f.close();
    throw OutputError("cannot open '" + path + "' to append: " + std::strerror(err));
  }
  f.written_ = static_cast<long long>(st.st_size);
  return f;
}

AppendFile::AppendFile(AppendFile&& o) noexcept : path_(std::move(o.path_)), fd_(o.fd_), written_(o.written_) {
  o.fd_ = -1;
}

AppendFile& AppendFile::operator=(AppendFile&& o) noexcept {
  if (this != &o) {
    close();
    path_ = std::move(o.path_);
    fd_ = o.fd_;
    written_ = o.written_;
    o.fd_ = -1;
  }
  return *this;
}

AppendFile::~AppendFile() { close(); }

void AppendFile::close() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void AppendFile::append(const std::string& text) {
  if (fd_ < 0) throw OutputError("cannot write '" + path_ + "': an earlier write failed");
  if (writeAll(fd_, text.data(), text.size())) {
    written_ += static_cast<long long>(text.size());
    return;
  }
  // Keep whole records: cut off what the failed write left of this one (shrinking a file needs no
  // space), and take no more.
  const int err = errno;
  const bool cut = ::ftruncate(fd_, static_cast<off_t>(written_)) == 0;
  close();
  throw OutputError(writeFailure(path_, err) + (cut ? "" : "; its last row may be cut short"));
}

StepLog::StepLog(const std::string& path, std::vector<std::string> columns)
    : file_(AppendFile::create(path, csvHeader(columns) + "\n")), nColumns_(columns.size()) {}

void keepCsvRows(const std::string& path, const std::string& header, long long rows) {
  std::ifstream in(path);
  if (!in) throw InputError("restart: '" + path + "' is missing: the run to continue did not write it");
  std::string line, kept;
  if (!std::getline(in, line) || line != header)
    throw InputError("restart: '" + path + "' has other columns than this run writes (another scene?)");
  kept = line + "\n";
  long long n = 0;
  while (n < rows && std::getline(in, line)) {
    kept += line + "\n";
    ++n;
  }
  if (n < rows)
    throw InputError("restart: '" + path + "' has " + std::to_string(n) + " rows, the checkpoint needs " +
                     std::to_string(rows));
  writeTextAtomically(path, kept);
}

StepLog::StepLog(const std::string& path, std::vector<std::string> columns, long long keepRows)
    : nColumns_(columns.size()) {
  keepCsvRows(path, csvHeader(columns), keepRows);
  file_ = AppendFile::open(path);
}

void StepLog::row(const std::vector<double>& values) {
  MFSI_ASSERT(values.size() == nColumns_, "step log row has " << values.size() << " values for " << nColumns_);
  std::ostringstream line;
  line << std::setprecision(12);
  for (std::size_t i = 0; i < values.size(); ++i) line << (i ? "," : "") << values[i];
  line << "\n";
  file_.append(line.str());
}

bool stdoutIsTerminal() { return ::isatty(STDOUT_FILENO) == 1; }

Progress::Progress(long long totalSteps, double endTime, bool terminal, int plainEvery)
    : total_(totalSteps), endTime_(endTime), terminal_(terminal), plainEvery_(plainEvery), start_(wallSeconds()) {
  if (plainEvery_ == 0) plainEvery_ = static_cast<int>(std::max<long long>(1, totalSteps / 10));
}

void Progress::update(long long step, double simTime) {
  const double elapsed = wallSeconds() - start_;
  double frac = total_ > 0 ? double(step) / double(total_) : 0.0;
  if (endTime_ > 0) frac = std::max(frac, simTime / endTime_);
  const double eta = frac > 0 ? elapsed * (1.0 - frac) / frac : 0.0;
  if (terminal_) {
    std::printf("\r  step %lld/%lld  t = %.6g  elapsed %.1f s  ETA %.1f s   ", step, total_, simTime, elapsed, eta);
    std::fflush(stdout);
    drew_ = true;
  } else if (plainEvery_ > 0 && (step % plainEvery_ == 0 || step == total_)) {
    std::printf("  step %lld/%lld  t = %.6g  elapsed %.1f s  ETA %.1f s\n", step, total_, simTime, elapsed, eta);
  }
}

void Progress::finish() {
  if (drew_) std::printf("\n");
  std::fflush(stdout);
}

}  // namespace mfsi
