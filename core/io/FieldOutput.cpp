#include "core/io/FieldOutput.hpp"

#include "core/Error.hpp"
#include "core/RunLog.hpp"
#include "core/io/Hdf5File.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <system_error>

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

FieldSeries::FieldSeries(std::string runDir) : dir_(std::move(runDir)), indexPath_(dir_ + "/fields.xdmf") {}

std::string FieldSeries::framePath(int i) const { return dir_ + "/" + entries_.at(static_cast<std::size_t>(i)).file; }

void FieldSeries::write(const FieldFrame& frame) {
  std::error_code ec;
  fs::create_directories(dir_ + "/fields", ec);
  if (ec) throw OutputError("cannot create '" + dir_ + "/fields': " + ec.message());
  char name[64];
  std::snprintf(name, sizeof name, "fields/fields_%06lld.h5", frame.step);
  Entry entry{frame.time, name, {}, frame.step};

  Hdf5File h5 = Hdf5File::create(dir_ + "/" + entry.file);
  h5.writeAttribute("time", frame.time);
  h5.writeAttribute("step", static_cast<double>(frame.step));
  std::vector<std::pair<std::string, Written>> pending;
  for (const OutputGrid& g : frame.grids) {
    Topology topo = topologyOf(g);
    const std::string root = "/" + g.name;
    const auto known = written_.find(g.name);
    Written next;  // where this grid's points, cells and geometric fields are once this frame is on disk
    std::string topologyDims;
    for (std::size_t d : topo.dims) topologyDims += (topologyDims.empty() ? "" : " ") + std::to_string(d);
    GridEntry ge{g.name, g.shape, g.nPoints(), g.nCells(), topo.type, topologyDims, {}, {}, {}};
    const bool samePoints = known != written_.end() && known->second.points == g.points;
    const bool sameCells = known != written_.end() && known->second.topology == topo.values;
    if (samePoints) {
      next.pointsFile = known->second.pointsFile;
    } else {
      h5.write(root + "/points", g.points, {g.nPoints(), 3});
      next.pointsFile = entry.file;
      next.points = g.points;
    }
    if (sameCells) {
      next.topologyFile = known->second.topologyFile;
    } else {
      h5.write(root + "/topology", topo.values, topo.dims);
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
          h5.write(root + "/" + key, f.values, shapeOf(n, f));
          ge.files[key] = entry.file;
        }
        if (f.geometric) next.geometricFiles[key] = ge.files[key];
        into.push_back({f.name, f.components, {}, f.vector, f.geometric});
      }
    };
    fields(g.pointFields, "point", g.nPoints(), ge.pointFields);
    fields(g.cellFields, "cell", g.nCells(), ge.cellFields);
    pending.emplace_back(g.name, std::move(next));
    entry.grids.push_back(std::move(ge));
  }
  h5.commit();
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
  const std::string& file = entries_.back().file;
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
