#include "structure/membrane/MembraneMesh.hpp"

#include "core/Error.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <unordered_map>

namespace mfsi {

namespace {

using Vec3 = std::array<real, 3>;

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
real norm(const Vec3& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

int elementSize(const std::array<lid_t, 4>& e) { return e[3] < 0 ? 3 : 4; }

/// Area vector of a flat or warped element (half the cross product of the diagonals for quads).
Vec3 areaVector(const std::vector<Vec3>& p, const std::array<lid_t, 4>& e) {
  if (elementSize(e) == 3) {
    Vec3 c = cross(sub(p[e[1]], p[e[0]]), sub(p[e[2]], p[e[0]]));
    return {0.5 * c[0], 0.5 * c[1], 0.5 * c[2]};
  }
  Vec3 c = cross(sub(p[e[2]], p[e[0]]), sub(p[e[3]], p[e[1]]));
  return {0.5 * c[0], 0.5 * c[1], 0.5 * c[2]};
}

/// Merge nodes closer than tol (relative to the bounding box) and renumber elements and node
/// sets; used by the block generators to glue blocks.
void mergeCoincidentNodes(MembraneMeshInput& m, real relTol = 1e-9) {
  Vec3 lo = m.points.front(), hi = m.points.front();
  for (const auto& p : m.points)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  const real tol = relTol * std::max(norm(sub(hi, lo)), real(1e-300));
  const real cell = 10 * tol;
  auto key = [&](long long i, long long j, long long k) { return (i * 73856093LL) ^ (j * 19349663LL) ^ (k * 83492791LL); };
  std::unordered_map<long long, std::vector<lid_t>> buckets;
  std::vector<lid_t> newId(m.points.size(), -1);
  std::vector<Vec3> pts;
  for (std::size_t n = 0; n < m.points.size(); ++n) {
    const auto& p = m.points[n];
    const long long ci = std::llround(p[0] / cell), cj = std::llround(p[1] / cell), ck = std::llround(p[2] / cell);
    lid_t found = -1;
    for (long long di = -1; di <= 1 && found < 0; ++di)
      for (long long dj = -1; dj <= 1 && found < 0; ++dj)
        for (long long dk = -1; dk <= 1 && found < 0; ++dk) {
          auto it = buckets.find(key(ci + di, cj + dj, ck + dk));
          if (it == buckets.end()) continue;
          for (lid_t q : it->second)
            if (norm(sub(pts[q], p)) <= tol) {
              found = q;
              break;
            }
        }
    if (found < 0) {
      found = static_cast<lid_t>(pts.size());
      pts.push_back(p);
      buckets[key(ci, cj, ck)].push_back(found);
    }
    newId[n] = found;
  }
  m.points = pts;
  for (auto& e : m.elements)
    for (auto& n : e)
      if (n >= 0) n = newId[n];
  for (auto& [name, nodes] : m.nodeSets) {
    for (auto& n : nodes) n = newId[n];
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  }
}

/// Reverse elements whose normal points to -z (generators build flat meshes in the xy plane).
void orientUp(MembraneMeshInput& m) {
  for (auto& e : m.elements)
    if (areaVector(m.points, e)[2] < 0) {
      if (elementSize(e) == 3)
        std::swap(e[1], e[2]);
      else
        std::swap(e[1], e[3]);
    }
}

/// Append a structured block of quads (or triangles) with node positions pos(i, j),
/// i in [0, ni], j in [0, nj].
template <class Pos>
void addBlock(MembraneMeshInput& m, int ni, int nj, MembraneElementType type, const Pos& pos) {
  const lid_t base = static_cast<lid_t>(m.points.size());
  for (int j = 0; j <= nj; ++j)
    for (int i = 0; i <= ni; ++i) m.points.push_back(pos(i, j));
  auto id = [&](int i, int j) { return base + j * (ni + 1) + i; };
  for (int j = 0; j < nj; ++j)
    for (int i = 0; i < ni; ++i) {
      const lid_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if (type == MembraneElementType::Quad4) {
        m.elements.push_back({a, b, c, d});
      } else {
        // Split along the shorter diagonal (alternating on a regular grid) to avoid slivers.
        const real ac = norm(sub(m.points[c], m.points[a])), bd = norm(sub(m.points[d], m.points[b]));
        const bool useAc = std::abs(ac - bd) < 1e-12 * (ac + bd) ? ((i + j) % 2 == 0) : ac < bd;
        if (useAc) {
          m.elements.push_back({a, b, c, -1});
          m.elements.push_back({a, c, d, -1});
        } else {
          m.elements.push_back({a, b, d, -1});
          m.elements.push_back({b, c, d, -1});
        }
      }
    }
}

}  // namespace

const std::vector<lid_t>& MembraneMesh::nodeSet(const std::string& name) const {
  auto it = nodeSets_.find(name);
  if (it == nodeSets_.end()) {
    std::string known;
    for (const auto& [n, s] : nodeSets_) known += (known.empty() ? "" : ", ") + n;
    MFSI_CHECK(false, source_ << ": no node set '" << name << "' (known: " << known << ")");
  }
  return it->second;
}

lid_t MembraneMesh::nearestNode(const std::array<real, 3>& p) const {
  lid_t best = 0;
  real bestD = -1;
  for (lid_t n = 0; n < nNodes(); ++n) {
    const real d = norm(sub(hostPoints_[n], p));
    if (bestD < 0 || d < bestD) {
      bestD = d;
      best = n;
    }
  }
  return best;
}

MembraneMesh buildMembraneMesh(const MembraneMeshInput& in) {
  const std::string src = in.source.empty() ? std::string("<membrane mesh>") : in.source;
  const lid_t nNodes = static_cast<lid_t>(in.points.size());
  MFSI_CHECK(nNodes > 0 && !in.elements.empty(), src << ": membrane mesh has no nodes or no elements");
  MembraneMesh mesh;
  mesh.source_ = src;
  mesh.hostPoints_ = in.points;
  mesh.hostElements_ = in.elements;

  // Element checks and areas.
  mesh.elementAreas_.resize(in.elements.size());
  std::vector<Vec3> normals(nNodes, Vec3{0, 0, 0});
  Vec3 centroid{0, 0, 0};
  for (std::size_t e = 0; e < in.elements.size(); ++e) {
    const auto& el = in.elements[e];
    const int nv = elementSize(el);
    for (int a = 0; a < nv; ++a) {
      MFSI_CHECK(el[a] >= 0 && el[a] < nNodes, src << ": element " << e << " refers to node " << el[a] << " of "
                                                   << nNodes);
      for (int b = 0; b < a; ++b) MFSI_CHECK(el[a] != el[b], src << ": element " << e << " repeats node " << el[a]);
    }
    if (nv == 4) ++mesh.nQuads_;
    const Vec3 s = areaVector(in.points, el);
    const real area = norm(s);
    // Degenerate: area tiny against the squared longest edge.
    real h2 = 0;
    for (int a = 0; a < nv; ++a) {
      const real l = norm(sub(in.points[el[(a + 1) % nv]], in.points[el[a]]));
      h2 = std::max(h2, l * l);
    }
    MFSI_CHECK(area > 1e-12 * h2 && h2 > 0, src << ": element " << e << " is degenerate (area " << area << ")");
    mesh.elementAreas_[e] = area;
    mesh.referenceArea_ += area;
    Vec3 c{0, 0, 0};
    for (int a = 0; a < nv; ++a) {
      for (int k = 0; k < 3; ++k) {
        normals[el[a]][k] += s[k];
        c[k] += in.points[el[a]][k] / nv;
      }
    }
    for (int k = 0; k < 3; ++k) centroid[k] += c[k] * area;
  }
  for (int k = 0; k < 3; ++k) centroid[k] /= mesh.referenceArea_;

  // Edges: a directed edge may appear once; the same undirected edge at most twice, opposite.
  std::map<std::pair<lid_t, lid_t>, lid_t> directed;
  for (std::size_t e = 0; e < in.elements.size(); ++e) {
    const auto& el = in.elements[e];
    const int nv = elementSize(el);
    for (int a = 0; a < nv; ++a) {
      const auto key = std::make_pair(el[a], el[(a + 1) % nv]);
      auto [it, inserted] = directed.emplace(key, static_cast<lid_t>(e));
      MFSI_CHECK(inserted, src << ": elements " << it->second << " and " << e << " share edge " << key.first << "-"
                               << key.second << " in the same direction (inconsistent orientation or a "
                               << "non-manifold edge)");
    }
  }
  std::map<lid_t, lid_t> nextOnBoundary;
  for (const auto& [edge, e] : directed)
    if (!directed.count({edge.second, edge.first})) {
      MFSI_CHECK(!nextOnBoundary.count(edge.first),
                 src << ": boundary node " << edge.first << " starts two boundary edges (pinched boundary)");
      nextOnBoundary[edge.first] = edge.second;
    }
  for (const auto& [a, b] : nextOnBoundary) mesh.boundaryNodes_.push_back(a);
  std::sort(mesh.boundaryNodes_.begin(), mesh.boundaryNodes_.end());
  std::map<lid_t, bool> visited;
  for (lid_t start : mesh.boundaryNodes_) {
    if (visited[start]) continue;
    std::vector<lid_t> loop;
    lid_t n = start;
    while (!visited[n]) {
      visited[n] = true;
      loop.push_back(n);
      auto it = nextOnBoundary.find(n);
      MFSI_CHECK(it != nextOnBoundary.end(), src << ": open boundary chain at node " << n);
      n = it->second;
    }
    mesh.boundaryLoops_.push_back(loop);
  }

  mesh.hostNormals_.resize(nNodes);
  for (lid_t n = 0; n < nNodes; ++n) {
    const real l = norm(normals[n]);
    MFSI_CHECK(l > 0, src << ": node " << n << " belongs to no element");
    for (int k = 0; k < 3; ++k) mesh.hostNormals_[n][k] = normals[n][k] / l;
  }
  mesh.nodeSets_ = in.nodeSets;
  for (const auto& [name, nodes] : mesh.nodeSets_)
    for (lid_t n : nodes) MFSI_CHECK(n >= 0 && n < nNodes, src << ": node set '" << name << "' lists node " << n);
  mesh.centreNode_ = mesh.nearestNode(centroid);
  if (!mesh.nodeSets_.count("boundary")) mesh.nodeSets_["boundary"] = mesh.boundaryNodes_;
  if (!mesh.nodeSets_.count("centre")) mesh.nodeSets_["centre"] = {mesh.centreNode_};

  // Device copies.
  mesh.points_ = Real3View("mfsi::structure::membrane::mesh::points", nNodes);
  mesh.nodeNormals_ = Real3View("mfsi::structure::membrane::mesh::nodeNormals", nNodes);
  mesh.elements_ = Quad4View("mfsi::structure::membrane::mesh::elements", mesh.nElements());
  auto hp = Kokkos::create_mirror_view(mesh.points_);
  auto hn = Kokkos::create_mirror_view(mesh.nodeNormals_);
  auto he = Kokkos::create_mirror_view(mesh.elements_);
  for (lid_t n = 0; n < nNodes; ++n)
    for (int k = 0; k < 3; ++k) {
      hp(n, k) = in.points[n][k];
      hn(n, k) = mesh.hostNormals_[n][k];
    }
  for (lid_t e = 0; e < mesh.nElements(); ++e)
    for (int a = 0; a < 4; ++a) he(e, a) = in.elements[e][a];
  Kokkos::deep_copy(mesh.points_, hp);
  Kokkos::deep_copy(mesh.nodeNormals_, hn);
  Kokkos::deep_copy(mesh.elements_, he);
  mesh.nodeElements_ = buildNodeItemMap(in.elements, nNodes, "mfsi::structure::membrane::mesh");
  return mesh;
}

MembraneMeshInput generateRectangleMesh(const MembraneRectangleSpec& s) {
  MFSI_CHECK(s.nx >= 1 && s.ny >= 1, "membrane rectangle: nx and ny must be >= 1");
  MFSI_CHECK(s.lx > 0 && s.ly > 0, "membrane rectangle: lx and ly must be > 0");
  MFSI_CHECK(s.jitter >= 0 && s.jitter < 0.35, "membrane rectangle: jitter must be in [0, 0.35)");
  MembraneMeshInput m;
  m.source = "rectangle generator";
  const real hx = s.lx / s.nx, hy = s.ly / s.ny;
  std::mt19937 rng(s.seed);
  std::uniform_real_distribution<real> uni(-1.0, 1.0);
  addBlock(m, s.nx, s.ny, s.type, [&](int i, int j) {
    real x = i * hx, y = j * hy;
    if (i > 0 && i < s.nx && j > 0 && j < s.ny && s.jitter > 0) {
      x += s.jitter * hx * uni(rng);
      y += s.jitter * hy * uni(rng);
    }
    return Vec3{s.origin[0] + x, s.origin[1] + y, s.origin[2]};
  });
  auto id = [&](int i, int j) { return static_cast<lid_t>(j * (s.nx + 1) + i); };
  for (int j = 0; j <= s.ny; ++j) {
    m.nodeSets["xmin"].push_back(id(0, j));
    m.nodeSets["xmax"].push_back(id(s.nx, j));
  }
  for (int i = 0; i <= s.nx; ++i) {
    m.nodeSets["ymin"].push_back(id(i, 0));
    m.nodeSets["ymax"].push_back(id(i, s.ny));
  }
  m.nodeSets["corners"] = {id(0, 0), id(s.nx, 0), id(s.nx, s.ny), id(0, s.ny)};
  std::sort(m.nodeSets["corners"].begin(), m.nodeSets["corners"].end());
  m.nodeSets["centre"] = {id(s.nx / 2, s.ny / 2)};
  return m;
}

MembraneMeshInput generateDiscMesh(const MembraneDiscSpec& s) {
  MFSI_CHECK(s.nCore >= 1 && s.nRing >= 1, "membrane disc: nCore and nRing must be >= 1");
  MFSI_CHECK(s.radius > 0, "membrane disc: radius must be > 0");
  MFSI_CHECK(s.coreFraction > 0.05 && s.coreFraction < 0.95, "membrane disc: coreFraction must be in (0.05, 0.95)");
  MFSI_CHECK(s.ringGrading > 0, "membrane disc: ringGrading must be > 0");
  MembraneMeshInput m;
  m.source = "disc generator";
  const real half = s.coreFraction * s.radius / std::sqrt(2.0);
  const int n = s.nCore;
  const Vec3 c = s.centre;
  addBlock(m, n, n, s.type, [&](int i, int j) {
    return Vec3{c[0] - half + 2 * half * i / n, c[1] - half + 2 * half * j / n, c[2]};
  });
  // Radial stations of the ring blocks: geometric sizes with last/first = ringGrading.
  std::vector<real> station(s.nRing + 1, 0);
  const real q = s.nRing > 1 ? std::pow(s.ringGrading, 1.0 / (s.nRing - 1)) : 1.0;
  real total = 0, size = 1;
  for (int l = 0; l < s.nRing; ++l, size *= q) total += size;
  size = 1;
  for (int l = 0; l < s.nRing; ++l, size *= q) station[l + 1] = station[l] + size / total;
  station[s.nRing] = 1;
  // Four outer blocks, one per side of the square: i runs along the side, j outwards.
  const real pi = std::acos(-1.0);
  for (int side = 0; side < 4; ++side) {
    const real theta0 = side * pi / 2;  // east, north, west, south
    const real ct = std::cos(theta0), st = std::sin(theta0);
    addBlock(m, n, s.nRing, s.type, [&](int i, int j) {
      const real t = -1 + 2.0 * i / n;  // along the side
      // Square side point in the rotated frame: (half, t half); circle point at theta0 + t pi/4.
      const real sx = half, sy = t * half;
      const real ix = ct * sx - st * sy, iy = st * sx + ct * sy;
      const real th = theta0 + t * pi / 4;
      const real ox = s.radius * std::cos(th), oy = s.radius * std::sin(th);
      const real w = station[j];
      return Vec3{c[0] + ix + w * (ox - ix), c[1] + iy + w * (oy - iy), c[2]};
    });
  }
  orientUp(m);
  mergeCoincidentNodes(m);
  // The centre node: nearest to the centre (exact when nCore is even).
  lid_t best = 0;
  for (lid_t p = 1; p < static_cast<lid_t>(m.points.size()); ++p)
    if (norm(sub(m.points[p], c)) < norm(sub(m.points[best], c))) best = p;
  m.nodeSets["centre"] = {best};
  return m;
}

MembraneMeshInput generateAnnulusMesh(const MembraneAnnulusSpec& s) {
  MFSI_CHECK(s.nRadial >= 1 && s.nTheta >= 3, "membrane annulus: nRadial >= 1 and nTheta >= 3 required");
  MFSI_CHECK(s.innerRadius > 0 && s.outerRadius > s.innerRadius, "membrane annulus: need 0 < innerRadius < outerRadius");
  MFSI_CHECK(s.radialGrading > 0, "membrane annulus: radialGrading must be > 0");
  MembraneMeshInput m;
  m.source = "annulus generator";
  const real pi = std::acos(-1.0);
  std::vector<real> r(s.nRadial + 1, s.innerRadius);
  const real q = s.nRadial > 1 ? std::pow(s.radialGrading, 1.0 / (s.nRadial - 1)) : 1.0;
  real total = 0, size = 1;
  for (int l = 0; l < s.nRadial; ++l, size *= q) total += size;
  size = 1;
  for (int l = 0; l < s.nRadial; ++l, size *= q)
    r[l + 1] = r[l] + (s.outerRadius - s.innerRadius) * size / total;
  r[s.nRadial] = s.outerRadius;
  addBlock(m, s.nTheta, s.nRadial, MembraneElementType::Quad4, [&](int i, int j) {
    const real th = 2 * pi * i / s.nTheta;
    return Vec3{s.centre[0] + r[j] * std::cos(th), s.centre[1] + r[j] * std::sin(th), s.centre[2]};
  });
  for (int i = 0; i <= s.nTheta; ++i) {
    m.nodeSets["inner"].push_back(static_cast<lid_t>(i));
    m.nodeSets["outer"].push_back(static_cast<lid_t>(s.nRadial * (s.nTheta + 1) + i));
  }
  orientUp(m);
  mergeCoincidentNodes(m);
  return m;
}

MembraneMeshInput generateSphereMesh(const MembraneSphereSpec& s) {
  MFSI_CHECK(s.n >= 1 && s.radius > 0, "membrane sphere: need n >= 1 and radius > 0");
  MembraneMeshInput m;
  m.source = "sphere generator";
  const real pi = std::acos(-1.0);
  // Face k: outward axis a = k / 2 with sign +-1; (u, v) spans the other two axes.
  for (int face = 0; face < 6; ++face) {
    const int axis = face / 2;
    const real sign = face % 2 == 0 ? 1.0 : -1.0;
    const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
    addBlock(m, s.n, s.n, MembraneElementType::Quad4, [&](int i, int j) {
      Vec3 p{0, 0, 0};
      p[axis] = sign;
      p[ua] = std::tan(pi / 4 * (-1 + 2.0 * i / s.n));
      p[va] = std::tan(pi / 4 * (-1 + 2.0 * j / s.n));
      const real l = norm(p);
      return Vec3{s.centre[0] + s.radius * p[0] / l, s.centre[1] + s.radius * p[1] / l,
                  s.centre[2] + s.radius * p[2] / l};
    });
  }
  // Outward orientation: the area vector must point away from the centre.
  for (auto& e : m.elements) {
    Vec3 c{0, 0, 0};
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < 3; ++k) c[k] += 0.25 * m.points[e[a]][k] - 0.25 * s.centre[k];
    const Vec3 A = areaVector(m.points, e);
    if (A[0] * c[0] + A[1] * c[1] + A[2] * c[2] < 0) std::swap(e[1], e[3]);
  }
  mergeCoincidentNodes(m);
  lid_t best = 0;
  const Vec3 pole{s.centre[0], s.centre[1], s.centre[2] + s.radius};
  for (lid_t p = 1; p < static_cast<lid_t>(m.points.size()); ++p)
    if (norm(sub(m.points[p], pole)) < norm(sub(m.points[best], pole))) best = p;
  m.nodeSets["centre"] = {best};
  return m;
}

}  // namespace mfsi
