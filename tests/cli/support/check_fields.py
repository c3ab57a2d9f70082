"""Check a run's fields.xdmf the way a user's reader sees it (used by tests/cli/fields_readers.cmake).

    python3 check_fields.py RUN_DIR EXPECTED_FRAMES [MEMBRANES]

MEMBRANES: how many membrane grids the run has (default 1; 0 for a fluid-only scene).

Always: the XDMF parses; every DataItem names an HDF5 dataset (h5py) whose size matches its
Dimensions; every grid's series has EXPECTED_FRAMES times, increasing; the values are finite.
With ParaView's Python modules (Debian python3-paraview): ParaView's own XDMF reader loads the
file, sees the same times and, at the last one, the mesh with U and p (p's range equal to the HDF5
values) and the membrane's surface with its arrays. Exit 0 ok, 1 failure, 77 nothing to check with.
"""
import math
import os
import sys
import xml.etree.ElementTree as ET

try:
    import h5py
    import numpy as np
except ImportError:
    print("no h5py/numpy for this interpreter: skipped")
    sys.exit(77)

run, expected = sys.argv[1], int(sys.argv[2])
n_membranes = int(sys.argv[3]) if len(sys.argv) > 3 else 1
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)


root = ET.parse(os.path.join(run, "fields.xdmf")).getroot()
series = root.find("Domain").findall("Grid")
names = [g.get("Name") for g in series]
check("mesh" in names and sum(n.startswith("membrane") for n in names) == n_membranes, f"grids {names}")
times = {}
last = {}
for s in series:
    check(s.get("CollectionType") == "Temporal", f"{s.get('Name')}: not a temporal collection")
    ts = [float(g.find("Time").get("Value")) for g in s.findall("Grid")]
    times[s.get("Name")] = ts
    check(len(ts) == expected and all(b > a for a, b in zip(ts, ts[1:])), f"{s.get('Name')}: times {ts}")
    for g in s.findall("Grid"):
        for item in g.iter("DataItem"):
            file, path = item.text.strip().split(":")
            dims = [int(d) for d in item.get("Dimensions").split()]
            with h5py.File(os.path.join(run, file), "r") as h5:
                check(path in h5, f"{file}: no dataset {path}")
                if path in h5:
                    data = h5[path][()]
                    check(data.size == math.prod(dims), f"{file}:{path} has {data.size} values for {dims}")
                    check(np.all(np.isfinite(data)), f"{file}:{path} is not finite")
                    last[(s.get("Name"), path.split("/", 2)[-1])] = data

p = last.get(("mesh", "cell/p"))
check(p is not None and p.size > 0, "no pressure field")

try:
    from paraview.simple import Xdmf3ReaderS, servermanager
except ImportError:
    print(f"h5py + XML checks of {len(series)} grids x {expected} frames; ParaView is absent")
else:
    reader = Xdmf3ReaderS(FileName=[os.path.join(run, "fields.xdmf")])
    reader.UpdatePipelineInformation()
    tv = reader.TimestepValues
    tv = list(tv) if hasattr(tv, "__iter__") else [tv]
    check(np.allclose(tv, times["mesh"], rtol=0, atol=1e-12), f"ParaView's times {tv}, the file's {times['mesh']}")
    reader.UpdatePipeline(max(tv))
    blocks = []

    def walk(b):
        if b is None:
            return
        if b.IsA("vtkDataSet"):
            blocks.append(b)
            return
        pieces = b.IsA("vtkMultiPieceDataSet")
        for i in range(b.GetNumberOfPieces() if pieces else b.GetNumberOfBlocks()):
            walk(b.GetPiece(i) if pieces else b.GetBlock(i))

    walk(servermanager.Fetch(reader))
    meshes = [b for b in blocks if b.GetCellData().GetArray("p") is not None]
    surfaces = [b for b in blocks if b.GetCellData().GetArray("vonMises") is not None]
    check(len(meshes) == 1 and len(surfaces) == n_membranes,
          f"ParaView found {len(meshes)} meshes, {len(surfaces)} membranes")
    if meshes:
        m = meshes[0]
        check(m.GetNumberOfCells() == p.size and m.GetCellType(0) == 12, "ParaView's mesh: cells or type")
        lo, hi = m.GetCellData().GetArray("p").GetRange()
        check(abs(lo - p.min()) < 1e-12 and abs(hi - p.max()) < 1e-12, f"ParaView's p range {lo, hi}")
        check(m.GetCellData().GetArray("U").GetNumberOfComponents() == 3, "ParaView's U is not a vector")
    if surfaces:
        s = surfaces[0]
        check(s.GetCellType(0) == 9 and s.GetPointData().GetArray("displacement") is not None,
              "ParaView's membrane: quads and displacement")
    print(f"ParaView {servermanager.vtkSMProxyManager.GetVersionMajor()}.{servermanager.vtkSMProxyManager.GetVersionMinor()} "
          f"reads {len(blocks)} grids x {len(tv)} frames; h5py + XML checks as well")

for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
