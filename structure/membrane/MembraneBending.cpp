#include "structure/membrane/MembraneBending.hpp"

#include "core/Error.hpp"

#include <cmath>
#include <map>
#include <utility>

namespace mfsi {

namespace {

using Point = std::array<real, 3>;

real triangleArea(const Point& a, const Point& b, const Point& c) {
  const real u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const real v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const real n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

real distance2(const Point& a, const Point& b) {
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

// Calibration on a square grid of spacing a, small deflection w = (k11 x^2 + 2 k12 x y + k22 y^2) / 2.
// The hinge angle of two linear interpolants is the jump of their slope across the edge.
//  - Edge x = 0, wings (a, y) and (-a, y) at the same y (either end of the edge): the angle is
//    a k11 whatever k12. Two hinges, |e|^2 / (A1 + A2) = 1, factor 1/4: D a^2 k11^2 / 2 per edge
//    (the edge y = 0 likewise with k22).
//  - Each diagonal: theta = sqrt(2) a k12, |d|^2 / A = 2, factor 1/8: D a^2 k12^2 / 2 each.
// Per cell (one edge of each direction, two diagonals): D a^2 (k11^2 + k22^2 + 2 k12^2) / 2.
// Wings paired across the edge (rather than all four pairings, which also see the twist) keep the
// twist on the diagonals, which every cell has, rim cells included: the energy a rim cell lacks is
// then only the bending across the rim, which a simply supported rim does not carry.
constexpr real kEdgeFactor = 1.0 / 4.0;
constexpr real kDiagonalFactor = 1.0 / 8.0;

/// The node of quad q next to node a that is not b.
lid_t wingNextTo(const std::array<lid_t, 4>& q, lid_t a, lid_t b) {
  for (int i = 0; i < 4; ++i)
    if (q[i] == a) return q[(i + 1) % 4] != b ? q[(i + 1) % 4] : q[(i + 3) % 4];
  return -1;
}

}  // namespace

MembraneHinges buildMembraneHinges(const MembraneMesh& mesh, real bendingStiffness) {
  MFSI_CHECK(std::isfinite(bendingStiffness) && bendingStiffness > 0,
             "membrane bending: the bending stiffness must be > 0, got " << bendingStiffness);
  MFSI_CHECK(mesh.nTriangles() == 0, "membrane bending (material.bending: plate) needs a quad membrane mesh; this one "
                                         "has "
                                             << mesh.nTriangles() << " triangles");
  const auto& P = mesh.hostPoints();
  const auto& elems = mesh.hostElements();
  std::vector<std::array<lid_t, 4>> nodes;
  std::vector<real> k;
  auto add = [&](std::array<lid_t, 4> h, real stiffness) {
    nodes.push_back(h);
    k.push_back(stiffness);
  };
  // Interior edges: (min node, max node) -> the (element, local edge) pairs that hold it.
  std::map<std::pair<lid_t, lid_t>, std::vector<std::pair<lid_t, int>>> edges;
  for (lid_t e = 0; e < static_cast<lid_t>(elems.size()); ++e)
    for (int i = 0; i < 4; ++i) {
      const lid_t a = elems[e][i], b = elems[e][(i + 1) % 4];
      edges[{std::min(a, b), std::max(a, b)}].push_back({e, i});
    }
  for (const auto& [key, owners] : edges) {
    if (owners.size() != 2) continue;  // a rim (or a non-manifold edge): no hinge
    const auto [e1, i1] = owners[0];
    const auto [e2, i2] = owners[1];
    const lid_t a = elems[e1][i1], b = elems[e1][(i1 + 1) % 4];
    // Each end of the edge pairs the two wings next to it, one in each quad.
    const real le2 = distance2(P[a], P[b]);
    for (const auto& [end, other] : {std::pair<lid_t, lid_t>{a, b}, std::pair<lid_t, lid_t>{b, a}}) {
      const lid_t p = wingNextTo(elems[e1], end, other), q = wingNextTo(elems[e2], end, other);
      const real area = triangleArea(P[a], P[b], P[p]) + triangleArea(P[a], P[b], P[q]);
      MFSI_CHECK(area > 0, "membrane bending: degenerate elements at the edge " << a << "-" << b);
      add({a, b, p, q}, kEdgeFactor * bendingStiffness * le2 / area);
    }
  }
  for (const auto& q : elems) {
    const real area = triangleArea(P[q[0]], P[q[1]], P[q[2]]) + triangleArea(P[q[0]], P[q[2]], P[q[3]]);
    add({q[0], q[2], q[3], q[1]}, kDiagonalFactor * bendingStiffness * distance2(P[q[0]], P[q[2]]) / area);
    add({q[1], q[3], q[0], q[2]}, kDiagonalFactor * bendingStiffness * distance2(P[q[1]], P[q[3]]) / area);
  }

  const lid_t n = static_cast<lid_t>(k.size());
  MembraneHinges h;
  h.nodes = Kokkos::View<lid_t* [4], MemSpace>("mfsi::structure::membrane::hingeNodes", n);
  auto hn = Kokkos::create_mirror_view(h.nodes);
  std::vector<real> rest(n);
  for (lid_t i = 0; i < n; ++i) {
    real x[4][3], g[4][3];
    for (int a = 0; a < 4; ++a) {
      hn(i, a) = nodes[i][a];
      for (int c = 0; c < 3; ++c) x[a][c] = P[nodes[i][a]][c];
    }
    MFSI_CHECK(membrane::hingeAngle(x, rest[i], g), "membrane bending: degenerate hinge at nodes "
                                                        << nodes[i][0] << "-" << nodes[i][1]);
  }
  Kokkos::deep_copy(h.nodes, hn);
  h.stiffness = toDevice(k, "mfsi::structure::membrane::hingeStiffness");
  h.restAngle = toDevice(rest, "mfsi::structure::membrane::hingeRestAngle");
  h.hostNodes = std::move(nodes);
  return h;
}

namespace {

/// The hinge's current points, its angle change and gradient; false when degenerate.
struct HingeState {
  real dtheta = 0;
  real grad[4][3];
};

KOKKOS_INLINE_FUNCTION bool hingeState(const Kokkos::View<lid_t* [4], MemSpace>& nodes, const ConstRealView& rest,
                                       const ConstReal3View& X, const ConstRealView& u, lid_t h, HingeState& s) {
  real x[4][3];
  for (int a = 0; a < 4; ++a) {
    const lid_t n = nodes(h, a);
    for (int c = 0; c < 3; ++c) x[a][c] = X(n, c) + u(3 * n + c);
  }
  real theta = 0;
  const bool ok = membrane::hingeAngle(x, theta, s.grad);
  s.dtheta = ok ? membrane::hingeAngleChange(theta, rest(h)) : 0;
  return ok;
}

}  // namespace

void membraneHingeResidualItems(const ExecSpace& exec, const MembraneHinges& hinges, const ConstReal3View& X,
                                const ConstRealView& u, lid_t firstItem, const ItemValuesView& residual,
                                const ItemValuesView& external) {
  const auto nodes = hinges.nodes;
  const ConstRealView rest = hinges.restAngle, k = hinges.stiffness;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::hingeResidual", RangePolicy(exec, 0, hinges.size()), KOKKOS_LAMBDA(lid_t h) {
        HingeState s;
        hingeState(nodes, rest, X, u, h, s);
        const real f = -2 * k(h) * s.dtheta;
        for (int a = 0; a < 4; ++a)
          for (int c = 0; c < 3; ++c) {
            residual(firstItem + h, 3 * a + c) = f * s.grad[a][c];
            external(firstItem + h, 3 * a + c) = 0;
          }
      });
}

void membraneHingeTangentItems(const ExecSpace& exec, const MembraneHinges& hinges, const ConstReal3View& X,
                               const ConstRealView& u, lid_t firstItem, bool rowSums, const ItemValuesView& out) {
  const auto nodes = hinges.nodes;
  const ConstRealView rest = hinges.restAngle, k = hinges.stiffness;
  Kokkos::parallel_for(
      "mfsi::structure::membrane::hingeTangent", RangePolicy(exec, 0, hinges.size()), KOKKOS_LAMBDA(lid_t h) {
        HingeState s;
        hingeState(nodes, rest, X, u, h, s);
        const real* g = &s.grad[0][0];
        const real c = 2 * k(h);
        for (int i = 0; i < 12; ++i) {
          if (rowSums) {
            real sum = 0;
            for (int j = 0; j < 12; ++j) sum += kmath::fabs(c * g[i] * g[j]);
            out(firstItem + h, i) = sum;
          } else {
            for (int j = 0; j < 12; ++j) out(firstItem + h, 12 * i + j) = c * g[i] * g[j];
          }
        }
      });
}

real membraneBendingEnergy(const ExecSpace& exec, const MembraneHinges& hinges, const ConstReal3View& X,
                           const ConstRealView& u) {
  const auto nodes = hinges.nodes;
  const ConstRealView rest = hinges.restAngle, k = hinges.stiffness;
  real energy = 0;
  Kokkos::parallel_reduce(
      "mfsi::structure::membrane::bendingEnergy", RangePolicy(exec, 0, hinges.size()),
      KOKKOS_LAMBDA(lid_t h, real & sum) {
        HingeState s;
        hingeState(nodes, rest, X, u, h, s);
        sum += k(h) * s.dtheta * s.dtheta;
      },
      energy);
  return energy;
}

}  // namespace mfsi
