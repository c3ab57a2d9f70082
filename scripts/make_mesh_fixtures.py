#!/usr/bin/env python3
"""Write the small mesh fixtures of tests/data/meshes/ (Gmsh 4.1 ASCII files and OpenFOAM polyMesh
directories) used by tests/core/test_readers.cpp.

    python3 scripts/make_mesh_fixtures.py [output-dir]     # default: tests/data/meshes
    python3 scripts/make_mesh_fixtures.py --tools          # also rerun gmsh and blockMesh

Deterministic (fixed random seed), standard library only. The good meshes are boxes of hexes with
the six sides as named patches; node and element numbering, hex node rotation, face rotation and
Gmsh entity/tag layout are scrambled so the readers' remapping and hex reconstruction are
exercised. The bad meshes each carry exactly one defect that a reader must report.

With --tools, the fixtures written by the real tools are remade too (needs `gmsh` and OpenFOAM's
`blockMesh` on PATH; Debian packages gmsh and openfoam): gmsh_box.msh and gmsh_cylinder.msh from
their .geo files, and openfoam_box/constant/polyMesh from openfoam_box/system/blockMeshDict.
"""
import itertools
import os
import random
import shutil
import subprocess
import sys

# Hex node order (VTK/Gmsh/OpenFOAM) and its six faces with outward normals (core/HexMesh.hpp).
HEX_FACES = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (0, 4, 7, 3), (1, 2, 6, 5)]
HEX_CORNERS = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
               (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
# Box sides in BlockSpec::patches order: xmin, xmax, ymin, ymax, zmin, zmax.
SIDE_NAMES = ["left", "right", "bottom", "top", "back", "front"]


def graded(a, b, n, ratio):
    """Same arithmetic as gradedCoordinates() in core/BlockMesh.cpp."""
    if n == 1 or abs(ratio - 1.0) < 1e-14:
        return [a + (b - a) * i / n for i in range(n + 1)]
    q = ratio ** (1.0 / (n - 1))
    total, s = 0.0, 1.0
    for _ in range(n):
        total += s
        s *= q
    x, pos, h = [a], a, (b - a) / total
    for _ in range(n):
        pos += h
        x.append(pos)
        h *= q
    x[n] = b
    return x


def hex_rotations():
    """The 24 orientation-preserving node permutations of a hex: new node a = old node p[a]."""
    index = {c: i for i, c in enumerate(HEX_CORNERS)}
    perms = []
    for axes in itertools.permutations(range(3)):
        parity = sum(1 for i in range(3) for j in range(i + 1, 3) if axes[i] > axes[j]) % 2
        for signs in itertools.product((1, -1), repeat=3):
            if (-1) ** parity * signs[0] * signs[1] * signs[2] != 1:
                continue
            perms.append([index[tuple(signs[k] * c[axes[k]] for k in range(3))] for c in HEX_CORNERS])
    assert len(perms) == 24
    return perms


ROTATIONS = hex_rotations()


class Box:
    """A structured box of hexes: points, cells (VTK order) and the boundary faces of each side."""

    def __init__(self, lo, hi, n, grading=(1, 1, 1), transform=None):
        self.n = n
        xs = [graded(lo[d], hi[d], n[d], grading[d]) for d in range(3)]
        nx, ny, nz = n
        self.ijk = []
        self.points = []
        for k in range(nz + 1):
            for j in range(ny + 1):
                for i in range(nx + 1):
                    p = (xs[0][i], xs[1][j], xs[2][k])
                    self.points.append(transform(p) if transform else p)
                    self.ijk.append((i, j, k))
        node = lambda i, j, k: i + (nx + 1) * (j + (ny + 1) * k)
        self.cells, self.cell_ijk = [], []
        for k in range(nz):
            for j in range(ny):
                for i in range(nx):
                    self.cells.append([node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k),
                                       node(i, j, k + 1), node(i + 1, j, k + 1), node(i + 1, j + 1, k + 1),
                                       node(i, j + 1, k + 1)])
                    self.cell_ijk.append((i, j, k))
        # side -> list of (cell, outward quad)
        local = {0: 4, 1: 5, 2: 2, 3: 3, 4: 0, 5: 1}
        self.side_faces = [[] for _ in range(6)]
        for c, (i, j, k) in enumerate(self.cell_ijk):
            for s, hit in enumerate((i == 0, i == nx - 1, j == 0, j == ny - 1, k == 0, k == nz - 1)):
                if hit:
                    self.side_faces[s].append((c, [self.cells[c][a] for a in HEX_FACES[local[s]]]))

    def node_sides(self, v):
        i, j, k = self.ijk[v]
        nx, ny, nz = self.n
        return frozenset(s for s, hit in enumerate((i == 0, i == nx, j == 0, j == ny, k == 0, k == nz)) if hit)


def fmt(x):
    return repr(float(x))


# ----------------------------------------------------------------------------------------------
# Gmsh 4.1 ASCII
# ----------------------------------------------------------------------------------------------

def msh_text(node_blocks, element_blocks, entities=None, physical_names=None, version="4.1 0 8"):
    """node_blocks: [(dim, entity, [(tag, xyz, params-or-None)])];
    element_blocks: [(dim, entity, type, [(tag, [node tags])])];
    entities: {'points': [(tag, xyz, phys)], 'curves'|'surfaces'|'volumes': [(tag, lo, hi, phys, bounding)]};
    physical_names: [(dim, tag, name)]."""
    out = ["$MeshFormat", version, "$EndMeshFormat"]
    if physical_names:
        out.append("$PhysicalNames")
        out.append(str(len(physical_names)))
        out += ['%d %d "%s"' % pn for pn in physical_names]
        out.append("$EndPhysicalNames")
    if entities:
        out.append("$Entities")
        out.append(" ".join(str(len(entities.get(k, []))) for k in ("points", "curves", "surfaces", "volumes")))
        for tag, xyz, phys in entities.get("points", []):
            out.append(" ".join([str(tag)] + [fmt(v) for v in xyz] + [str(len(phys))] + [str(p) for p in phys]))
        for kind in ("curves", "surfaces", "volumes"):
            for tag, lo, hi, phys, bounding in entities.get(kind, []):
                out.append(" ".join([str(tag)] + [fmt(v) for v in lo + hi] + [str(len(phys))] + [str(p) for p in phys]
                                    + [str(len(bounding))] + [str(b) for b in bounding]))
        out.append("$EndEntities")
    all_tags = [t for _, _, nodes in node_blocks for t, _, _ in nodes]
    out.append("$Nodes")
    out.append("%d %d %d %d" % (len(node_blocks), len(all_tags), min(all_tags), max(all_tags)))
    for dim, entity, nodes in node_blocks:
        parametric = 1 if any(p is not None for _, _, p in nodes) else 0
        out.append("%d %d %d %d" % (dim, entity, parametric, len(nodes)))
        out += [str(t) for t, _, _ in nodes]
        for _, xyz, params in nodes:
            out.append(" ".join(fmt(v) for v in list(xyz) + (list(params) if parametric else [])))
    out.append("$EndNodes")
    all_elems = [t for _, _, _, elems in element_blocks for t, _ in elems]
    out.append("$Elements")
    out.append("%d %d %d %d" % (len(element_blocks), len(all_elems), min(all_elems), max(all_elems)))
    for dim, entity, etype, elems in element_blocks:
        out.append("%d %d %d %d" % (dim, entity, etype, len(elems)))
        out += [" ".join(str(v) for v in [t] + list(nodes)) for t, nodes in elems]
    out.append("$EndElements")
    return "\n".join(out) + "\n"


def box_msh(box, rng, names, volume_split=True, extra_bottom_entity=True):
    """A Gmsh-like file for `box`: nodes classified on point/curve/surface/volume entities, sparse
    shuffled node and element tags, random hex rotations, quads on the side surfaces.
    names[s] is the physical name of side s (None: physical group without a name)."""
    nx = box.n[0]
    n_nodes = len(box.points)
    node_tag = rng.sample(range(1, 10 * n_nodes), n_nodes + 1)  # sparse, shuffled; the last is an orphan
    corner_sets = sorted({box.node_sides(v) for v in range(n_nodes) if len(box.node_sides(v)) == 3}, key=sorted)
    edge_sets = sorted({box.node_sides(v) for v in range(n_nodes) if len(box.node_sides(v)) == 2}, key=sorted)
    point_of = {s: t + 1 for t, s in enumerate(corner_sets)}
    curve_of = {s: t + 1 for t, s in enumerate(edge_sets)}
    phys_side = [11 + s for s in range(6)]

    def volume_of_x(i):
        return 1 if (not volume_split or i < nx // 2) else 2

    def entity_of(v):
        s = box.node_sides(v)
        if len(s) == 3:
            return 0, point_of[s]
        if len(s) == 2:
            return 1, curve_of[s]
        if len(s) == 1:
            return 2, next(iter(s)) + 1
        return 3, volume_of_x(box.ijk[v][0])

    blocks = {}
    for v in range(n_nodes):
        blocks.setdefault(entity_of(v), []).append(v)
    node_blocks = []
    for (dim, ent) in sorted(blocks):
        vs = blocks[(dim, ent)]
        rng.shuffle(vs)
        # One surface block carries parametric coordinates (u, v), which readers must skip.
        params = (lambda v: (0.25, 0.75)) if (dim, ent) == (2, 2) else (lambda v: None)
        nodes = [(node_tag[v], box.points[v], params(v)) for v in vs]
        if (dim, ent) == (3, 1):
            nodes.insert(len(nodes) // 2, (node_tag[n_nodes], (9.0, 9.0, 9.0), None))  # used by no element
        node_blocks.append((dim, ent, nodes))

    def bbox(vs):
        lo = [min(box.points[v][d] for v in vs) for d in range(3)]
        hi = [max(box.points[v][d] for v in vs) for d in range(3)]
        return lo, hi

    closure = lambda sides: [v for v in range(n_nodes) if sides <= box.node_sides(v)]
    entities = {"points": [], "curves": [], "surfaces": [], "volumes": []}
    for s, t in point_of.items():
        v = closure(s)[0]
        entities["points"].append((t, box.points[v], []))
    for s, t in curve_of.items():
        lo, hi = bbox(closure(s))
        ends = [point_of[c] for c in corner_sets if s <= c]
        entities["curves"].append((t, lo, hi, [50] if t == 1 else [], [ends[0], -ends[1]]))
    for s in range(6):
        lo, hi = bbox(closure(frozenset([s])))
        bounding = [curve_of[e] * (1 if k % 2 == 0 else -1) for k, e in enumerate(
            [e for e in edge_sets if s in e])]
        entities["surfaces"].append((s + 1, lo, hi, [phys_side[s]], bounding))
    bottom = 2
    if extra_bottom_entity:
        # Part of the bottom side lives on a second surface entity of the same physical group.
        lo, hi = bbox(closure(frozenset([bottom])))
        entities["surfaces"].append((7, lo, hi, [phys_side[bottom]], []))
    n_vol = 2 if volume_split else 1
    for vol in range(1, n_vol + 1):
        lo, hi = bbox([v for c, cell in enumerate(box.cells) if volume_of_x(box.cell_ijk[c][0]) == vol for v in cell])
        entities["volumes"].append((vol, lo, hi, [100], list(range(1, 7))))

    line_nodes = sorted(closure(edge_sets[0]), key=lambda v: box.points[v])
    n_elems = len(box.cells) + sum(len(f) for f in box.side_faces) + 1 + len(line_nodes)
    elem_tag = iter(rng.sample(range(1, 10 * n_elems), n_elems))
    element_blocks = []
    # 0D and 1D elements, which readers ignore.
    element_blocks.append((0, 1, 15, [(next(elem_tag), [node_tag[closure(corner_sets[0])[0]]])]))
    element_blocks.append((1, 1, 1, [(next(elem_tag), [node_tag[a], node_tag[b]])
                                     for a, b in zip(line_nodes, line_nodes[1:])]))
    for s in range(6):
        quads = {1: [], 7: []}
        for c, q in box.side_faces[s]:
            q = q[::-1] if rng.random() < 0.5 else q  # any orientation is accepted
            r = rng.randrange(4)
            q = q[r:] + q[:r]
            ent = 7 if (extra_bottom_entity and s == bottom and box.cell_ijk[c][0] >= nx // 2) else 1
            quads[ent].append((next(elem_tag), [node_tag[v] for v in q]))
        element_blocks.append((2, s + 1, 3, quads[1]))
        if quads[7]:
            element_blocks.append((2, 7, 3, quads[7]))
    hexes = {}
    for c, cell in enumerate(box.cells):
        p = rng.choice(ROTATIONS)
        hexes.setdefault(volume_of_x(box.cell_ijk[c][0]), []).append(
            (next(elem_tag), [node_tag[cell[p[a]]] for a in range(8)]))
    for vol in sorted(hexes):
        element_blocks.append((3, vol, 5, hexes[vol]))

    physical_names = [(1, 50, "edge")] + [(2, phys_side[s], names[s]) for s in range(6) if names[s]] + [(3, 100, "fluid")]
    return msh_text(node_blocks, element_blocks, entities, physical_names)


def simple_msh(points, hexes, others=(), quads=(), tag_offset=0):
    """A minimal file: all nodes and elements on volume entity 1, no $Entities."""
    nodes = [(tag_offset + i + 1, p, None) for i, p in enumerate(points)]
    blocks = [(3, 1, 5, [(tag_offset + 1 + e, [tag_offset + v + 1 for v in h]) for e, h in enumerate(hexes)])]
    e0 = len(hexes)
    for etype, conn in others:
        blocks.append((3, 1, etype, [(tag_offset + 1 + e0, [tag_offset + v + 1 for v in conn])]))
        e0 += 1
    return msh_text([(3, 1, nodes)], blocks)


# ----------------------------------------------------------------------------------------------
# OpenFOAM polyMesh (ASCII)
# ----------------------------------------------------------------------------------------------

def foam_header(cls, obj, note=None):
    lines = ["/*---------------------------------------------------------------------------*\\",
             "  Mesh fixture for membrane-fsi, written by scripts/make_mesh_fixtures.py",
             "\\*---------------------------------------------------------------------------*/",
             "FoamFile", "{", "    version     2.0;", "    format      ascii;",
             '    arch        "LSB;label=32;scalar=64";', "    class       %s;" % cls,
             '    location    "constant/polyMesh";']
    if note:
        lines.append('    note        "%s";' % note)
    lines += ["    object      %s;" % obj, "}", "// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //", "", ""]
    return "\n".join(lines) + "\n"


FOAM_FOOTER = "\n\n// ************************************************************************* //\n"


def write_polymesh(path, points, cell_faces, patches, rng):
    """cell_faces[c]: the outward faces (node lists) of cell c; patches: [(name, type, [face keys])].
    Writes faces in OpenFOAM order: internal faces sorted by (owner, neighbour), owner < neighbour,
    oriented out of the owner; then boundary faces patch by patch. Face start nodes are rotated."""
    os.makedirs(path, exist_ok=True)
    by_key = {}
    for c, faces in enumerate(cell_faces):
        for f in faces:
            by_key.setdefault(tuple(sorted(f)), []).append((c, list(f)))
    internal, boundary = [], {}
    for key, refs in by_key.items():
        assert len(refs) in (1, 2)
        if len(refs) == 2:
            (o, fo), (n, _) = sorted(refs)
            internal.append((o, n, fo))
        else:
            boundary[key] = refs[0]
    internal.sort(key=lambda t: (t[0], t[1]))
    faces, owner, neighbour, entries = [], [], [], []
    for o, n, f in internal:
        faces.append(f)
        owner.append(o)
        neighbour.append(n)
    claimed = set()
    for name, ptype, keys in patches:
        start = len(faces)
        for key in sorted(keys, key=lambda k: (boundary[k][0], k)):
            assert key not in claimed
            claimed.add(key)
            faces.append(boundary[key][1])
            owner.append(boundary[key][0])
        entries.append((name, ptype, start, len(faces) - start))
    assert claimed == set(boundary), "every boundary face must be in a patch"
    rotated = []
    for f in faces:
        r = rng.randrange(len(f))
        rotated.append(f[r:] + f[:r])
    n_cells = len(cell_faces)
    note = "nPoints:%d  nCells:%d  nFaces:%d  nInternalFaces:%d" % (len(points), n_cells, len(faces), len(internal))

    def write(name, cls, body, note=None):
        with open(os.path.join(path, name), "w") as fh:
            fh.write(foam_header(cls, name, note) + body + FOAM_FOOTER)

    write("points", "vectorField", "%d\n(\n%s\n)\n" % (len(points), "\n".join(
        "(%s)" % " ".join(fmt(v) for v in p) for p in points)))
    write("faces", "faceList", "%d\n(\n%s\n)\n" % (len(rotated), "\n".join(
        "%d(%s)" % (len(f), " ".join(str(v) for v in f)) for f in rotated)))
    write("owner", "labelList", "%d\n(\n%s\n)\n" % (len(owner), "\n".join(str(o) for o in owner)), note)
    write("neighbour", "labelList", "%d\n(\n%s\n)\n" % (len(neighbour), "\n".join(str(n) for n in neighbour)), note)
    body = ["%d" % len(entries), "("]
    for name, ptype, start, size in entries:
        body += ["    %s" % name, "    {", "        type            %s;" % ptype]
        if ptype == "wall":
            body.append("        inGroups        List<word> 1(wall);")
        body += ["        nFaces          %d;" % size, "        startFace       %d;" % start, "    }"]
    body.append(")")
    write("boundary", "polyBoundaryMesh", "\n".join(body) + "\n")


def box_polymesh(path, box, rng, types):
    """`box` as a polyMesh with shuffled node and cell numbering; patch i named SIDE_NAMES[i]."""
    n_nodes, n_cells = len(box.points), len(box.cells)
    new_node = list(range(n_nodes))
    rng.shuffle(new_node)
    points = [None] * n_nodes
    for v in range(n_nodes):
        points[new_node[v]] = box.points[v]
    new_cell = list(range(n_cells))
    rng.shuffle(new_cell)
    cell_faces = [None] * n_cells
    for c, cell in enumerate(box.cells):
        cell_faces[new_cell[c]] = [[new_node[cell[a]] for a in f] for f in HEX_FACES]
    patches = [(SIDE_NAMES[s], types[s], [tuple(sorted(new_node[v] for v in q)) for _, q in box.side_faces[s]])
               for s in range(6)]
    write_polymesh(path, points, cell_faces, patches, rng)


# ----------------------------------------------------------------------------------------------

def skew(p):
    """Volume-preserving shear (det 1), so the sheared box keeps the volume of the unsheared one."""
    x, y, z = p
    return (x + 0.4 * y + 0.2 * z, y + 0.3 * z, z)


def run_tools(out):
    """Remake the fixtures that the real Gmsh and OpenFOAM write."""
    for tool in ("gmsh", "blockMesh"):
        if not shutil.which(tool):
            sys.exit("--tools needs '%s' on PATH" % tool)
    for name in ("gmsh_box", "gmsh_cylinder"):
        subprocess.run(["gmsh", name + ".geo", "-3", "-format", "msh41", "-o", name + ".msh"], cwd=out, check=True,
                       stdout=subprocess.DEVNULL)
    # blockMesh needs the OpenFOAM environment; Debian's package keeps it in this bashrc.
    bashrc = "/usr/share/openfoam/etc/bashrc"
    if "WM_PROJECT_DIR" not in os.environ and os.path.exists(bashrc):
        cmd = ["bash", "-c", "source %s >/dev/null 2>&1; blockMesh -case openfoam_box" % bashrc]
    else:
        cmd = ["blockMesh", "-case", "openfoam_box"]
    subprocess.run(cmd, cwd=out, check=True, stdout=subprocess.DEVNULL)


def main():
    args = [a for a in sys.argv[1:] if a != "--tools"]
    out = args[0] if args else os.path.join(os.path.dirname(__file__), "..", "tests", "data", "meshes")
    os.makedirs(out, exist_ok=True)
    rng = random.Random(20240611)

    def save(name, text):
        with open(os.path.join(out, name), "w") as fh:
            fh.write(text)

    # The box of the tests: [0,1]x[0,0.5]x[0,0.25], 4x2x2 cells.
    box = Box((0, 0, 0), (1, 0.5, 0.25), (4, 2, 2))
    box_text = box_msh(box, rng, SIDE_NAMES)
    save("box.msh", box_text)
    box_polymesh(os.path.join(out, "box.polyMesh"), box, rng,
                 ["patch", "patch", "wall", "symmetry", "empty", "symmetryPlane"])

    # Graded and sheared box: 5x3x2 cells, grading (2, 0.5, 1); the front side is an unnamed
    # physical group in the Gmsh file ("patch16").
    graded_box = Box((0, 0, 0), (1, 0.5, 0.25), (5, 3, 2), grading=(2.0, 0.5, 1.0), transform=skew)
    save("skewed.msh", box_msh(graded_box, rng, SIDE_NAMES[:5] + [None]))
    box_polymesh(os.path.join(out, "skewed.polyMesh"), graded_box, rng, ["patch"] * 6)

    # The box mirrored (x -> -x) without turning its faces around: every face points into its
    # owner, the reader must still build right-handed cells.
    mirrored = Box((0, 0, 0), (1, 0.5, 0.25), (4, 2, 2), transform=lambda p: (-p[0], p[1], p[2]))
    box_polymesh(os.path.join(out, "mirrored.polyMesh"), mirrored, rng, ["patch"] * 6)

    # --- bad meshes ---------------------------------------------------------------------------
    two = Box((0, 0, 0), (2, 1, 1), (2, 1, 1))
    # A hex with a tetrahedron glued on its x+ side.
    tet_points = two.points[:] + [(3.0, 0.5, 0.5)]
    c1 = two.cells[1]
    save("bad_tet.msh", simple_msh(tet_points, [two.cells[0], c1], others=[(4, [c1[1], c1[2], c1[6], 12])]))
    # Second hex listed bottom-up mirrored (top and bottom swapped): negative volume.
    c = two.cells[1]
    save("bad_inverted.msh", simple_msh(two.points, [two.cells[0], c[4:] + c[:4]], tag_offset=40))
    # Box file cut in the middle of a hexahedron (after its tag and three node tags).
    lines = box_text.splitlines(keepends=True)
    cut = len(lines) - 9
    save("bad_truncated.msh", "".join(lines[:cut]) + " ".join(lines[cut].split()[:4]))
    # A coordinate that is not a number, an element with an unknown node tag, an old format.
    bad = simple_msh(two.points, two.cells).replace("\n2.0 1.0 1.0\n", "\n2.0 1.O 1.0\n")
    assert "1.O" in bad
    save("bad_number.msh", bad)
    save("bad_node_tag.msh", simple_msh(two.points, [two.cells[0], two.cells[1][:7] + [98]]))  # node tag 99
    save("bad_version.msh", simple_msh(two.points, two.cells).replace("4.1 0 8", "2.2 0 8"))
    save("bad_binary.msh", "$MeshFormat\n4.1 1 8\n$EndMeshFormat\n")

    # polyMesh with a hex and a prism (triangle in x-z extruded along y) on its x+ side.
    pts = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1),
           (2, 0, 0), (2, 1, 0)]
    hex_faces = [[a for a in f] for f in HEX_FACES]
    prism_faces = [[1, 8, 5], [2, 6, 9], [1, 5, 6, 2], [1, 2, 9, 8], [8, 9, 6, 5]]
    write_polymesh(os.path.join(out, "bad_prism.polyMesh"), pts, [hex_faces, prism_faces],
                   [("walls", "wall", [tuple(sorted(f)) for f in hex_faces if 1 not in f or 0 in f] +
                     [tuple(sorted(f)) for f in prism_faces if sorted(f) != [1, 2, 5, 6]])], rng)
    # Binary polyMesh: only the header matters.
    os.makedirs(os.path.join(out, "bad_binary.polyMesh"), exist_ok=True)
    with open(os.path.join(out, "bad_binary.polyMesh", "points"), "w") as fh:
        fh.write(foam_header("vectorField", "points").replace("format      ascii", "format      binary"))

    if "--tools" in sys.argv[1:]:
        run_tools(out)


if __name__ == "__main__":
    main()
