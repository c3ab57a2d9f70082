#pragma once
/// \file
/// \brief Symmetric lattice storage of a 7-point (5-point on a one-cell-thick block) matrix: the
/// diagonal and the three (two) upper couplings per row, for the SpMV of conjugate gradients.
///
/// Why: CG's product q = A p streams A's values from memory every iteration (the pressure
/// matrix does not stay in cache between two products: the V-cycle in between evicts it). A
/// CSR row of a 7-point matrix holds 7 doubles (56 B; host sweeps over row runs read no column
/// index); a symmetric lattice matrix is fully described by its diagonal and the couplings to
/// the +x, +y and +z neighbours (32 B per row): the lower coupling a_{i,i-s} of row i is the
/// upper one a_{i-s,i} of row i - s, stored at u_s(i - s). The host kernel reads the four arrays
/// contiguously (as it reads p at i, i -+ 1, i -+ nx, i -+ nx ny) and vectorises; device backends
/// run a plain per-row kernel. Couplings that leave the lattice (x = nx - 1 for u_x, ...) are
/// stored as 0, so the kernel needs no lattice coordinates: only rows whose neighbours i -+ nx ny
/// leave [0, n) (the first and last planes) take the branching path.
///
/// The products are those of the CSR kernels to rounding (each row sums its seven terms in
/// column order, as blas::spmv; missing neighbours add +-0): bitwise equal in practice on
/// builds without FMA contraction. The p.q sum of `spmvDot` is deterministic (see blas::reduce)
/// but in a different order than blas::spmvDot's (lanes, see blas::detail::reduceHostBlocks).
///
/// Distributed memory (not built): each rank would hold its owned block as a lattice
/// (nx x ny x nz rows) and the couplings to ghost cells on the block faces in separate face
/// arrays (one per face, indexed by the face's lattice position), multiplied against the ghost
/// entries [nRows, nCols) of p after `updateGhosts`. The lower couplings across a face are the
/// neighbour rank's upper ones, so each rank stores its own copy of the face couplings (the
/// values of its CSR ghost columns) rather than fetching them.
#include "kernels/Blas.hpp"

namespace mfsi {

/// \brief Diagonal + upper couplings of a symmetric lattice matrix, refreshed from a CSR matrix.
///
/// Usage: `update(exec, A)` after each change of A's values (one device kernel; the lattice is
/// detected on the host once per sparsity), then `matches(A)` tells whether the copy holds A
/// (same rowPtr and values allocations, symmetric lattice) and `spmvDot` multiplies with it.
/// The copy keeps shallow references to A's rowPtr, colIdx and values views, so a matrix freed
/// and re-allocated at the same address is never mistaken for the old one. Values refilled in
/// place after `update` are not seen until the next `update`.
class SymmetricLatticeMatrix {
 public:
  /// \brief Refresh from A's current values. Returns whether A is a symmetric lattice matrix
  /// (sparsity accepted by `detectLattice` - 7-point, or 5-point one cell thick, numbered x
  /// fastest - and a_ij == a_ji exactly); if not, the copy is invalid and `matches` is false.
  bool update(const ExecSpace& exec, const CsrMatrix& A);

  /// \brief Whether the copy was made by the last `update` from this matrix's views (rowPtr,
  /// colIdx, values) and A is a symmetric lattice matrix, or was assembled for A (`markAssembled`).
  bool matches(const CsrMatrix& A) const;

  /// \brief Direct assembly, for a caller that forms A's values itself (symmetric by
  /// construction, e.g. one coefficient per face): `prepare(A)` detects A's lattice (once per
  /// sparsity, as `update`) without reading A's values and returns whether it is one; the caller
  /// then writes `diagonal()` and the upper couplings (0 where a coupling leaves the lattice) and
  /// calls `markAssembled(A)`. A's CSR values are not written: they stay stale until
  /// `writeCsr(exec, A)` fills them from the lattice (for CSR consumers such as a multigrid
  /// set-up). No symmetry check is made: the caller guarantees it. Saves `update`'s copy pass and
  /// the assembly's CSR writes (32 instead of 56 B per row).
  bool prepare(const CsrMatrix& A);
  void markAssembled(const CsrMatrix& A);
  /// \brief Whether the lattice holds A's values by `markAssembled` (so A's CSR values may be stale).
  bool assembledFor(const CsrMatrix& A) const { return assembled_ && matches(A); }
  /// \brief A's CSR values from the lattice (both halves of each coupling).
  void writeCsr(const ExecSpace& exec, const CsrMatrix& A) const;
  /// \brief The arrays `prepare` allocated (nRows entries each; upperZ empty when nz = 1).
  RealView diagonal() const { return diag_; }
  RealView upperX() const { return ux_; }
  RealView upperY() const { return uy_; }
  RealView upperZ() const { return uz_; }

  /// \brief Whether the last `update` produced a usable copy.
  bool valid() const { return valid_; }

  /// \brief Lattice extents of the sparsity seen last (nz = 1: one cell thick); 0 if none.
  lid_t nx() const { return nx_; }
  lid_t ny() const { return ny_; }
  lid_t nz() const { return nz_; }

  /// \brief y = A x on rows [0, n) and returns the global w.y (deterministic; see the file
  /// comment). x and w have n entries; y must not alias x.
  double spmvDot(const ExecSpace& exec, const SolverComm& comm, const ConstRealView& x, const RealView& y,
                 const ConstRealView& w) const;

  /// \brief y = A x on rows [0, n).
  void spmv(const ExecSpace& exec, const ConstRealView& x, const RealView& y) const;

  /// \brief r = b - A x with the global sums of `blas::scaledResidualTerms` (OpenFOAM's scaled
  /// residual about xbar; row sums of A from the copy). Row products and row sums in CSR column
  /// order: the numbers of the CSR pass over the same matrix.
  std::array<double, 4> scaledResidual(const ExecSpace& exec, const SolverComm& comm, const ConstRealView& x,
                                       const ConstRealView& b, double xbar, const RealView& r) const;

  /// \brief Drop the copy and the references to the last matrix.
  void clear();

 private:
  /// Whether A has the sparsity views the lattice was detected for.
  bool holdsSparsityOf(const CsrMatrix& A) const;
  // Sparsity the lattice was detected for (held: their addresses identify it).
  IndexView rowPtr_, colIdx_;
  lid_t nRows_ = 0, nnz_ = 0;
  lid_t nx_ = 0, ny_ = 0, nz_ = 0;
  bool lattice_ = false;
  // Values the copy was made from (held, as above).
  RealView values_;
  bool valid_ = false;
  bool assembled_ = false;  ///< values written by a caller (markAssembled), not copied by update
  RealView diag_, ux_, uy_, uz_;  ///< uz_ empty when nz = 1
};

}  // namespace mfsi
