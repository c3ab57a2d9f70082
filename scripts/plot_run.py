#!/usr/bin/env python3
"""PNG pictures of an mfsi run folder (what `mfsi plot RUN_DIR` runs):

- steps.csv: the time series against time, one picture per group of quantities: forces and moments
  on patches, force coefficients and pressure drops, probes, membrane displacements, iterations,
  residuals (log scale), energies, wall time per step, and one per module for the rest;
- bodies.csv: position, orientation, velocities and loads of each rigid body;
- fields.xdmf, for a 2D scene (a mesh one cell thick): p and |U| on the cells at the last output,
  with the membranes drawn as lines.

    /usr/bin/python3 scripts/plot_run.py results/cylinder              # PNGs in results/cylinder/plots/
    /usr/bin/python3 scripts/plot_run.py results/cylinder --out /tmp/cyl

Prints the files written, one a line. Needs numpy and matplotlib (Debian: apt-get install
python3-matplotlib); the field picture also needs h5py (python3-h5py) and is left out, with a note,
without it. Exit 0 ok; 2 bad input (not a run folder, nothing to plot) or no matplotlib; 4 a picture
could not be written; 1 internal error.
"""
import argparse
import csv
import json
import math
import os
import re
import sys
import xml.etree.ElementTree as ET

BAD_INPUT, WRITE_FAILED = 2, 4


def fail(message, code=BAD_INPUT):
    print(f"error: {message}", file=sys.stderr)
    sys.exit(code)


def note(message):
    print(f"note: {message}", file=sys.stderr)


# ---------------------------------------------------------------------------------------------
# Reading the run folder (no numpy/matplotlib needed: a wrong folder is reported without them).


def read_csv(path):
    """Header and rows of a CSV file; a row of the wrong length (a run cut short mid-line) is left
    out with a note. Numbers stay strings here."""
    with open(path, newline="") as f:
        lines = [r for r in csv.reader(f) if r]
    if not lines:
        return [], []
    header, rows = lines[0], []
    for n, r in enumerate(lines[1:], start=2):
        if len(r) == len(header):
            rows.append(r)
        else:
            note(f"{path} line {n} has {len(r)} values, the header {len(header)}: left out")
    return header, rows


def to_float(s):
    try:
        return float(s)
    except ValueError:
        return math.nan


def run_info(run):
    """Scene name and status from summary.json (empty when it is missing or unreadable)."""
    try:
        with open(os.path.join(run, "summary.json")) as f:
            s = json.load(f)
        return str(s.get("scene") or ""), str(s.get("status") or "")
    except (OSError, ValueError):
        return "", ""


# ---------------------------------------------------------------------------------------------
# Grouping the columns of steps.csv: <module>.<name>... -> (file, panel, label, log scale)

GROUP_ORDER = ["forces", "coefficients", "probes", "membranes", "energies", "iterations", "residuals"]
GROUP_TITLES = {
    "forces": "forces and moments on patches",
    "coefficients": "coefficients and pressure drops",
    "probes": "probes",
    "membranes": "membrane displacements",
    "energies": "energies",
    "iterations": "iterations",
    "residuals": "residuals",
    "timing": "wall time",
}
COUNTS = {"columns", "cutBacks", "limited"}


def classify(column):
    """(group, panel, label, log) of a steps.csv column."""
    parts = column.split(".")
    module, leaf = parts[0], parts[-1]
    owner = ".".join(parts[:-1])  # module plus patch / membrane name
    place = ".".join(parts[1:-1]) or module
    low = leaf.lower()
    if module == "fluid" and len(parts) >= 3 and parts[1] == "probe":
        name = parts[2]
        if len(parts) == 3:
            return "probes", "pressure at the probes", name, False
        return "probes", f"{leaf} at the probes", name, False
    if re.fullmatch(r"force_[xyz]", leaf):
        return "forces", f"force on {place}", "F" + leaf[-1], False
    if re.fullmatch(r"moment_[xyz]", leaf):
        return "forces", f"moment on {place}", "M" + leaf[-1], False
    if leaf.startswith("c_"):
        return "coefficients", "force coefficients", f"{place} {leaf}", False
    if module == "fluid" and low.startswith("dp"):
        return "coefficients", "pressure drop", leaf, False
    if low.endswith("residual") or leaf == "continuityMax":
        return "residuals", owner, leaf, True
    if low.endswith("iterations") or leaf in COUNTS:
        return "iterations", owner, leaf, False
    if "energy" in low:
        return "energies", owner, leaf, False
    if module == "membrane":
        return "membranes", owner, leaf, False
    return module, column, leaf, False


# ---------------------------------------------------------------------------------------------
# Pictures (numpy and matplotlib are imported in main() once the input is known to be a run).

np = plt = h5py = None


def save(fig, out, name, written):
    """Writes the figure to a temporary name and renames it, so a failed write leaves no
    truncated PNG that looks complete."""
    path = os.path.join(out, name)
    tmp = os.path.join(out, f".{name}.tmp")
    try:
        fig.savefig(tmp, format="png", dpi=110)
        os.replace(tmp, path)
    except OSError as e:
        try:
            os.remove(tmp)
        except OSError:
            pass
        fail(f"cannot write {path}: {e}", WRITE_FAILED)
    finally:
        plt.close(fig)
    written.append(path)


def grid_of(n):
    cols = 1 if n <= 3 else 2
    return (n + cols - 1) // cols, cols


def series_figure(title, x, xlabel, panels):
    """panels: [(panel title, [(label, y)], log)]. Series that are zero throughout are left out
    and named in the panel; a panel with nothing left is dropped. None when nothing is left."""
    kept = []
    for ptitle, series, log in panels:
        shown = [(lab, y) for lab, y in series if not np.all(np.nan_to_num(y) == 0)]
        zero = [lab for lab, y in series if np.all(np.nan_to_num(y) == 0)]
        if shown:
            kept.append((ptitle, shown, zero, log))
    if not kept:
        return None
    rows, cols = grid_of(len(kept))
    fig, axes = plt.subplots(rows, cols, figsize=(7.5 * cols, 2.6 * rows + 0.8), sharex=True, squeeze=False)
    marker = "." if len(x) <= 40 else None
    for ax, (ptitle, shown, zero, log) in zip(axes.flat, kept):
        for lab, y in shown:
            ax.plot(x, y, label=lab, marker=marker, linewidth=1.2)
        if log and np.any(np.concatenate([y for _, y in shown]) > 0):
            ax.set_yscale("log", nonpositive="mask")
        ax.set_title(ptitle + (f"  (zero throughout: {', '.join(zero)})" if zero else ""), fontsize=10)
        ax.grid(True, alpha=0.3)
        if len(shown) > 1 or shown[0][0] != ptitle:
            ax.legend(fontsize=8, ncol=1 + len(shown) // 6)
    for ax in axes.flat[len(kept):]:
        ax.set_visible(False)
    for c in range(cols):  # the lowest panel of each column carries the time axis
        ax = [a for a in axes[:, c] if a.get_visible()][-1]
        ax.set_xlabel(xlabel)
        ax.xaxis.set_tick_params(labelbottom=True)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_steps(header, rows, heading, out, written):
    data = np.array([[to_float(v) for v in r] for r in rows], dtype=float)
    col = {name: data[:, i] for i, name in enumerate(header)}
    x, xlabel = col.get("time"), "time [s]"
    if x is None or np.all(x == x[0]) and len(x) > 1:
        x, xlabel = col.get("step", np.arange(1, len(rows) + 1, dtype=float)), "step"
    groups = {}  # group -> {panel: (log, [(label, y)])}
    for name in header:
        if name in ("step", "time", "wall_s"):
            continue
        group, panel, label, log = classify(name)
        groups.setdefault(group, {}).setdefault(panel, (log, []))[1].append((label, col[name]))
    energies = groups.get("energies", {})
    for panel, (log, series) in energies.items():
        labels = dict(series)
        if "kineticEnergy" in labels and "potentialEnergy" in labels:
            series.append(("total", labels["kineticEnergy"] + labels["potentialEnergy"]))
    if "wall_s" in col:
        wall = col["wall_s"]
        groups["timing"] = {"wall time per step [s]": (False, [("wall time per step", np.diff(wall, prepend=0.0))])}
    order = [g for g in GROUP_ORDER if g in groups] + sorted(g for g in groups if g not in GROUP_ORDER)
    for group in order:
        panels = [(p, s, log) for p, (log, s) in groups[group].items()]
        fig = series_figure(f"{heading}: {GROUP_TITLES.get(group, group)}", x, xlabel, panels)
        if fig is None:
            note(f"{group}: every series is zero throughout; no picture")
            continue
        save(fig, out, f"{group}.png", written)


def plot_bodies(path, heading, out, written):
    header, rows = read_csv(path)
    if "time" not in header or "body" not in header or not rows:
        if header:
            note(f"{path} has no rows: no body pictures")
        return
    ib = header.index("body")
    names = list(dict.fromkeys(r[ib] for r in rows))
    wanted = [("position", ["x", "y", "z"]), ("orientation [rad]", ["roll", "pitch", "yaw"]),
              ("velocity", ["vx", "vy", "vz"]), ("angular velocity", ["wx", "wy", "wz"]),
              ("force", ["Fx", "Fy", "Fz"]), ("moment", ["Mx", "My", "Mz"])]
    for body in names:
        mine = np.array([[to_float(v) for i, v in enumerate(r) if i != ib] for r in rows if r[ib] == body])
        cols = [h for h in header if h != "body"]
        col = {h: mine[:, i] for i, h in enumerate(cols)}
        panels = [(t, [(c, col[c]) for c in cs if c in col], False) for t, cs in wanted]
        panels = [p for p in panels if p[1]]
        fig = series_figure(f"{heading}: body {body}", col["time"], "time [s]", panels)
        if fig is None:
            note(f"body {body}: every series is zero throughout; no picture")
            continue
        safe = re.sub(r"[^A-Za-z0-9_.-]", "_", body)
        save(fig, out, f"body_{safe}.png", written)


# ---------------------------------------------------------------------------------------------
# The field at the last output of a 2D scene.


class Grid:
    """One grid at one time: names of HDF5 datasets ("file.h5", "/mesh/points")."""

    def __init__(self, name, time, topology_type, topology, geometry, attributes):
        self.name, self.time, self.topology_type = name, time, topology_type
        self.topology, self.geometry, self.attributes = topology, geometry, attributes


def _item(base, element):
    item = element.find("DataItem") if element is not None else None
    if item is None or not (item.text or "").strip():
        return None
    file, dataset = item.text.strip().rsplit(":", 1)
    return os.path.join(base, file), dataset


def last_grids_xdmf(path):
    """The last grid of each temporal collection of fields.xdmf."""
    base = os.path.dirname(path)
    domain = ET.parse(path).getroot().find("Domain")
    grids = []
    for top in domain.findall("Grid") if domain is not None else []:
        members = top.findall("Grid") if top.get("GridType") == "Collection" else [top]
        if not members:
            continue
        g = members[-1]
        t = g.find("Time")
        topo = g.find("Topology")
        attributes = {a.get("Name"): (a.get("Center"), _item(base, a)) for a in g.findall("Attribute")}
        grids.append(Grid(g.get("Name") or top.get("Name"), float(t.get("Value")) if t is not None else math.nan,
                          topo.get("TopologyType") if topo is not None else "", _item(base, topo),
                          _item(base, g.find("Geometry")), attributes))
    return grids


def last_grids_h5(folder):
    """Without fields.xdmf: the grids of the newest fields/*.h5; a topology written only with an
    earlier frame is taken from the newest earlier file that holds it."""
    files = sorted(f for f in os.listdir(folder) if f.endswith(".h5"))
    if not files:
        return []
    paths = [os.path.join(folder, f) for f in files]
    grids = []
    with h5py.File(paths[-1], "r") as h:
        names = [n for n in h if isinstance(h[n], h5py.Group) and "points" in h[n]]
        for n in names:
            topo = None
            for p in reversed(paths):
                with h5py.File(p, "r") as e:
                    if f"{n}/topology" in e:
                        topo = (p, f"/{n}/topology")
                        break
            width = h5py.File(topo[0], "r")[topo[1]].shape[-1] if topo else 0
            kind = {8: "Hexahedron", 4: "Quadrilateral", 3: "Triangle"}.get(width, "")
            attributes = {}
            for center, sub in (("Cell", "cell"), ("Node", "point")):
                if sub in h[n]:
                    for a in h[n][sub]:
                        attributes[a] = (center, (paths[-1], f"/{n}/{sub}/{a}"))
            grids.append(Grid(n, math.nan, kind, topo, (paths[-1], f"/{n}/points"), attributes))
    return grids


def read_item(item):
    file, dataset = item
    with h5py.File(file, "r") as h:
        return np.asarray(h[dataset][()])


def thin_axis(points):
    """The axis across which the mesh is one cell thick (every point on one of its two extreme
    planes), the thinnest if several; None for a 3D mesh."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    scale = float(np.max(hi - lo)) or 1.0
    tol = 1e-8 * scale
    thin = [a for a in range(3)
            if np.all((np.abs(points[:, a] - lo[a]) <= tol) | (np.abs(points[:, a] - hi[a]) <= tol))]
    return min(thin, key=lambda a: (hi[a] - lo[a], -a)) if thin else None  # a tie: the last axis (z)


def cell_polygons(points, hexes, axis, plane):
    """The face of each hexahedron on the plane axis = lo, as a counter-clockwise quadrilateral in
    the two other coordinates; cells without four nodes on that plane are left out (mask)."""
    inplane = [a for a in range(3) if a != axis]
    on = np.abs(points[hexes][:, :, axis] - plane) <= 1e-8 * (np.ptp(points, axis=0).max() or 1.0)
    ok = on.sum(axis=1) == 4
    quads = points[hexes[ok][on[ok]].reshape(-1, 4)][:, :, inplane]
    centre = quads.mean(axis=1, keepdims=True)
    angle = np.arctan2(quads[:, :, 1] - centre[:, :, 1], quads[:, :, 0] - centre[:, :, 0])
    order = np.argsort(angle, axis=1)
    return np.take_along_axis(quads, order[:, :, None], axis=1), ok


def membrane_segments(grid, axis):
    """The edges of a membrane's cells projected on the picture plane (edges across the thin
    direction collapse to points and are left out)."""
    inplane = [a for a in range(3) if a != axis]
    pts = read_item(grid.geometry)[:, inplane]
    cells = read_item(grid.topology)
    if cells.ndim == 1:
        return np.zeros((0, 2, 2))
    a = pts[cells]
    b = pts[np.roll(cells, -1, axis=1)]
    seg = np.stack([a, b], axis=2).reshape(-1, 2, 2)
    length = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1)
    return seg[length > 1e-12 * (np.ptp(pts, axis=0).max() or 1.0)]


def plot_field(run, heading, out, written):
    xdmf = os.path.join(run, "fields.xdmf")
    folder = os.path.join(run, "fields")
    if not os.path.isfile(xdmf) and not os.path.isdir(folder):
        return
    global h5py
    try:
        import h5py
    except ImportError:
        note(f"no field picture: the interpreter {sys.executable} has no h5py "
             "(apt-get install python3-h5py)")
        return
    from matplotlib.collections import LineCollection, PolyCollection
    from mpl_toolkits.axes_grid1 import make_axes_locatable

    grids = last_grids_xdmf(xdmf) if os.path.isfile(xdmf) else last_grids_h5(folder)
    volumes = [g for g in grids if g.topology_type == "Hexahedron" and g.topology and g.geometry]
    surfaces = [g for g in grids if g.topology_type in ("Quadrilateral", "Triangle") and g.topology and g.geometry]
    for g in volumes:
        points = read_item(g.geometry)
        axis = thin_axis(points)
        if axis is None:
            note(f"{g.name}: a 3D mesh, no field picture (open {xdmf} in ParaView)")
            continue
        fields = []
        for name, label, cmap in (("p", "p", "coolwarm"), ("U", "|U|", "viridis")):
            center, item = g.attributes.get(name, (None, None))
            if center == "Cell" and item:
                v = read_item(item)
                fields.append((label, np.linalg.norm(v, axis=1) if v.ndim == 2 else v, cmap))
        if not fields:
            note(f"{g.name}: no cell field p or U at the last output; no field picture")
            continue
        quads, ok = cell_polygons(points, read_item(g.topology).astype(np.int64), axis, points[:, axis].min())
        if not np.any(ok):
            note(f"{g.name}: no cell has a face on the plane of the picture; no field picture")
            continue
        lines = [membrane_segments(s, axis) for s in surfaces]
        inplane = [a for a in range(3) if a != axis]
        lo, hi = quads.reshape(-1, 2).min(axis=0), quads.reshape(-1, 2).max(axis=0)
        width, height = max(hi[0] - lo[0], 1e-30), max(hi[1] - lo[1], 1e-30)
        wide = width / height > 1.6
        n = len(fields)
        rows, cols = (n, 1) if wide else (1, n)
        panel_w = 9.0 if wide else 5.5
        panel_h = min(max(panel_w * height / width, 1.2), 9.0) + 0.9
        fig, axes = plt.subplots(rows, cols, figsize=(panel_w * cols + 1.2, panel_h * rows + 0.6), squeeze=False)
        pad = 0.01 * max(width, height)
        for ax, (label, values, cmap) in zip(axes.flat, fields):
            pc = PolyCollection(quads, array=values[ok], cmap=cmap, edgecolors="face", linewidths=0.2)
            ax.add_collection(pc)
            for seg in lines:
                if len(seg):
                    ax.add_collection(LineCollection(seg, colors="black", linewidths=1.8, zorder=3))
            ax.set_xlim(lo[0] - pad, hi[0] + pad)
            ax.set_ylim(lo[1] - pad, hi[1] + pad)
            ax.set_aspect("equal")
            ax.set_xlabel("xyz"[inplane[0]])
            ax.set_ylabel("xyz"[inplane[1]])
            ax.set_title(label, fontsize=10)
            bar = make_axes_locatable(ax).append_axes("right", size="3%", pad=0.1)
            fig.colorbar(pc, cax=bar)
        when = f"t = {g.time:g}" if not math.isnan(g.time) else "last output"
        drawn = " (membranes in black)" if any(len(s) for s in lines) else ""
        fig.suptitle(f"{heading}: {when}{drawn}")
        fig.tight_layout()
        save(fig, out, "field.png" if g.name == "mesh" else f"field_{re.sub(r'[^A-Za-z0-9_.-]', '_', g.name)}.png",
             written)


# ---------------------------------------------------------------------------------------------


def main():
    parser = argparse.ArgumentParser(description="PNG pictures of an mfsi run folder.")
    parser.add_argument("run", metavar="RUN_DIR", help="a folder written by `mfsi run --out RUN_DIR`")
    parser.add_argument("--out", metavar="DIR", help="folder for the PNGs (default: RUN_DIR/plots)")
    args = parser.parse_args()
    run = args.run
    if not os.path.isdir(run):
        fail(f"'{run}' is not a folder")
    steps = os.path.join(run, "steps.csv")
    if not os.path.isfile(steps):
        fail(f"'{run}' is not a run folder: it has no steps.csv (`mfsi run --out DIR` writes one)")

    global np, plt
    try:
        import numpy
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as pyplot
    except ImportError as e:
        fail(f"the Python interpreter {sys.executable} has no {e.name or 'matplotlib'}; install it, e.g. "
             f"apt-get install python3-matplotlib (or {sys.executable} -m pip install matplotlib)")
    np, plt = numpy, pyplot

    header, rows = read_csv(steps)
    scene, status = run_info(run)
    heading = scene or os.path.basename(os.path.normpath(run))
    if status and status != "ok":
        heading += f" (run status: {status})"
    out = args.out or os.path.join(run, "plots")
    bodies = os.path.join(run, "bodies.csv")
    has_fields = os.path.isfile(os.path.join(run, "fields.xdmf")) or os.path.isdir(os.path.join(run, "fields"))
    if not rows:
        what = "is empty" if not header else "has a header but no rows (the run took no time step)"
        if not os.path.isfile(bodies) and not has_fields:
            fail(f"{steps} {what}: nothing to plot")
        note(f"{steps} {what}: no time series")

    written = []
    created = not os.path.isdir(out)
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        fail(f"cannot create {out}: {e}", WRITE_FAILED)
    if rows:
        plot_steps(header, rows, heading, out, written)
    if os.path.isfile(bodies):
        plot_bodies(bodies, heading, out, written)
    if has_fields:
        plot_field(run, heading, out, written)
    if not written:
        if created:
            os.rmdir(out)
        fail(f"nothing to plot in '{run}'")
    for path in written:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
