#!/usr/bin/env python3
"""Write the Gmsh 4.1 ASCII membrane surface fixtures tests/data/meshes/membrane_*.msh used by
tests/structure/test_membrane_import.cpp.

    python3 scripts/make_membrane_fixtures.py [output-dir]     # default: tests/data/meshes

Deterministic (fixed random seed), standard library only. Node tags are sparse and shuffled and
spread over several node blocks so that the reader's renumbering is exercised.

  membrane_square_quads.msh  unit square z = 0, 4x4 quads in two surface entities (x < 0.5 and
                             x > 0.5) of the physical surface "membrane"; a second square
                             [2,3]x[0,1] of 2x2 quads in the physical surface "other"; physical
                             curves "clamped" (the four sides of the unit square) and "xmin"
                             (its side x = 0); the curve x = 0.5 carries lines outside any group.
  membrane_square_tris.msh   the unit square, 4x4 cells each split in two triangles along the
                             diagonal the rectangle generator picks ((i + j) even: a-c, else b-d);
                             physical surface "membrane", physical curve "clamped".
  membrane_bad_type.msh      the triangle square with one 6-node triangle block (element 77)
  membrane_bad_node.msh      the quad square whose element 5 uses node tag 999 (absent)
  membrane_bad_line.msh      the triangle square whose "clamped" group holds 3-node lines (element 88)
  membrane_bad_truncated.msh membrane_square_quads.msh cut in the middle of the $Elements section
"""
import os
import random
import sys

N = 4  # cells per side of the unit square


def grid_id(i, j, n=N):
    return j * (n + 1) + i


class Msh:
    """Collects nodes (by key), entities and element blocks and writes MSH 4.1 ASCII."""

    def __init__(self, seed):
        self.rng = random.Random(seed)
        self.coords = {}       # key -> (x, y, z)
        self.names = []        # (dim, tag, name)
        self.entities = {0: [], 1: [], 2: [], 3: []}  # dim -> [(tag, phys tags, bbox)]
        self.blocks = []       # (dim, entity, type, [(tag, [node keys])]) ; raw rows allowed
        self.next_element = 1

    def node(self, key, xyz):
        self.coords[key] = xyz

    def entity(self, dim, tag, phys, keys):
        pts = [self.coords[k] for k in keys]
        lo = [min(p[d] for p in pts) for d in range(3)]
        hi = [max(p[d] for p in pts) for d in range(3)]
        self.entities[dim].append((tag, phys, lo + hi))

    def block(self, dim, entity, etype, elements, first_tag=None):
        """elements: list of node-key lists. Returns the element tags used."""
        tags = []
        rows = []
        for e in elements:
            t = self.next_element if first_tag is None else first_tag + len(tags)
            self.next_element = max(self.next_element, t + 1)
            tags.append(t)
            rows.append((t, e))
        self.blocks.append((dim, entity, etype, rows))
        return tags

    def write(self, path, node_tag_override=None):
        keys = list(self.coords)
        order = keys[:]
        self.rng.shuffle(order)
        # Sparse tags: 3 k + 7 in a shuffled order.
        tag = {k: 3 * n + 7 for n, k in enumerate(order)}
        lines = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat"]
        lines.append("$PhysicalNames")
        lines.append(str(len(self.names)))
        for dim, t, name in self.names:
            lines.append('%d %d "%s"' % (dim, t, name))
        lines.append("$EndPhysicalNames")
        lines.append("$Entities")
        lines.append(" ".join(str(len(self.entities[d])) for d in range(4)))
        for d in range(4):
            for t, phys, box in self.entities[d]:
                coords = box[:3] if d == 0 else box
                row = [str(t)] + ["%.17g" % c for c in coords] + [str(len(phys))] + [str(p) for p in phys]
                if d > 0:
                    row.append("0")
                lines.append(" ".join(row))
        lines.append("$EndEntities")
        # Nodes: two blocks on surface entity 1 (the reader does not care about classification).
        half = len(order) // 2
        node_blocks = [order[:half], order[half:]]
        lines.append("$Nodes")
        lines.append("%d %d %d %d" % (len(node_blocks), len(order), min(tag.values()), max(tag.values())))
        for blk in node_blocks:
            lines.append("2 1 0 %d" % len(blk))
            for k in blk:
                lines.append(str(tag[k]))
            for k in blk:
                lines.append("%.17g %.17g %.17g" % self.coords[k])
        lines.append("$EndNodes")
        n_el = sum(len(b[3]) for b in self.blocks)
        all_tags = [r[0] for b in self.blocks for r in b[3]]
        lines.append("$Elements")
        lines.append("%d %d %d %d" % (len(self.blocks), n_el, min(all_tags), max(all_tags)))
        for dim, ent, etype, rows in self.blocks:
            lines.append("%d %d %d %d" % (dim, ent, etype, len(rows)))
            for t, e in rows:
                node_tags = [str(tag[k]) if not isinstance(k, int) else str(k) for k in e]
                if node_tag_override and t in node_tag_override:
                    node_tags[0] = str(node_tag_override[t])
                lines.append(" ".join([str(t)] + node_tags))
        lines.append("$EndElements")
        text = "\n".join(lines) + "\n"
        with open(path, "w") as f:
            f.write(text)
        return text


def square_nodes(m, n=N, x0=0.0, prefix="s"):
    for j in range(n + 1):
        for i in range(n + 1):
            m.node((prefix, i, j), (x0 + i / n, j / n, 0.0))


def side_lines(prefix, n=N):
    """The four sides of the square as node-key pairs (counter-clockwise) and the x = 0 side alone."""
    bottom = [((prefix, i, 0), (prefix, i + 1, 0)) for i in range(n)]
    right = [((prefix, n, j), (prefix, n, j + 1)) for j in range(n)]
    top = [((prefix, i + 1, n), (prefix, i, n)) for i in range(n)]
    left = [((prefix, 0, j + 1), (prefix, 0, j)) for j in range(n)]
    return bottom, right, top, left


def quads_file(seed):
    m = Msh(seed)
    square_nodes(m)
    square_nodes(m, 2, 2.0, "o")
    m.names = [(1, 10, "clamped"), (1, 11, "xmin"), (2, 1, "membrane"), (2, 2, "other")]
    all_s = [("s", i, j) for j in range(N + 1) for i in range(N + 1)]
    bottom, right, top, left = side_lines("s")
    mid = [(("s", N // 2, j), ("s", N // 2, j + 1)) for j in range(N)]
    m.entity(1, 1, [10], [k for e in bottom for k in e])
    m.entity(1, 2, [10], [k for e in right for k in e])
    m.entity(1, 3, [10], [k for e in top for k in e])
    m.entity(1, 4, [10, 11], [k for e in left for k in e])
    m.entity(1, 5, [], [k for e in mid for k in e])
    m.entity(2, 1, [1], [k for k in all_s if k[1] <= N // 2])
    m.entity(2, 2, [1], [k for k in all_s if k[1] >= N // 2])
    m.entity(2, 3, [2], [("o", i, j) for j in range(3) for i in range(3)])
    for ent, lst in ((1, bottom), (2, right), (3, top), (4, left), (5, mid)):
        m.block(1, ent, 1, [list(e) for e in lst])
    for ent, irange in ((1, range(0, N // 2)), (2, range(N // 2, N))):
        els = []
        for j in range(N):
            for i in irange:
                a, b, c, d = ("s", i, j), ("s", i + 1, j), ("s", i + 1, j + 1), ("s", i, j + 1)
                # Rotate the start node: any cyclic rotation keeps the orientation.
                q = [a, b, c, d]
                r = (i + 2 * j) % 4
                els.append(q[r:] + q[:r])
        m.block(2, ent, 3, els)
    els = []
    for j in range(2):
        for i in range(2):
            els.append([("o", i, j), ("o", i + 1, j), ("o", i + 1, j + 1), ("o", i, j + 1)])
    m.block(2, 3, 3, els)
    return m


def tris_file(seed, line_type=1, bad_triangle=False):
    m = Msh(seed)
    square_nodes(m)
    m.names = [(1, 10, "clamped"), (2, 1, "membrane")]
    all_s = [("s", i, j) for j in range(N + 1) for i in range(N + 1)]
    bottom, right, top, left = side_lines("s")
    for t, lst in enumerate((bottom, right, top, left), start=1):
        m.entity(1, t, [10], [k for e in lst for k in e])
    m.entity(2, 1, [1], all_s)
    for t, lst in enumerate((bottom, right, top, left), start=1):
        if line_type == 1:
            m.block(1, t, 1, [list(e) for e in lst])
        else:
            # 3-node lines: end nodes then a (fake) middle node; the reader must reject the type.
            m.block(1, t, 8, [list(e) + [e[0]] for e in lst], first_tag=88 if t == 1 else None)
    els = []
    for j in range(N):
        for i in range(N):
            a, b, c, d = ("s", i, j), ("s", i + 1, j), ("s", i + 1, j + 1), ("s", i, j + 1)
            if (i + j) % 2 == 0:
                els += [[a, b, c], [a, c, d]]
            else:
                els += [[a, b, d], [b, c, d]]
    if bad_triangle:
        m.block(2, 1, 2, els[1:])
        e = els[0]
        m.block(2, 1, 9, [e + e], first_tag=77)  # 6 nodes (repeated: only the type matters)
    else:
        m.block(2, 1, 2, els)
    return m


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "tests", "data",
                                                             "meshes")
    os.makedirs(out, exist_ok=True)
    text = quads_file(11).write(os.path.join(out, "membrane_square_quads.msh"))
    tris_file(12).write(os.path.join(out, "membrane_square_tris.msh"))
    tris_file(13, bad_triangle=True).write(os.path.join(out, "membrane_bad_type.msh"))
    tris_file(14, line_type=8).write(os.path.join(out, "membrane_bad_line.msh"))
    quads_file(15).write(os.path.join(out, "membrane_bad_node.msh"), node_tag_override={5: 999})
    # Cut after the first two tokens (tag and one node) of an element line in mid-$Elements.
    start = text.index("$Elements")
    cut = text.index("\n", start + len(text[start:]) // 2) + 1
    partial = " ".join(text[cut:].split("\n", 1)[0].split()[:2])
    with open(os.path.join(out, "membrane_bad_truncated.msh"), "w") as f:
        f.write(text[:cut] + partial + "\n")
    print("wrote membrane fixtures to", os.path.abspath(out))


if __name__ == "__main__":
    main()
