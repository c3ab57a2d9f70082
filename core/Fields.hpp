#pragma once
/// \file
/// \brief Fields on cells, faces and nodes (labelled device Views) and the time state.
#include "core/HexMesh.hpp"

namespace mfsi {

/// \brief Where a field lives.
enum class FieldLocation { Cell, Face, Node };

/// \brief Time state of a run, passed explicitly to every module.
struct TimeState {
  int step = 0;        ///< number of completed steps
  real time = 0.0;     ///< simulated time at the start of the step being computed
  real dt = 0.0;       ///< current step size
  real dtOld = 0.0;    ///< previous step size (BDF2 on variable steps)
  real endTime = 0.0;  ///< scene end time
};

/// Number of entities of `mesh` at `loc`.
lid_t fieldSize(const HexMesh& mesh, FieldLocation loc);

/// Zero-initialised scalar field; `label` must be hierarchical, e.g. "mfsi::fluid::p".
RealView makeScalarField(const HexMesh& mesh, FieldLocation loc, const std::string& label);

/// Zero-initialised 3-vector field.
Real3View makeVectorField(const HexMesh& mesh, FieldLocation loc, const std::string& label);

}  // namespace mfsi
