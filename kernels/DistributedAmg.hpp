#pragma once
/// \file
/// \brief Smoothed-aggregation AMG across MPI ranks, for the pressure Poisson equation of a
/// decomposed mesh (rows: owned cells; columns: owned cells, then ghosts).
///
/// Method (as kernels/Amg.hpp, distributed the way ML/MueLu's "uncoupled" aggregation is):
///  - aggregation is decoupled: each rank aggregates its own rows, so no aggregate crosses a rank
///    boundary. On a structured lattice (the global ids number one block x fastest, every row holds
///    its diagonal and exactly its in-range 7- or 5-point lattice neighbours, every coupling strong;
///    checked on every rank) into lattice-aligned cubes as kernels/Amg: 2x2x2 on the finest level,
///    3x3x3 below (squares on one cell thick lattices), each cube's part on a rank one aggregate, so
///    the cubes a partition cuts become smaller aggregates; otherwise greedily (three phases) over
///    the owned-owned strong couplings;
///  - the prolongator is smoothed, P = (I - omega D^{-1} A) P_tent, omega = damping / lambda_max;
///    its rows reach across rank boundaries (a ghost neighbour's aggregate is a ghost column), so
///    the coarse operators keep the coupling between ranks: A_c = R (A P) with R = P^T, rows of P
///    and of A P sent to the ranks that hold them as ghosts (core/parallel/RowExchange);
///  - each level has its own halo (the coarse ghosts a rank's rows and prolongator touch);
///  - a coarse level with fewer than `agglomerateRows` rows per rank moves onto fewer ranks (each
///    run of consecutive ranks gathers onto its first; the cycle gathers its right-hand side there
///    and scatters its correction back), so small levels are not spread thin over many ranks;
///  - once a level has at most `coarseSize` rows over all ranks (or cannot coarsen further) it is
///    solved directly: by the one rank that holds it, or else gathered onto every rank and solved
///    there, the same on every rank (so deterministic); by a dense pseudo-inverse up to
///    `denseCoarseRows` rows, above that by one V-cycle of a one-process DistributedAmg of it;
///  - symmetric V-cycle with fourth-kind Chebyshev smoothing in D^{-1} A (lambda_max from power
///    iterations, boosted by 1.1), every product after a halo exchange; every sum in a fixed order;
///    in float by default (`mixedPrecision`), set-up in double.
/// One rank is the same algorithm with no communication (the reference the distributed
/// iteration counts are compared with). The serial kernels/Amg.hpp remains the one-rank solver of
/// the fluid (lattice-patterned storage); this one keeps CSR with row runs.
/// Measured (perf/distributed_amg.sh, 64^3 Laplacian, CG to 1e-8, one rank): greedy aggregation
/// 13 iterations (kernels/Amg with greedy aggregates: 13 too), lattice cubes 9 (kernels/Amg: 9).
#include "core/parallel/LocalMesh.hpp"
#include "kernels/Preconditioner.hpp"

#include <mpi.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace mfsi {

struct DistributedAmgOptions {
  double strengthThreshold = 0.08;  ///< finest level; 0 below
  double prolongationDamping = 1.45;  ///< omega lambda_max of the prolongator smoothing (kernels/Amg's)
  int chebyshevDegree = 2;          ///< of the fourth-kind Chebyshev smoother
  std::int64_t coarseSize = 300;    ///< rows over all ranks at or below which a level is solved directly
  /// A gathered coarsest level with more rows than this (decoupled aggregation cannot go below
  /// about one row per rank, so on many ranks it stays large) is solved by one V-cycle of a
  /// one-process AMG built on the gathered matrix, the same on every rank, instead of a dense
  /// pseudo-inverse whose set-up grows with its cube.
  std::int64_t denseCoarseRows = 500;
  /// A coarse level with fewer rows than this per rank that may hold rows moves onto fewer ranks,
  /// about this many rows each (the rows of consecutive ranks onto the first of them): the levels
  /// below it are built and cycled on those ranks only, so the many-rank exchanges of small levels
  /// become a gather and a scatter within each group, and a coarsest level on one rank is solved
  /// there without a gather. 0: never (every rank keeps its rows down to the coarsest level).
  std::int64_t agglomerateRows = 800;
  int maxLevels = 16;
  /// Lattice-aligned cubes where the fine matrix is a structured lattice (false: greedy always).
  bool latticeAggregation = true;
  /// The V-cycle in float (rounded copies of every level's operator, P, R and inverse diagonal;
  /// float vectors and halo exchanges; the coarsest solve in double), as kernels/Amg's Mixed: about
  /// a third fewer bytes per cycle; set-up computes in double either way. false: double throughout.
  bool mixedPrecision = true;
  /// Each halo exchange of the cycle runs while the product that needs it multiplies the rows that
  /// read no ghost (Halo::begin/end, CsrGhostSplit); false: exchange, then multiply. The same
  /// results bit for bit.
  bool overlapExchange = true;
};

/// \brief One level: rows over all ranks, nonzeros over all ranks, and this rank's rows and ghosts.
struct DistributedAmgLevelInfo {
  std::int64_t rows = 0;
  std::int64_t nonzeros = 0;
  lid_t ownedRows = 0;
  lid_t ghosts = 0;
  bool lattice = false;  ///< aggregated into lattice cubes (false: greedily, or the coarsest level)
  int ranks = 0;         ///< ranks that hold rows of the level
};

class DistributedAmg final : public Preconditioner {
 public:
  /// \param comm the ranks (MPI_COMM_NULL or a one-rank communicator: no communication)
  /// \param plan the halo of the matrix's columns (its ghosts, as core/parallel/LocalMesh)
  /// \param globalIds global ids of the matrix's columns (owned, then ghosts)
  DistributedAmg(MPI_Comm comm, const HaloPlan& plan, std::vector<gid_t> globalIds,
                 const DistributedAmgOptions& options = {});
  ~DistributedAmg() override;

  void setup(const ExecSpace& exec, const CsrMatrix& A) override;
  void apply(const ExecSpace& exec, const ConstRealView& r, const RealView& z) override;
  std::string name() const override { return "distributed-amg"; }
  /// \brief The coarsest level's gathers (one MPI_Allgatherv per V-cycle on several ranks) made
  /// by every DistributedAmg of this process so far: a latency count of the scaling model (perf/).
  static std::int64_t coarseGathers();

  const std::vector<DistributedAmgLevelInfo>& levels() const;
  /// \brief Bytes this rank's hierarchy holds (device views and host arrays; a view two of its
  /// parts share counted once; the halos' buffers not counted). After set-up it holds what the
  /// cycle uses: the operators, prolongators, restrictions, inverse diagonals and work vectors in
  /// the cycle's precision, the coarsest level's solve, and the copy of the fine matrix's
  /// sparsity (its values in a float cycle are a rounded copy).
  std::size_t memoryBytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mfsi
