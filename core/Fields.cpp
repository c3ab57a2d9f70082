#include "core/Fields.hpp"

namespace mfsi {

lid_t fieldSize(const HexMesh& mesh, FieldLocation loc) {
  switch (loc) {
    case FieldLocation::Cell: return mesh.nCells();
    case FieldLocation::Face: return mesh.nFaces();
    case FieldLocation::Node: return mesh.nNodes();
  }
  return 0;
}

RealView makeScalarField(const HexMesh& mesh, FieldLocation loc, const std::string& label) {
  return RealView(label, fieldSize(mesh, loc));
}

Real3View makeVectorField(const HexMesh& mesh, FieldLocation loc, const std::string& label) {
  return Real3View(label, fieldSize(mesh, loc));
}

}  // namespace mfsi
