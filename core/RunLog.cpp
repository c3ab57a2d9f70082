#include "core/RunLog.hpp"

#include "core/Error.hpp"
#include "core/Timers.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>

namespace mfsi {

std::string jsonEscape(const std::string& s) {
  std::ostringstream os;
  for (unsigned char c : s) {
    switch (c) {
      case '"': os << "\\\""; break;
      case '\\': os << "\\\\"; break;
      case '\n': os << "\\n"; break;
      case '\r': os << "\\r"; break;
      case '\t': os << "\\t"; break;
      default:
        if (c < 0x20) {
          os << "\\u" << std::hex << std::setw(4) << std::setfill('0') << static_cast<int>(c) << std::dec;
        } else {
          os << c;
        }
    }
  }
  return os.str();
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

void writeTextAtomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".part";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.flush();
    if (!out) {
      out.close();
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw OutputError("cannot write '" + tmp + "' (is the disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw OutputError("cannot rename '" + tmp + "' to '" + path + "': " + ec.message());
}

void writeSummary(const std::string& dir, const RunSummary& s) {
  std::filesystem::create_directories(dir);
  writeTextAtomically(dir + "/summary.json", toJson(s));
}

StepLog::StepLog(const std::string& path, std::vector<std::string> columns)
    : path_(path), out_(path), nColumns_(columns.size()) {
  if (!out_) throw OutputError("cannot write '" + path + "'");
  for (std::size_t i = 0; i < columns.size(); ++i) out_ << (i ? "," : "") << columns[i];
  out_ << "\n";
  out_.flush();
  if (!out_) throw OutputError("cannot write '" + path + "' (is the disk full?)");
}

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
    : path_(path), nColumns_(columns.size()) {
  std::string header;
  for (std::size_t i = 0; i < columns.size(); ++i) header += (i ? "," : "") + columns[i];
  keepCsvRows(path, header, keepRows);
  out_.open(path, std::ios::app);
  if (!out_) throw OutputError("cannot write '" + path + "'");
}

void StepLog::row(const std::vector<double>& values) {
  MFSI_ASSERT(values.size() == nColumns_, "step log row has " << values.size() << " values for " << nColumns_);
  out_ << std::setprecision(12);
  for (std::size_t i = 0; i < values.size(); ++i) out_ << (i ? "," : "") << values[i];
  out_ << "\n";
  out_.flush();
  if (!out_) throw OutputError("cannot write '" + path_ + "' (is the disk full?)");
}

bool stdoutIsTerminal() { return ::isatty(STDOUT_FILENO) == 1; }

Progress::Progress(long long totalSteps, double endTime, bool terminal, int plainEvery)
    : total_(totalSteps), endTime_(endTime), terminal_(terminal), plainEvery_(plainEvery), start_(wallSeconds()) {
  if (plainEvery_ <= 0) plainEvery_ = static_cast<int>(std::max<long long>(1, totalSteps / 10));
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
  } else if (step % plainEvery_ == 0 || step == total_) {
    std::printf("  step %lld/%lld  t = %.6g  elapsed %.1f s  ETA %.1f s\n", step, total_, simTime, elapsed, eta);
  }
}

void Progress::finish() {
  if (drew_) std::printf("\n");
  std::fflush(stdout);
}

}  // namespace mfsi
