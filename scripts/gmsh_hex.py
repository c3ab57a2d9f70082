"""Gmsh MSH 4.1 ASCII writer for block-structured all-hex meshes, shared by the mesh scripts
(make_cylinder_mesh.py, tube_mesh.py): 8-node hexahedra (type 5) in the physical volume "fluid" and
boundary quadrangles (type 3), one physical surface and one surface entity per patch, in the layout
core/GmshReader.cpp reads. Standard library only; numpy arrays work as inputs."""
import os


def fmt(v):
    """Shortest round-tripping-enough text of a coordinate, without "-0"."""
    s = "%.9g" % v
    return "0" if s == "-0" else s


def write_hex_msh(path, patches, coords, cells, faces, volume_box, volume_tag):
    """Write `path` (to a temporary name, then renamed: never a truncated mesh under the final name).

    patches: patch names in tag order (tags 1..n); coords: node coordinates; cells: 8 node indices
    per hex (0-based, right-handed); faces: {patch: quads (0-based, outward normals)};
    volume_box: (xmin, ymin, zmin, xmax, ymax, zmax) of the volume entity; volume_tag: its tag."""
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(patches) + 1)]
    out += ['2 %d "%s"' % (t + 1, p) for t, p in enumerate(patches)]
    out += ['3 %d "fluid"' % volume_tag, "$EndPhysicalNames", "$Entities", "0 0 %d 1" % len(patches)]
    for t, p in enumerate(patches):
        pts = [coords[v] for f in faces[p] for v in f]
        box = [min(c[d] for c in pts) for d in range(3)] + [max(c[d] for c in pts) for d in range(3)]
        out.append("%d %s 1 %d 0" % (t + 1, " ".join(fmt(b) for b in box), t + 1))
    out.append("1 %s 1 %d %d %s" % (" ".join(fmt(b) for b in volume_box), volume_tag, len(patches),
                                    " ".join(str(t + 1) for t in range(len(patches)))))
    nn = len(coords)
    out += ["$EndEntities", "$Nodes", "1 %d 1 %d" % (nn, nn), "3 1 0 %d" % nn]
    out += [str(i + 1) for i in range(nn)]
    out += ["%s %s %s" % (fmt(x), fmt(y), fmt(z)) for x, y, z in coords]
    n_elem = len(cells) + sum(len(faces[p]) for p in patches)
    out += ["$EndNodes", "$Elements", "%d %d 1 %d" % (len(patches) + 1, n_elem, n_elem)]
    tag = 0
    out.append("3 1 5 %d" % len(cells))
    for c in cells:
        tag += 1
        out.append("%d %s" % (tag, " ".join(str(v + 1) for v in c)))
    for t, p in enumerate(patches):
        out.append("2 %d 3 %d" % (t + 1, len(faces[p])))
        for f in faces[p]:
            tag += 1
            out.append("%d %s" % (tag, " ".join(str(v + 1) for v in f)))
    out.append("$EndElements")
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        fh.write("\n".join(out) + "\n")
    os.replace(tmp, path)
