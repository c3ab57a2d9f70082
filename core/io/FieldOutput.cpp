#include "core/io/FieldOutput.hpp"

#include "core/Error.hpp"
#include "core/RunLog.hpp"
#include "core/io/Hdf5File.hpp"
#include "core/io/RowWriter.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <type_traits>

namespace mfsi::io {

namespace fs = std::filesystem;

std::size_t OutputGrid::nCells() const {
  switch (shape) {
    case CellShape::Hexahedron: return cells.size() / 8;
    case CellShape::Surface: return cells.size() / 4;
    case CellShape::Point: return nPoints();
  }
  return 0;
}

namespace {

void checkSize(const OutputGrid& g, const std::string& field, int components, std::size_t n, std::size_t size) {
  if (components < 1 || size != n * static_cast<std::size_t>(components))
    throw std::logic_error("output field '" + field + "' of grid '" + g.name + "' has " + std::to_string(size) +
                           " values for " + std::to_string(n) + " x " + std::to_string(components));
}

/// XDMF's topology of a grid: its type, the dataset's values (the HDF5 layout XDMF reads) and shape.
struct Topology {
  std::string type;
  std::vector<std::int64_t> values;
  std::vector<std::size_t> dims;
};

Topology topologyOf(const OutputGrid& g) {
  Topology t;
  const std::size_t n = g.nCells();
  if (g.shape == CellShape::Hexahedron) {
    t.type = "Hexahedron";
    t.values = g.cells;
    t.dims = {n, 8};
    return t;
  }
  if (g.shape == CellShape::Point) {
    t.type = "Polyvertex";
    for (std::size_t i = 0; i < n; ++i) t.values.push_back(static_cast<std::int64_t>(i));
    t.dims = {n};
    return t;
  }
  std::size_t triangles = 0;
  for (std::size_t c = 0; c < n; ++c) triangles += g.cells[4 * c + 3] < 0 ? 1 : 0;
  if (triangles == 0 || triangles == n) {
    const int k = triangles == 0 ? 4 : 3;
    t.type = triangles == 0 ? "Quadrilateral" : "Triangle";
    for (std::size_t c = 0; c < n; ++c)
      for (int a = 0; a < k; ++a) t.values.push_back(g.cells[4 * c + a]);
    t.dims = {n, static_cast<std::size_t>(k)};
    return t;
  }
  // XDMF's mixed list: each cell's type id (4 triangle, 5 quadrilateral) then its nodes.
  t.type = "Mixed";
  for (std::size_t c = 0; c < n; ++c) {
    const bool tri = g.cells[4 * c + 3] < 0;
    t.values.push_back(tri ? 4 : 5);
    for (int a = 0; a < (tri ? 3 : 4); ++a) t.values.push_back(g.cells[4 * c + a]);
  }
  t.dims = {t.values.size()};
  return t;
}

std::string attributeType(const OutputField& f) {
  if (f.components == 1) return "Scalar";
  if (f.components == 3 && f.vector) return "Vector";
  return "Matrix";
}

/// A scalar field is one-dimensional (what XDMF's "n" reads), others n x components.
std::vector<std::size_t> shapeOf(std::size_t n, const OutputField& f) {
  if (f.components == 1) return {n};
  return {n, static_cast<std::size_t>(f.components)};
}

/// Text safe inside an XML attribute or element.
std::string xml(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string number(double v) {
  std::ostringstream os;
  os << std::setprecision(17) << v;
  return os.str();
}

}  // namespace

void OutputGrid::addPointField(std::string fieldName, int components, std::vector<double> values, bool vector,
                               bool geometric) {
  checkSize(*this, fieldName, components, nPoints(), values.size());
  pointFields.push_back({std::move(fieldName), components, std::move(values), vector, geometric});
}

void OutputGrid::addCellField(std::string fieldName, int components, std::vector<double> values, bool vector,
                              bool geometric) {
  checkSize(*this, fieldName, components, nCells(), values.size());
  cellFields.push_back({std::move(fieldName), components, std::move(values), vector, geometric});
}

OutputGrid* FieldFrame::find(const std::string& name) {
  for (auto& g : grids)
    if (g.name == name) return &g;
  return nullptr;
}

FieldSeries::FieldSeries(std::string runDir, MPI_Comm comm)
    : dir_(std::move(runDir)), indexPath_(dir_ + "/fields.xdmf"), comm_(comm) {
  if (comm_ != MPI_COMM_NULL) {
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &ranks_);
  }
}

std::string FieldSeries::framePath(int i) const { return dir_ + "/" + entries_.at(static_cast<std::size_t>(i)).file; }

namespace {
std::string frameFile(long long step) {
  char name[64];
  std::snprintf(name, sizeof name, "fields/fields_%06lld.h5", step);
  return name;
}

/// Rank 0's `text` on every rank of `comm` (collective).
std::string fromRankZero(MPI_Comm comm, const std::string& text) {
  unsigned long long n = text.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, comm);
  std::string out = text;
  out.resize(n);
  MPI_Bcast(out.data(), static_cast<int>(n), MPI_CHAR, 0, comm);
  return out;
}

void makeFieldsFolder(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir + "/fields", ec);
  if (ec) throw OutputError("cannot create '" + dir + "/fields': " + ec.message());
}
}  // namespace

std::pair<bool, bool> FieldSeries::unchanged(const OutputGrid& g, const std::vector<std::int64_t>& topology) const {
  const auto known = written_.find(g.name);
  if (known == written_.end()) return {false, false};
  return {known->second.points == g.points, known->second.topology == topology};
}

void FieldSeries::putGrid(Hdf5File* h5, const OutputGrid& g, const std::pair<bool, bool>* agreed, Entry& entry,
                          std::vector<std::pair<std::string, Written>>& pending, std::vector<RowPiece>& pieces) const {
  if (g.decomposed && g.shape != CellShape::Hexahedron)
    throw std::logic_error("output grid '" + g.name + "': only a hexahedral grid may be decomposed");
  Topology topo = topologyOf(g);
  const std::pair<bool, bool> same = agreed ? *agreed : unchanged(g, topo.values);
  const bool samePoints = same.first, sameCells = same.second;  // (a lambda below reads them)
  const std::size_t nPoints = g.decomposed ? g.globalPoints : g.nPoints();
  const std::size_t nCells = g.decomposed ? g.globalCells : g.nCells();
  if (g.decomposed) topo.dims = {nCells, 8};
  const std::string root = "/" + g.name;
  const auto known = written_.find(g.name);
  Written next;  // where this grid's points, cells and geometric fields are once this frame is on disk
  std::string topologyDims;
  for (std::size_t d : topo.dims) topologyDims += (topologyDims.empty() ? "" : " ") + std::to_string(d);
  GridEntry ge{g.name, g.shape, nPoints, nCells, topo.type, topologyDims, {}, {}, {}};
  // A decomposed grid's datasets are reserved in the file (on the rank that lays it out) and
  // written by every rank, each its own rows; a whole grid's are written here.
  auto put = [&](const std::string& dataset, const auto& values, std::vector<std::size_t> dims, bool pointRows) {
    if (!g.decomposed) {
      h5->write(dataset, values, dims);
      return;
    }
    constexpr bool integers = std::is_same_v<std::decay_t<decltype(values)>, std::vector<std::int64_t>>;
    if (h5) h5->reserve(dataset, dims, integers);
    const std::vector<std::int64_t>& rows = pointRows ? g.pointRows : g.cellRows;
    RowPiece piece;
    piece.width = dims.size() > 1 ? dims[1] : 1;
    piece.rows = rows.data();
    piece.nRows = rows.size();
    piece.values = values.data();
    if (values.size() != rows.size() * piece.width)
      throw std::logic_error("output grid '" + g.name + "': " + dataset + " has " + std::to_string(values.size()) +
                             " values for " + std::to_string(rows.size()) + " rows");
    pieces.push_back(piece);
  };
  if (samePoints) {
    next.pointsFile = known->second.pointsFile;
  } else {
    put(root + "/points", g.points, {nPoints, 3}, true);
    next.pointsFile = entry.file;
    next.points = g.points;
  }
  if (sameCells) {
    next.topologyFile = known->second.topologyFile;
  } else {
    if (g.decomposed)
      put(root + "/topology", g.cells, topo.dims, false);  // the pieces point at the grid's own values
    else
      put(root + "/topology", topo.values, topo.dims, false);
    next.topologyFile = entry.file;
    next.topology = std::move(topo.values);
  }
  ge.files["points"] = next.pointsFile;
  ge.files["topology"] = next.topologyFile;
  auto fields = [&](const std::vector<OutputField>& list, const std::string& group, std::size_t n,
                    std::vector<OutputField>& into) {
    for (const auto& f : list) {
      const std::string key = group + "/" + f.name;
      const std::string* earlier = nullptr;
      if (f.geometric && samePoints && sameCells) {
        const auto it = known->second.geometricFiles.find(key);
        if (it != known->second.geometricFiles.end()) earlier = &it->second;
      }
      if (earlier) {
        ge.files[key] = *earlier;
      } else {
        put(root + "/" + key, f.values, shapeOf(n, f), group == "point");
        ge.files[key] = entry.file;
      }
      if (f.geometric) next.geometricFiles[key] = ge.files[key];
      into.push_back({f.name, f.components, {}, f.vector, f.geometric});
    }
  };
  fields(g.pointFields, "point", nPoints, ge.pointFields);
  fields(g.cellFields, "cell", nCells, ge.cellFields);
  pending.emplace_back(g.name, std::move(next));
  entry.grids.push_back(std::move(ge));
}

void FieldSeries::write(const FieldFrame& frame) {
  if (ranks_ > 1) return writeShared(frame);
  makeFieldsFolder(dir_);
  Entry entry{frame.time, frameFile(frame.step), {}, frame.step};
  Hdf5File h5 = Hdf5File::create(dir_ + "/" + entry.file);
  h5.writeAttribute("time", frame.time);
  h5.writeAttribute("step", static_cast<double>(frame.step));
  std::vector<std::pair<std::string, Written>> pending;
  std::vector<RowPiece> pieces;
  for (const OutputGrid& g : frame.grids) {
    if (g.decomposed) throw std::logic_error("output grid '" + g.name + "' is decomposed on a one-rank series");
    putGrid(&h5, g, nullptr, entry, pending, pieces);
  }
  h5.commit();
  publish(std::move(entry), pending);
}

void FieldSeries::writeShared(const FieldFrame& frame) {
  // The decomposed grids, in the frame's order (the same on every rank); whether each one's
  // points and cells are those already written is decided over all ranks' parts.
  std::vector<const OutputGrid*> parts;
  for (const OutputGrid& g : frame.grids)
    if (g.decomposed) parts.push_back(&g);
  std::vector<int> same(2 * parts.size() + 1);
  same.back() = static_cast<int>(parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const auto [points, cells] = unchanged(*parts[i], parts[i]->cells);  // a hexahedral grid's topology is its cells
    same[2 * i] = points;
    same[2 * i + 1] = cells;
  }
  std::vector<int> low(same.size()), high(same.size());
  MPI_Allreduce(same.data(), low.data(), static_cast<int>(same.size()), MPI_INT, MPI_MIN, comm_);
  MPI_Allreduce(same.data(), high.data(), static_cast<int>(same.size()), MPI_INT, MPI_MAX, comm_);
  if (low.back() != high.back())
    throw std::logic_error("field output: the ranks' frames hold different numbers of decomposed grids");

  Entry entry{frame.time, frameFile(frame.step), {}, frame.step};
  const std::string path = dir_ + "/" + entry.file;
  std::vector<std::pair<std::string, Written>> pending;
  std::vector<RowPiece> pieces;
  // Rank 0 lays the file out (its whole grids written, the decomposed ones reserved); the others
  // list their rows of the same datasets in the same order.
  std::string failure;
  int fault = 0;
  std::vector<ReservedDataset> layout;
  try {
    std::optional<Hdf5File> h5;
    if (rank_ == 0) {
      makeFieldsFolder(dir_);
      h5.emplace(Hdf5File::createShared(path));
      h5->writeAttribute("time", frame.time);
      h5->writeAttribute("step", static_cast<double>(frame.step));
      for (const OutputGrid& g : frame.grids)
        if (!g.decomposed) putGrid(&*h5, g, nullptr, entry, pending, pieces);
    }
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const std::pair<bool, bool> agreed{low[2 * i] != 0, low[2 * i + 1] != 0};
      putGrid(h5 ? &*h5 : nullptr, *parts[i], &agreed, entry, pending, pieces);
    }
    if (h5) layout = h5->commitLayout();
    // The index lists the grids in the frame's order, as on one rank (the whole grids were
    // written first, so that their values lie before the reserved ones).
    std::stable_sort(entry.grids.begin(), entry.grids.end(), [&](const GridEntry& a, const GridEntry& b) {
      auto at = [&](const std::string& name) {
        for (std::size_t i = 0; i < frame.grids.size(); ++i)
          if (frame.grids[i].name == name) return i;
        return frame.grids.size();
      };
      return at(a.name) < at(b.name);
    });
  } catch (const OutputError& e) {
    failure = e.what();
  } catch (const std::exception& e) {  // a fault on one rank stops every rank with it, not a hang
    failure = e.what();
    fault = 1;
  }
  // Rank 0's count of reserved datasets, then every rank's verdict: the failure of the lowest
  // rank that failed, on every rank, a fault (not a write that failed) as a logic_error.
  constexpr std::uint64_t kFailed = ~std::uint64_t(0);
  std::uint64_t laidOut = failure.empty() ? layout.size() : kFailed;
  MPI_Bcast(&laidOut, 1, MPI_UINT64_T, 0, comm_);
  if (failure.empty() && laidOut != kFailed && laidOut != pieces.size()) {
    failure = "field output: rank 0 laid out " + std::to_string(laidOut) + " datasets, rank " +
              std::to_string(rank_) + " has " + std::to_string(pieces.size());
    fault = 1;
  }
  MPI_Allreduce(MPI_IN_PLACE, &fault, 1, MPI_INT, MPI_MAX, comm_);
  const std::string verdict = agreeOnFailure(comm_, failure);
  if (!verdict.empty()) {
    std::error_code ec;
    if (rank_ == 0) fs::remove(path + ".part", ec);  // laid out for rows that will not come
    if (fault) throw std::logic_error(verdict);
    throw OutputError(verdict);
  }
  // Where each reserved dataset lies, from rank 0.
  std::vector<std::uint64_t> offsets(pieces.size());
  for (std::size_t i = 0; i < layout.size(); ++i) offsets[i] = layout[i].offset;
  MPI_Bcast(offsets.data(), static_cast<int>(offsets.size()), MPI_UINT64_T, 0, comm_);
  for (std::size_t i = 0; i < pieces.size(); ++i) pieces[i].offset = offsets[i];
  const std::string part = path + ".part";
  const std::string rows = writeRows(comm_, part, pieces, path);
  // Rank 0 names the file and lists it; the other ranks keep their parts' points and cells.
  std::string published = rows;
  if (rank_ == 0) {
    std::error_code ec;
    if (!published.empty()) {
      fs::remove(part, ec);
    } else {
      fs::rename(part, path, ec);
      if (ec) {
        std::error_code ignored;
        fs::remove(part, ignored);
        published = "cannot rename '" + part + "' to '" + path + "': " + ec.message();
      } else {
        try {
          publish(std::move(entry), pending);
        } catch (const OutputError& e) {
          published = e.what();
        }
      }
    }
  }
  int ok = published.empty() ? 1 : 0;
  MPI_Bcast(&ok, 1, MPI_INT, 0, comm_);
  if (!ok) throw OutputError(rows.empty() ? fromRankZero(comm_, published) : rows);
  if (rank_ != 0) {
    entries_.push_back(Entry{frame.time, entry.file, {}, frame.step});
    remember(pending, entry.file);
  }
}

void FieldSeries::publish(Entry entry, std::vector<std::pair<std::string, Written>>& pending) {
  // The frame counts once the index lists it (a checkpoint lists the frames the index does): when
  // the index cannot be written, its previous version stays, without this frame (whose complete
  // file stays unlisted).
  entries_.push_back(std::move(entry));
  try {
    writeTextAtomically(indexPath_, xdmf());
  } catch (const OutputError&) {
    entries_.pop_back();
    throw;
  }
  remember(pending, entries_.back().file);
}

void FieldSeries::remember(std::vector<std::pair<std::string, Written>>& pending, const std::string& file) {
  for (auto& [name, next] : pending) {
    Written& w = written_[name];
    if (next.pointsFile == file) w.points = std::move(next.points);
    if (next.topologyFile == file) w.topology = std::move(next.topology);
    w.pointsFile = next.pointsFile;
    w.topologyFile = next.topologyFile;
    w.geometricFiles = std::move(next.geometricFiles);
  }
}

// One record per line, fields separated by tabs (names never hold tabs or line breaks):
//   E time step file | G name shape nPoints nCells topologyType topologyDims | F key file |
//   P/C name components vector geometric (no values: the index needs none).
std::string FieldSeries::state() const {
  std::ostringstream os;
  os << std::setprecision(17);
  for (const Entry& e : entries_) {
    os << "E\t" << e.time << "\t" << e.step << "\t" << e.file << "\n";
    for (const GridEntry& g : e.grids) {
      os << "G\t" << g.name << "\t" << static_cast<int>(g.shape) << "\t" << g.nPoints << "\t" << g.nCells << "\t"
         << g.topologyType << "\t" << g.topologyDims << "\n";
      for (const auto& [key, file] : g.files) os << "F\t" << key << "\t" << file << "\n";
      for (const auto& f : g.pointFields)
        os << "P\t" << f.name << "\t" << f.components << "\t" << f.vector << "\t" << f.geometric << "\n";
      for (const auto& f : g.cellFields)
        os << "C\t" << f.name << "\t" << f.components << "\t" << f.vector << "\t" << f.geometric << "\n";
    }
  }
  return os.str();
}

void FieldSeries::restore(const std::string& state, long long step) {
  std::vector<Entry> entries;
  std::istringstream in(state);
  auto bad = [](const std::string& line) {
    return InputError("restart: the checkpoint's list of field frames is damaged at '" + line + "'");
  };
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> t;
    std::istringstream ls(line);
    for (std::string tok; std::getline(ls, tok, '\t');) t.push_back(tok);
    try {
      if (t.size() == 4 && t[0] == "E") {
        entries.push_back(Entry{std::stod(t[1]), t[3], {}, std::stoll(t[2])});
      } else if (t.size() == 7 && t[0] == "G" && !entries.empty()) {
        GridEntry g;
        g.name = t[1];
        g.shape = static_cast<CellShape>(std::stoi(t[2]));
        g.nPoints = std::stoull(t[3]);
        g.nCells = std::stoull(t[4]);
        g.topologyType = t[5];
        g.topologyDims = t[6];
        entries.back().grids.push_back(std::move(g));
      } else if (t.size() == 3 && t[0] == "F" && !entries.empty() && !entries.back().grids.empty()) {
        entries.back().grids.back().files[t[1]] = t[2];
      } else if (t.size() == 5 && (t[0] == "P" || t[0] == "C") && !entries.empty() && !entries.back().grids.empty()) {
        OutputField f;
        f.name = t[1];
        f.components = std::stoi(t[2]);
        f.vector = t[3] == "1";
        f.geometric = t[4] == "1";
        auto& g = entries.back().grids.back();
        (t[0] == "P" ? g.pointFields : g.cellFields).push_back(std::move(f));
      } else {
        throw bad(line);
      }
    } catch (const std::logic_error&) {
      throw bad(line);
    }
  }
  entries_.clear();
  for (auto& e : entries)
    if (e.step <= step) entries_.push_back(std::move(e));
  written_.clear();
}

std::string FieldSeries::xdmf() const {
  // One temporal collection per grid name (ParaView shows each as a block of one dataset).
  std::vector<std::string> names;
  for (const auto& e : entries_)
    for (const auto& g : e.grids)
      if (std::find(names.begin(), names.end(), g.name) == names.end()) names.push_back(g.name);

  std::ostringstream x;
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n";
  for (const auto& gridName : names) {
    x << "    <Grid Name=\"" << xml(gridName) << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (const auto& e : entries_) {
      for (const auto& g : e.grids) {
        if (g.name != gridName) continue;
        auto item = [&](const std::string& path, const std::string& dims, const char* type) {
          const std::string& file = g.files.at(path.substr(1));
          return "<DataItem Dimensions=\"" + dims + "\" NumberType=\"" + type + "\" Precision=\"8\" Format=\"HDF\">" +
                 xml(file + ":/" + g.name + path) + "</DataItem>";
        };
        x << "      <Grid Name=\"" << xml(g.name) << "\" GridType=\"Uniform\">\n"
          << "        <Time Value=\"" << number(e.time) << "\"/>\n"
          << "        <Topology TopologyType=\"" << g.topologyType << "\" NumberOfElements=\"" << g.nCells << "\""
          << (g.shape == CellShape::Point ? " NodesPerElement=\"1\"" : "") << ">\n"
          << "          " << item("/topology", g.topologyDims, "Int") << "\n        </Topology>\n"
          << "        <Geometry GeometryType=\"XYZ\">\n"
          << "          " << item("/points", std::to_string(g.nPoints) + " 3", "Float") << "\n        </Geometry>\n";
        auto attributes = [&](const std::vector<OutputField>& fields, const char* center, const char* group,
                              std::size_t n) {
          for (const auto& f : fields) {
            const std::string dims = std::to_string(n) + (f.components > 1 ? " " + std::to_string(f.components) : "");
            x << "        <Attribute Name=\"" << xml(f.name) << "\" AttributeType=\"" << attributeType(f) << "\" Center=\""
              << center << "\">\n          " << item(std::string("/") + group + "/" + f.name, dims, "Float")
              << "\n        </Attribute>\n";
          }
        };
        attributes(g.pointFields, "Node", "point", g.nPoints);
        attributes(g.cellFields, "Cell", "cell", g.nCells);
        x << "      </Grid>\n";
      }
    }
    x << "    </Grid>\n";
  }
  x << "  </Domain>\n</Xdmf>\n";
  return x.str();
}

}  // namespace mfsi::io
