#pragma once
/// \file
/// \brief Field output for ParaView: each output time is one HDF5 file (`fields/fields_<step>.h5`)
/// holding every grid of the run (the fluid mesh, each membrane, the rigid bodies), and one XDMF
/// file (`fields.xdmf`) lists them as time series, so ParaView opens the whole run as one dataset.
///
/// The modules fill a FieldFrame on the host (positions, cells and fields as plain arrays); the
/// series writes it. A grid's points and cells are written when they change and otherwise referred
/// to where they were written (a fixed mesh: once, in the first frame). Both files of an output time are written under temporary names and renamed,
/// so an interrupted run leaves the frames it finished and an XDMF file that lists exactly those.
#include <mpi.h>

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace mfsi::io {

class Hdf5File;
struct RowPiece;

/// \brief One field on a grid: `components` values per point or per cell, point or cell major.
/// Three components are a vector (ParaView draws glyphs of it) unless `vector` is false (e.g. the
/// in-plane strain E11, E22, E12).
/// A `geometric` field depends on nothing but the grid's points and cells (mesh displacement, cell
/// quality): while those do not change it is not written again.
struct OutputField {
  std::string name;
  int components = 1;
  std::vector<double> values;
  bool vector = true;
  bool geometric = false;
};

/// How a grid's cells are given.
enum class CellShape {
  Hexahedron,  ///< 8 nodes per cell, VTK order
  Surface,     ///< 4 nodes per cell; a triangle has -1 in its fourth slot
  Point        ///< one vertex per point (rigid bodies, probes): no cell list
};

/// \brief A grid of one output time: positions (3 per point), cells, point and cell fields.
///
/// On a decomposed mesh a grid may be one rank's part of a grid every rank holds a part of
/// (`decomposed`, hexahedra only): its points and cells are the rank's rows of the whole grid,
/// `pointRows` and `cellRows` their global rows (each global row on exactly one rank), its cells
/// name global points, and each rank writes its own rows of the frame's file.
struct OutputGrid {
  std::string name;
  CellShape shape = CellShape::Point;
  std::vector<double> points;
  std::vector<std::int64_t> cells;
  std::vector<OutputField> pointFields;
  std::vector<OutputField> cellFields;
  bool decomposed = false;
  std::vector<std::int64_t> pointRows, cellRows;  ///< decomposed: the global row of each point / cell
  std::size_t globalPoints = 0, globalCells = 0;  ///< decomposed: the whole grid's sizes

  std::size_t nPoints() const { return points.size() / 3; }
  std::size_t nCells() const;
  /// Add a field; throws std::logic_error when its size does not match the grid.
  void addPointField(std::string fieldName, int components, std::vector<double> values, bool vector = true,
                     bool geometric = false);
  void addCellField(std::string fieldName, int components, std::vector<double> values, bool vector = true,
                    bool geometric = false);
};

/// \brief Everything written at one output time.
struct FieldFrame {
  double time = 0;
  long long step = 0;
  std::vector<OutputGrid> grids;
  /// The grid of that name, or null.
  OutputGrid* find(const std::string& name);
};

/// \brief The time series of a run: writes frames and keeps the XDMF index in step with them.
class FieldSeries {
 public:
  /// Frames go to `<runDir>/fields/`, the index to `<runDir>/fields.xdmf`. With a communicator
  /// of several ranks, write() is collective over it: rank 0 lays each frame's file out and
  /// writes the grids of its own frame that are not decomposed (the others' are ignored), every
  /// rank writes its rows of the decomposed ones, and rank 0 writes the index.
  explicit FieldSeries(std::string runDir, MPI_Comm comm = MPI_COMM_NULL);
  /// Write one frame and rewrite the index. Throws OutputError when anything cannot be written
  /// (the frames written before stay listed and readable), on every rank of a collective write.
  void write(const FieldFrame& frame);
  int frames() const { return static_cast<int>(entries_.size()); }
  const std::string& indexPath() const { return indexPath_; }
  /// The HDF5 file of frame `i` (0-based, in writing order).
  std::string framePath(int i) const;
  /// The index of the frames written so far, for a checkpoint: a run restarted in the same folder
  /// lists them and its own (its first frame writes every grid's points and cells again).
  std::string state() const;
  /// Take over the frames of `state()` that are not later than `step` (a restarted run rewrites
  /// the later ones). Throws InputError when the text is not such an index.
  void restore(const std::string& state, long long step);

 private:
  struct GridEntry {
    std::string name;
    CellShape shape;
    std::size_t nPoints, nCells;
    std::string topologyType, topologyDims;  ///< XDMF's TopologyType and the dataset's Dimensions
    /// The frame file that holds each dataset ("points", "topology", "point/U", ...): this frame's,
    /// or an earlier one's for what did not change.
    std::map<std::string, std::string> files;
    std::vector<OutputField> pointFields, cellFields;  ///< names and components (no values)
  };
  struct Entry {
    double time;
    std::string file;  ///< relative to the run folder
    std::vector<GridEntry> grids;
    long long step = 0;
  };
  std::string xdmf() const;
  struct Written;
  /// Whether this rank's grid `g` has the points and the topology written last (not yet: false).
  std::pair<bool, bool> unchanged(const OutputGrid& g, const std::vector<std::int64_t>& topology) const;
  /// One grid into frame `entry`: its datasets written into `h5` (a whole grid), or (decomposed)
  /// reserved there and this rank's rows listed in `pieces` (h5 null on ranks other than 0).
  /// Unchanged points and topology are referred to where they were written: `agreed` (the ranks'
  /// verdict on a decomposed grid), or null to decide from this rank's grid.
  void putGrid(Hdf5File* h5, const OutputGrid& g, const std::pair<bool, bool>* agreed, Entry& entry,
               std::vector<std::pair<std::string, Written>>& pending, std::vector<RowPiece>& pieces) const;
  void writeShared(const FieldFrame& frame);
  /// After a frame's file is on disk: take its entry into the index and rewrite the index.
  void publish(Entry entry, std::vector<std::pair<std::string, Written>>& pending);
  /// Keep where this frame's grids are (`file`: the frame's own file) for the next frame.
  void remember(std::vector<std::pair<std::string, Written>>& pending, const std::string& file);

  /// The last points and cells written of each grid, and where: a frame whose grid has not moved
  /// (or not changed its cells) refers to them instead of writing them again.
  struct Written {
    std::string pointsFile, topologyFile;
    std::vector<double> points;
    std::vector<std::int64_t> topology;
    std::map<std::string, std::string> geometricFiles;  ///< "point/<name>", "cell/<name>" -> file
  };

  std::string dir_;
  std::string indexPath_;
  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0, ranks_ = 1;
  std::vector<Entry> entries_;
  std::map<std::string, Written> written_;
};

}  // namespace mfsi::io
