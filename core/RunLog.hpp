#pragma once
/// \file
/// \brief What every run leaves behind: `summary.json` (the stable machine-readable contract),
/// a per-step CSV log, and a progress display.
#include <cstddef>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace mfsi {

/// \brief Contents of summary.json:
/// {"scene","status","error","wall_s","steps","sim_time","cells","nodes","ranks","threads","backend",
///  "timers":{phase: s},"metrics":{name: number}}.
struct RunSummary {
  std::string scene;
  std::string status = "ok";  ///< "ok" | "diverged" | "error" | "interrupted"
  std::string error;          ///< empty -> null
  double wallSeconds = 0.0;
  long long steps = 0;
  double simTime = 0.0;
  long long cells = 0;
  long long nodes = 0;
  int ranks = 1;
  int threads = 1;
  std::string backend;
  std::map<std::string, double> timers;
  std::map<std::string, double> metrics;
};

/// JSON text of a summary (non-finite numbers are written as null). Always valid UTF-8 JSON,
/// whatever bytes the strings hold (see jsonEscape).
std::string toJson(const RunSummary& s);

/// Write `size` bytes to `path` through a temporary file (`<path>.part`) and a rename, so the file
/// is never half-written: on any failure the temporary file is removed and a file already at
/// `path` stays as it was. Throws OutputError naming `path` and the system's reason (a failed
/// write adds "is the disk full?").
void writeBytesAtomically(const std::string& path, const char* data, std::size_t size);
/// writeBytesAtomically of a text.
void writeTextAtomically(const std::string& path, const std::string& text);

/// Write `dir/summary.json` atomically (temporary file + rename); creates `dir`.
void writeSummary(const std::string& dir, const RunSummary& s);

/// \brief Escape a string for JSON (without the quotes), so that the result is valid UTF-8 JSON
/// whatever the bytes: `"` and `\` are escaped, control characters (U+0000 to U+001F) are written
/// as \n, \r, \t or \u00XX, well-formed UTF-8 is copied as it is, and each byte that is not part
/// of a well-formed UTF-8 sequence (a Latin-1 file name, a cut-off or overlong sequence, an encoded
/// surrogate) becomes \ufffd, the replacement character: a name with such bytes stays readable
/// and never passes for another valid name.
std::string jsonEscape(const std::string& s);

/// \brief Per-step CSV log (`steps.csv`): a header of column names, then one row per step.
/// Keep the header line (which must be `header`) and the first `rows` data lines of a CSV file and
/// drop the rest, atomically (the rows a run wrote after the checkpoint it is restarted from).
/// Throws InputError naming the file when it is missing, has another header or fewer rows.
void keepCsvRows(const std::string& path, const std::string& header, long long rows);

/// \brief A text file appended to in whole records (the rows of `steps.csv`, `bodies.csv`): each
/// `append` is one write, and when one fails the file is cut back to the records before it and
/// takes no more, so a full disk never leaves half a row that looks like data.
class AppendFile {
 public:
  AppendFile() = default;
  /// A new file holding `header` (written atomically: never a cut-off header), open to append.
  static AppendFile create(const std::string& path, const std::string& header);
  /// An existing file, open to append after what it holds. Throws OutputError when it cannot.
  static AppendFile open(const std::string& path);
  AppendFile(AppendFile&& other) noexcept;
  AppendFile& operator=(AppendFile&& other) noexcept;
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;
  ~AppendFile();
  /// Append `text` in one write. Throws OutputError naming the file when the write fails (or an
  /// earlier one did); the file then keeps exactly what it held before.
  void append(const std::string& text);
  bool isOpen() const { return fd_ >= 0; }

 private:
  void close() noexcept;

  std::string path_;
  int fd_ = -1;            ///< the file, opened to append
  long long written_ = 0;  ///< its size: what was written whole
};

class StepLog {
 public:
  StepLog() = default;
  StepLog(const std::string& path, std::vector<std::string> columns);
  /// Continue the log of a run restarted from a checkpoint in the same folder: keep its first
  /// `keepRows` rows (the steps up to the checkpoint), drop the later ones, append from there.
  /// Throws InputError when the file is missing, has other columns or fewer rows.
  StepLog(const std::string& path, std::vector<std::string> columns, long long keepRows);
  /// Append a row in one write (a stopped run keeps every step it finished). Throws OutputError
  /// when the write fails; the file then keeps exactly the whole rows before it (what a failed
  /// write left of the row is cut off) and takes no more.
  void row(const std::vector<double>& values);
  bool isOpen() const { return file_.isOpen(); }

 private:
  AppendFile file_;
  std::size_t nColumns_ = 0;
};

/// \brief One-line progress display (step, simulated time, ETA) on a terminal; plain lines at
/// most every `plainEvery` steps otherwise (0: a tenth of the run; negative: none).
class Progress {
 public:
  Progress(long long totalSteps, double endTime, bool terminal, int plainEvery = 0);
  void update(long long step, double simTime);
  void finish();

 private:
  long long total_;
  double endTime_;
  bool terminal_;
  int plainEvery_;
  double start_;
  bool drew_ = false;
};

/// Whether stdout is a terminal.
bool stdoutIsTerminal();

}  // namespace mfsi
