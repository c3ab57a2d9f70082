#!/usr/bin/env python3
"""mfsi study: what accuracy costs in time.

Runs a scene over a grid of settings, each run an ordinary `mfsi run SCENE --set KEY=V ... --out
DIR/runs/<id> --overwrite`, and writes DIR/study.csv (one row per setting), DIR/study.json (the
fits) and PNGs: error against wall time with the Pareto front, and error against each numeric
varied key with the observed order. Normally started by `mfsi study` (apps/Study.cpp), which finds
an interpreter with matplotlib and passes its own executable as --mfsi:

  mfsi study membrane-square --vary membranes.0.mesh.rectangle.cells=[8,8],[16,16],[32,32] \\
      --metric membrane.period --reference exact --jobs 2
  mfsi study cavity --vary mesh.refine=0.5,1,2 --vary fluid.convection=upwind,linear \\
      --metric fluid.ghia_u_max_err --reference 0
  python3 scripts/study.py --self-test          # the fits against synthetic data

Rules (README.md says the same):
- --vary KEY=V1,V2,...: values split at commas outside brackets, so vectors are values:
  cells=[8,8],[16,16]. KEY1+KEY2=V1,V2 sets both keys to each value (a disc's core and rings). Several
  --vary make the product grid. --set KEY=VALUE goes to every run. VALUE@LEVEL gives a value that is
  not a number a resolution level for the fits, counted like cells (larger is finer):
  mesh.file=/tmp/cylinder_coarse.msh@12,meshes/cylinder_medium.msh@24,/tmp/cylinder_fine.msh@48.
- --reference exact: the run's metric <METRIC>_exact (membrane.period -> membrane.period_exact);
  exact:KEY names it (membrane.centreDeflection against exact:membrane.hencky_w0_exact). A number: that
  value (0 for metrics that are errors already, such as fluid.ghia_u_max_err). finest: the run with
  the finest value of the first numeric varied key among the runs that share the other keys' values;
  Richardson extrapolation from the three finest estimates the limit. richardson: that limit is the
  reference, so the finest run has an error of its own (the finest run where no limit fits).
- error = |metric - reference| / |reference| (relative), |metric - reference| when the reference is 0.
- Resolution: a value is numeric when it is a number or a vector of numbers (its largest component:
  cells [32,32,1] -> 32). A key whose last part is dt or deltaT or ends in tol / tolerance is finer
  when smaller (h = value); any other numeric key (cells, refine, core, rings) is finer when larger
  (h = 1 / value). The observed order p is the least-squares slope of log(error) against log(h).
- Resume: each run folder holds study_settings.json (scene, its file's SHA-256, --set and the run's
  settings); a folder whose settings match and whose summary.json says ok, diverged, unconverged
  (a steady run that did not reach its steady state: a row, left out of the fits) or error is not
  run again. The metric and reference are not settings: changing them re-uses every run.
- Exit codes: 0 done (runs that failed, diverged or did not converge are rows), 2 bad input (scene,
  --vary, --set, --reference, a metric no finished run reports, every run refused as bad input), 130 / 143 stopped
  by SIGINT / SIGTERM (running runs stop after their step; what is done is written; a second signal
  kills them), 1 internal error.
"""

import argparse
import csv
import difflib
import hashlib
import io
import itertools
import json
import math
import os
import re
import shutil
import signal
import sys
import time

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2
DONE_STATUSES = ("ok", "diverged", "unconverged", "error")
THRESHOLDS = (1e-2, 1e-3)  # the cheapest run reaching each error is reported
KEY_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z0-9_]+)*$")


class BadInput(Exception):
    """A user error: exit 2 with the message."""


class Stopped(Exception):
    """SIGINT or SIGTERM before any run started."""

    def __init__(self, signum):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def stop_at_once(signum, _frame):
    raise Stopped(signum)


# ---------------------------------------------------------------------------------------------
# Command line: --vary, --set, --reference


def split_values(text):
    """'[4,4],[6,6],8' -> ['[4,4]', '[6,6]', '8']: commas inside brackets belong to a value."""
    values, depth, cur = [], 0, ""
    for ch in text:
        if ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
            if depth < 0:
                raise BadInput(f"unbalanced '{ch}' in '{text}'")
        if ch == "," and depth == 0:
            values.append(cur.strip())
            cur = ""
        else:
            cur += ch
    if depth != 0:
        raise BadInput(f"unbalanced brackets in '{text}'")
    values.append(cur.strip())
    return values


def parse_vary(spec):
    """'KEY=V1,V2' or 'K1+K2=V1,V2' -> (name, [keys], [values], {value: level}). A value may carry its
    resolution level for the fits, VALUE@LEVEL (mesh files: coarse.msh@1,medium.msh@2); then all do."""
    if "=" not in spec:
        raise BadInput(f"--vary '{spec}': expected KEY=V1,V2,... (e.g. --vary mesh.refine=1,2,4)")
    name, text = spec.split("=", 1)
    name = name.strip()
    keys = [k.strip() for k in name.split("+")]
    for k in keys:
        if not KEY_RE.match(k):
            raise BadInput(f"--vary '{spec}': '{k}' is not a scene key (a.b.c)")
    if len(set(keys)) != len(keys):
        raise BadInput(f"--vary '{spec}': a key is given twice")
    values, levels = [], {}
    for v in split_values(text):
        m = re.match(r"^(.*?)\s*@\s*([-+0-9.eE]+)$", v)
        if m:
            try:
                levels[m.group(1)] = float(m.group(2))
            except ValueError:
                raise BadInput(f"--vary '{spec}': '{v}': the level after @ is not a number") from None
            v = m.group(1)
        values.append(v)
    if any(v == "" for v in values):
        raise BadInput(f"--vary '{spec}': an empty value (expected KEY=V1,V2,...)")
    if len(set(values)) != len(values):
        raise BadInput(f"--vary '{spec}': a value is given twice")
    if levels and len(levels) != len(values):
        raise BadInput(f"--vary '{spec}': give every value a level (VALUE@LEVEL) or none")
    return name, keys, values, levels


def parse_set(spec):
    if "=" not in spec or not KEY_RE.match(spec.split("=", 1)[0].strip()):
        raise BadInput(f"--set '{spec}': expected KEY=VALUE")
    return spec.split("=", 1)[0].strip()


def parse_reference(text):
    """exact | exact:KEY | finest | a number -> dict(kind=..., key=..., value=...)."""
    if text == "exact":
        return {"kind": "exact", "key": None}
    if text.startswith("exact:"):
        key = text[len("exact:"):]
        if not KEY_RE.match(key):
            raise BadInput(f"--reference '{text}': expected exact:METRIC_NAME")
        return {"kind": "exact", "key": key}
    if text in ("finest", "richardson"):
        return {"kind": text}
    try:
        value = float(text)
    except ValueError:
        raise BadInput(f"--reference '{text}': expected exact, exact:METRIC, finest, richardson or a number") from None
    if not math.isfinite(value):
        raise BadInput(f"--reference '{text}': not a finite number")
    return {"kind": "value", "value": value}


# ---------------------------------------------------------------------------------------------
# Resolution and fits


def numeric_value(text):
    """A number, or the largest component of a vector of numbers; None otherwise."""
    t = text.strip()
    if t.startswith("[") and t.endswith("]"):
        parts = [p.strip() for p in t[1:-1].split(",")]
        try:
            nums = [float(p) for p in parts if p]
        except ValueError:
            return None
        return max(nums) if nums else None
    try:
        v = float(t)
    except ValueError:
        return None
    return v if math.isfinite(v) else None


def finer_when_smaller(name):
    """dt, deltaT and tolerances are finer when smaller; counts and factors when larger."""
    last = name.split("+")[0].split(".")[-1]
    return last.lower() in ("dt", "deltat") or re.search(r"tol(erance)?$", last, re.IGNORECASE) is not None


def spacing(name, value):
    """h of a numeric setting: the value itself (dt, tolerances) or its inverse (counts, factors)."""
    return value if finer_when_smaller(name) else 1.0 / value


def observed_order(h, err):
    """Least-squares fit log(err) = log(C) + p log(h); returns (p, C). Needs two distinct h."""
    import numpy as np

    x, y = np.log(np.asarray(h, float)), np.log(np.asarray(err, float))
    if len(x) < 2 or np.ptp(x) == 0:
        raise ValueError("an order needs two different resolutions")
    p, logc = np.polyfit(x, y, 1)
    return float(p), float(math.exp(logc))


def richardson(h, f):
    """Richardson extrapolation from three runs (any order of h): the limit f(0) and the order p of
    f(h) = f0 + C h^p, from the three values (generalised to unequal ratios, Celik et al. 2008,
    J. Fluids Eng. 130, 078001). Returns dict(limit, order, ratios) or dict(reason) when the three
    do not converge monotonically."""
    (h1, f1), (h2, f2), (h3, f3) = sorted(zip(h, f))[:3]
    r21, r32 = h2 / h1, h3 / h2
    e21, e32 = f2 - f1, f3 - f2
    if not (r21 > 1 and r32 > 1):
        return {"reason": "the three finest need different resolutions"}
    if e21 == 0 and e32 == 0:
        return {"limit": f1, "order": float("inf"), "ratios": [r21, r32]}
    if e21 == 0 or e32 / e21 <= 0:
        return {"reason": "oscillatory or stalled convergence (the differences change sign)"}
    ratio = e32 / e21
    p = math.log(ratio) / math.log(r21)
    for _ in range(200):  # p = ln|e32/e21 * (r21^p - 1)/(r32^p - 1)| / ln r21, a contraction near the root
        q = math.log((r21**p - 1) / (r32**p - 1)) if p > 0 else 0.0
        new = (math.log(ratio) + q) / math.log(r21)
        if not math.isfinite(new) or new <= 0:
            return {"reason": "no positive order fits the three finest runs"}
        if abs(new - p) < 1e-12:
            p = new
            break
        p = new
    limit = (r21**p * f1 - f2) / (r21**p - 1)
    return {"limit": limit, "order": p, "ratios": [r21, r32]}


def pareto_front(cost, err):
    """Indices of the points no other point beats in both cost and error, by increasing cost."""
    order = sorted(range(len(cost)), key=lambda i: (cost[i], err[i]))
    front, best = [], math.inf
    for i in order:
        if err[i] < best:
            front.append(i)
            best = err[i]
    return front


def predict_wall(numeric, categorical, samples, target):
    """The wall time of a run with settings `target` = (spacings h of the `numeric` keys, {key:
    value}), from `samples` = [(h, settings, wall)] of the runs done: a power law in the spacings
    (log time against log 1/h) times a factor per categorical value (`categorical` = [(key,
    value)], every value of a key but its first: a lumped solver may take 400x Newton's), fitted
    by least squares when there are enough runs, else with the exponents a 2D mesh (cells ~ n^2),
    a time step (steps ~ 1/dt) and a tolerance (iterations ~ its digits: exponent 0) usually have."""
    import numpy as np

    def features(h, settings):
        if None in h:
            return None
        return [1.0] + [-math.log(x) for x in h] + [1.0 if settings.get(n) == v else 0.0 for n, v in categorical]

    fitted = [(features(h, st), w) for h, st, w in samples if features(h, st) is not None]
    goal = features(*target)
    if goal is None or not fitted:
        same = [w for _, st, w in samples if all(st.get(n) == target[1].get(n) for n, _ in categorical)]
        pool = same or [w for _, _, w in samples]
        return sum(pool) / len(pool)
    k = 1 + len(numeric)
    if len(fitted) >= len(goal) + 1:
        coef, *_ = np.linalg.lstsq(np.array([f for f, _ in fitted]), np.log([w for _, w in fitted]), rcond=None)
    else:
        slopes = np.array([0.0 if re.search(r"tol(erance)?$", n.split("+")[0].split(".")[-1], re.IGNORECASE)
                           else 1.0 if finer_when_smaller(n) else 2.0 for n in numeric])
        resid = [(f, math.log(w) - np.dot(f[1:k], slopes)) for f, w in fitted]
        c0 = np.mean([x for f, x in resid if not any(f[k:])] or [x for _, x in resid])
        cat = [np.mean([x - c0 for f, x in resid if f[k + i]] or [0.0]) for i in range(len(categorical))]
        coef = np.concatenate([[c0], slopes, cat])
    return float(math.exp(np.dot(goal, coef)))


def self_test():
    """The fits against synthetic data with known answers; exit 0 when all hold."""
    failures = []

    def check(what, ok):
        print(("ok    " if ok else "FAIL  ") + what)
        if not ok:
            failures.append(what)

    # Second-order errors with a 2 % wobble, as a mesh study gives them.
    n = [8, 16, 32, 64, 128]
    h = [spacing("mesh.blocks.0.cells", v) for v in n]
    err = [0.3 * hi**2 * (1 + 0.02 * math.sin(3 * i)) for i, hi in enumerate(h)]
    p, _ = observed_order(h, err)
    check(f"order from cell counts 8..128 with C h^2 errors: {p:.4f} (2 +- 0.05)", abs(p - 2) <= 0.05)
    dts = [0.01, 0.005, 0.0025]
    p, c = observed_order([spacing("time.dt", v) for v in dts], [4.0 * d**2 for d in dts])
    check(f"order from dt (finer when smaller): {p:.6f}, C {c:.6f} (2, 4)", abs(p - 2) < 1e-9 and abs(c - 4) < 1e-9)
    p, _ = observed_order([1 / 4, 1 / 8, 1 / 16], [0.1, 0.05, 0.025])
    check(f"first order: {p:.6f}", abs(p - 1) < 1e-9)
    check("finer_when_smaller: dt, fsiTol, solver.tolerance yes; cells, refine no",
          finer_when_smaller("time.dt") and finer_when_smaller("coupling.fsiTol")
          and finer_when_smaller("membranes.0.solver.tolerance") and not finer_when_smaller("mesh.refine")
          and not finer_when_smaller("mesh.blocks.0.cells"))
    # Richardson: f = 1 + 0.5 h^2, equal and unequal ratios.
    for hs in ([0.1, 0.05, 0.025], [0.1, 0.06, 0.03], [0.4, 0.1, 0.2]):
        r = richardson(hs, [1 + 0.5 * x**2 for x in hs])
        check(f"Richardson on h = {hs}: limit {r.get('limit')}, order {r.get('order')} (1, 2)",
              "limit" in r and abs(r["limit"] - 1) < 1e-9 and abs(r["order"] - 2) < 1e-6)
    r = richardson([0.1, 0.05, 0.025], [1.1, 0.9, 1.05])
    check("Richardson refuses oscillatory convergence", "reason" in r)
    check("values split outside brackets",
          split_values("[4,4], [6, 6],8") == ["[4,4]", "[6, 6]", "8"] and split_values("upwind") == ["upwind"])
    check("numeric values: vectors by their largest component, words are not",
          numeric_value("[32,32,1]") == 32 and numeric_value("1e-3") == 1e-3 and numeric_value("upwind") is None)
    check("levels of named settings: a.msh@1,b.msh@2",
          parse_vary("mesh.file=a.msh@1, b.msh @ 2") == ("mesh.file", ["mesh.file"], ["a.msh", "b.msh"],
                                                        {"a.msh": 1.0, "b.msh": 2.0}))
    check("Pareto front", pareto_front([1, 2, 3, 4, 5], [0.5, 0.6, 0.1, 0.1, 0.01]) == [0, 2, 4])
    # ETA: a tolerance (numeric) by a method (categorical) as in the hencky solver study, where the
    # lumped method takes ~400x Newton's time: predictions stay with their method's runs.
    tol, cat = ["membranes.0.solver.tolerance"], [("membranes.0.solver.method", "newton")]
    done = [([1e-3], {"membranes.0.solver.method": "lumped"}, 8.0), ([1e-3], {"membranes.0.solver.method": "newton"}, 0.02),
            ([1e-4], {"membranes.0.solver.method": "lumped"}, 16.0)]
    lumped = predict_wall(tol, cat, done, ([1e-6], {"membranes.0.solver.method": "lumped"}))
    newton = predict_wall(tol, cat, done, ([1e-6], {"membranes.0.solver.method": "newton"}))
    check(f"predicted wall times by method: lumped {lumped:.3g} s in [8, 100], newton {newton:.3g} s in [0.01, 0.2]",
          8 <= lumped <= 100 and 0.01 <= newton <= 0.2)
    mesh = ["mesh.refine"]
    done = [([1 / r], {}, 0.1 * r ** 2) for r in (1, 2, 4)]
    w = predict_wall(mesh, [], done, ([1 / 8], {}))
    check(f"predicted wall time of a mesh refinement from t ~ n^2: {w:.4g} s (6.4)", abs(w - 6.4) < 1e-6)
    print("self-test " + ("passed" if not failures else f"FAILED ({len(failures)})"))
    return EXIT_OK if not failures else EXIT_FAILED


# ---------------------------------------------------------------------------------------------
# Files


def write_atomically(path, text):
    """Write through a temporary name and a rename: never a half-written file under `path`."""
    tmp = path + ".part"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def read_json(path):
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def fmt(x):
    if x is None:
        return ""
    if isinstance(x, float):
        return f"{x:.10g}"
    return str(x)


def short(x):
    return "-" if x is None else (f"{x:.4g}" if isinstance(x, float) else str(x))


def hms(seconds):
    s = int(round(seconds))
    return f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}" if s >= 3600 else f"{s // 60}:{s % 60:02d}"


# ---------------------------------------------------------------------------------------------
# The study


class Run:
    """One setting of the grid and what its run left."""

    def __init__(self, settings, folder, rid):
        self.settings = settings  # {vary name: value}
        self.folder = folder
        self.id = rid
        self.status = "pending"
        self.summary = None
        self.cpu_s = None
        self.max_rss_mb = None
        self.process_s = None  # launch to exit: the run's wall time with start-up (MPI, Kokkos) included
        self.exit_code = None
        self.reused = False
        self.pid = None
        self.started = None
        self.values = {}  # filled by evaluate(): metric, reference, error, message

    def label(self):
        return " ".join(f"{k}={v}" for k, v in self.settings.items())


def short_names(names):
    """The last part of each key (core+rings for a disc's two keys); the full keys when two end alike."""
    lasts = ["+".join(k.split(".")[-1] for k in n.split("+")) for n in names]
    return lasts if len(set(lasts)) == len(lasts) else list(names)


def run_ids(names, grid):
    """Folder names from the settings: the short name of each key and the value, made file-safe
    (cells=8x8_convection=upwind); an index when still equal."""
    parts = short_names(names)
    ids = []
    for point in grid:
        pieces = []
        for part, value in zip(parts, point):
            v = value.replace(" ", "").strip("[]").replace(",", "x")
            pieces.append(part + "=" + re.sub(r"[^A-Za-z0-9._+-]", "_", v))
        ids.append("_".join(pieces) or "default")
    seen = {}
    for i, rid in enumerate(ids):
        if ids.count(rid) > 1:
            seen[rid] = seen.get(rid, 0) + 1
            ids[i] = f"{rid}-{seen[rid]}"
    return ids


def check_scene(mfsi, scene, sets):
    """`mfsi check`: the scene loads with the --set values; returns (scene file, scene name)."""
    import subprocess

    args = [mfsi, "check", scene] + [a for s in sets for a in ("--set", s)]
    p = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        msg = (p.stderr.strip() or p.stdout.strip()).removeprefix("error: ")
        raise BadInput(f"scene '{scene}': {msg}")
    m = re.match(r"ok: (.*): scene '([^']*)'", p.stdout)
    if not m:
        return None, os.path.splitext(os.path.basename(scene))[0]
    return m.group(1), m.group(2)


def file_sha256(path):
    if not path:
        return None
    try:
        with open(path, "rb") as f:
            return hashlib.sha256(f.read()).hexdigest()
    except OSError:
        return None


class Study:
    def __init__(self, args):
        self.args = args
        self.mfsi = args.mfsi
        self.scene = args.scene
        self.vary = [parse_vary(v) for v in args.vary]
        if not self.vary:
            raise BadInput("give at least one --vary KEY=V1,V2,...")
        names = [n for n, _, _, _ in self.vary]
        all_keys = [k for _, keys, _, _ in self.vary for k in keys]
        if len(set(all_keys)) != len(all_keys):
            raise BadInput("a key is varied twice: " + ", ".join(sorted({k for k in all_keys if all_keys.count(k) > 1})))
        set_keys = [parse_set(s) for s in args.set]
        both = sorted(set(set_keys) & set(all_keys))
        if both:
            raise BadInput(f"{', '.join(both)}: both --set and --vary")
        if not KEY_RE.match(args.metric or ""):
            raise BadInput(f"--metric '{args.metric}': expected a metric name of summary.json (e.g. membrane.period)")
        self.metric = args.metric
        self.reference = parse_reference(args.reference)
        if args.jobs < 1:
            raise BadInput("--jobs must be at least 1")
        self.names = names
        # Numeric keys: every value a number (or vector of numbers), two of them positive. A run whose
        # value is not positive (an injected bad setting) has no resolution: it is left out of the fits.
        self.levels = {n: levels for n, _, _, levels in self.vary}
        self.numeric = [n for n, _, vals, _ in self.vary
                        if all(self.level(n, v) is not None for v in vals)
                        and len({self.level(n, v) for v in vals if self.level(n, v) > 0}) > 1]
        if self.reference["kind"] in ("finest", "richardson") and not self.numeric:
            raise BadInput(f"--reference {self.reference['kind']} needs a numeric --vary (cells, mesh.refine, "
                           "time.dt, ...) with at least two positive values: its finest value is the reference")
        total = args.threads
        if total is None:
            env = os.environ.get("OMP_NUM_THREADS", "")
            total = int(env) if env.isdigit() and int(env) > 0 else len(os.sched_getaffinity(0))
        self.jobs = args.jobs
        self.threads = max(1, total // self.jobs)
        self.scene_file, self.scene_name = check_scene(self.mfsi, self.scene, args.set)
        self.out = args.out or os.path.join("results", self.scene_name + "-study")
        grid = list(itertools.product(*[vals for _, _, vals, _ in self.vary]))
        ids = run_ids(names, grid)
        self.runs = [Run(dict(zip(names, point)), os.path.join(self.out, "runs", rid), rid)
                     for point, rid in zip(grid, ids)]
        # The scene by its file and contents (`cavity` and `cases/cavity.yaml` are one scene).
        self.record_base = {"scene": os.path.abspath(self.scene_file) if self.scene_file else self.scene,
                            "scene_sha256": file_sha256(self.scene_file), "set": list(args.set)}
        self.stop_signal = 0
        self.kill_sent = False
        self.warned_metric = False
        self.tty = sys.stdout.isatty()
        self.status_shown = False

    # -- runs -------------------------------------------------------------------------------

    def overrides(self, run):
        sets = list(self.args.set)
        for (name, keys, _, _), value in zip(self.vary, run.settings.values()):
            sets += [f"{k}={value}" for k in keys]
        return sets

    def record(self, run):
        return dict(self.record_base, settings=run.settings, overrides=self.overrides(run))

    def reuse(self, run):
        """A run done before for the same settings: read it instead of running it again."""
        rec = read_json(os.path.join(run.folder, "study_settings.json"))
        summary = read_json(os.path.join(run.folder, "summary.json"))
        if rec != self.record(run) or not summary or summary.get("status") not in DONE_STATUSES:
            return False
        usage = read_json(os.path.join(run.folder, "study_rusage.json")) or {}
        run.summary, run.status, run.reused = summary, summary["status"], True
        run.cpu_s, run.max_rss_mb, run.exit_code = usage.get("cpu_s"), usage.get("max_rss_mb"), usage.get("exit_code")
        run.process_s = usage.get("process_s")
        return True

    def launch(self, run):
        os.makedirs(run.folder, exist_ok=True)
        # An earlier summary must not outlive the settings it belongs to (a stop between the two).
        for name in ("summary.json", "study_rusage.json"):
            try:
                os.remove(os.path.join(run.folder, name))
            except FileNotFoundError:
                pass
        write_atomically(os.path.join(run.folder, "study_settings.json"), json.dumps(self.record(run), indent=2) + "\n")
        argv = [self.mfsi, "run", self.scene] + [a for s in self.overrides(run) for a in ("--set", s)]
        argv += ["--out", run.folder, "--overwrite", "--threads", str(self.threads)]
        env = dict(os.environ)
        if self.jobs > 1:
            env["OMP_PROC_BIND"] = "false"  # runs side by side must not pin their threads to the same cores
        log = os.path.join(run.folder, "run.log")
        actions = [(os.POSIX_SPAWN_OPEN, 1, log, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644),
                   (os.POSIX_SPAWN_DUP2, 1, 2)]
        # Its own session: a Ctrl-C reaches the study only, which passes exactly one SIGINT on (a
        # second one makes `mfsi run` stop at once instead of after its step).
        run.pid = os.posix_spawn(self.mfsi, argv, env, file_actions=actions, setsid=True,
                                 setsigdef=(signal.SIGINT, signal.SIGTERM))
        run.started = time.monotonic()
        run.status = "running"
        if self.stop_signal:  # the signal came while it was being started: it missed the one passed on
            os.killpg(run.pid, self.stop_signal)

    def reap(self, run):
        """Whether the run has ended; if so reads its summary and CPU time."""
        pid, status, usage = os.wait4(run.pid, os.WNOHANG)
        if pid == 0:
            return False
        run.pid = None
        run.process_s = time.monotonic() - run.started
        run.exit_code = os.waitstatus_to_exitcode(status)
        run.cpu_s = usage.ru_utime + usage.ru_stime
        run.max_rss_mb = usage.ru_maxrss / 1024.0
        run.summary = read_json(os.path.join(run.folder, "summary.json"))
        if run.summary and run.summary.get("status"):
            run.status = run.summary["status"]
        elif self.stop_signal:  # stopped by the signal we passed on, before it could write a summary
            run.status = "interrupted"
            run.summary = {"status": "interrupted", "error": f"stopped (exit code {run.exit_code}) before it wrote a summary"}
        else:
            run.status = "error"
            run.summary = {"status": "error", "error": f"no summary.json (exit code {run.exit_code}; see run.log)"}
        if run.status in DONE_STATUSES:
            write_atomically(os.path.join(run.folder, "study_rusage.json"),
                             json.dumps({"cpu_s": run.cpu_s, "process_s": run.process_s, "max_rss_mb": run.max_rss_mb,
                                         "exit_code": run.exit_code}, indent=2) + "\n")
        return True

    def on_signal(self, signum, _frame):
        running = [r for r in self.runs if r.pid]
        if not self.stop_signal:
            self.stop_signal = signum
            self.clear_status()
            print(f"study: {signal.Signals(signum).name}: no new runs; waiting for {len(running)} running run(s) "
                  "to end their step (a second signal kills them)", flush=True)
            for r in running:
                try:
                    os.killpg(r.pid, signum)
                except ProcessLookupError:
                    pass
        elif not self.kill_sent:
            self.kill_sent = True
            self.clear_status()
            print(f"study: killing {len(running)} running run(s)", flush=True)
            for r in running:
                try:
                    os.killpg(r.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass

    def show_status(self, running, pending, done):
        """On a terminal, one line rewritten in place: the runs in progress and the ETA."""
        if not self.tty or not running:
            return
        now = time.monotonic()
        eta = None if self.stop_signal else self.eta(pending, running, done)
        text = ("running " + ", ".join(f"{r.id} ({hms(now - r.started)})" for r in running)
                + ("" if eta is None else f" | ETA {hms(eta)}") + (" | stopping" if self.stop_signal else ""))
        width = max(20, shutil.get_terminal_size().columns - 1)
        sys.stdout.write("\r\033[K" + text[:width])
        sys.stdout.flush()
        self.status_shown = True

    def clear_status(self):
        if self.tty and self.status_shown:
            sys.stdout.write("\r\033[K")
            sys.stdout.flush()
            self.status_shown = False

    def predicted_wall(self, run, done):
        """The time a run is expected to take (predict_wall), from the runs done."""
        walls = [r.process_s or r.summary.get("wall_s") for r in done]  # start-up included: what the study waits
        pts = [(r, w) for r, w in zip(done, walls) if isinstance(w, (int, float)) and w > 0]
        if not pts:
            return None
        categorical = [(n, v) for n, _, vals, _ in self.vary if n not in self.numeric for v in vals[1:]]

        def sample(r):
            return [self.h(r, n) for n in self.numeric], r.settings

        return predict_wall(self.numeric, categorical, [sample(r) + (w,) for r, w in pts], sample(run))

    def eta(self, pending, running, done):
        total = 0.0
        for r in pending:
            w = self.predicted_wall(r, done)
            if w is None:
                return None
            total += w
        now = time.monotonic()
        for r in running:
            w = self.predicted_wall(r, done)
            if w is None:
                return None
            total += max(w - (now - r.started), 0.0)
        return total / self.jobs

    def execute(self):
        todo = [r for r in self.runs if not self.reuse(r)]
        reused = len(self.runs) - len(todo)
        grid = " x ".join(f"{n} ({len(vals)})" for n, _, vals, _ in self.vary)
        print(f"study of {self.scene_name} ({self.scene_file or self.scene}): {len(self.runs)} setting(s) of {grid}; "
              f"{reused} done already (reused), {len(todo)} to run, {self.jobs} at once x {self.threads} thread(s); "
              f"results in {self.out}/", flush=True)
        signal.signal(signal.SIGINT, self.on_signal)
        signal.signal(signal.SIGTERM, self.on_signal)
        pending, running, finished = list(todo), [], 0
        t0 = last_status = time.monotonic()
        while pending or running:
            while pending and len(running) < self.jobs and not self.stop_signal:
                run = pending.pop(0)
                try:
                    self.launch(run)
                except OSError as e:  # a row (run again on resume: it has no summary.json)
                    run.status, run.summary = "error", {"status": "error", "error": f"cannot start {self.mfsi}: {e}"}
                    finished += 1
                    print(f"[{finished}/{len(todo)}] {run.label()}: error: cannot start {self.mfsi}: {e}", flush=True)
                    continue
                running.append(run)
            if self.stop_signal and not running:
                break
            time.sleep(0.05)
            if time.monotonic() - last_status > 1:
                last_status = time.monotonic()
                self.show_status(running, pending, [r for r in self.runs if r.status in DONE_STATUSES])
            for run in list(running):
                if not self.reap(run):
                    continue
                self.clear_status()
                running.remove(run)
                finished += 1
                done = [r for r in self.runs if r.status in DONE_STATUSES]
                self.warn_missing_metric(run)
                eta = self.eta(pending, running, done)
                wall = (run.summary or {}).get("wall_s")
                value = (run.summary.get("metrics") or {}).get(self.metric) if run.summary else None
                print(f"[{finished}/{len(todo)}] {run.label()}: {run.status}"
                      f"{'' if wall is None else f' in {wall:.3g} s'}"
                      f"{'' if run.cpu_s is None else f' (cpu {run.cpu_s:.3g} s)'}"
                      f"{'' if value is None else f', {self.metric} {value:.6g}'}"
                      f" | elapsed {hms(time.monotonic() - t0)}, {len(running) if self.stop_signal else len(pending) + len(running)} left"
                      f"{'' if eta is None or not (pending or running) or self.stop_signal else f', ETA {hms(eta)}'}"
                      f"{', stopping' if self.stop_signal else ''}", flush=True)
        for r in pending:
            r.status = "not run" if self.stop_signal else r.status
        return reused, len(todo)

    def warn_missing_metric(self, run):
        if self.warned_metric or run.status != "ok":
            return
        metrics = run.summary.get("metrics") or {}
        if self.metric not in metrics:
            self.warned_metric = True
            close = difflib.get_close_matches(self.metric, list(metrics), n=3)
            print(f"warning: {run.id} reports no metric '{self.metric}'"
                  + (f" (did you mean {', '.join(close)}?)" if close else "")
                  + "; the runs go on (the table and plots are made from the runs again: Ctrl-C and rerun "
                  "with another --metric keeps every finished run)", flush=True)

    # -- table --------------------------------------------------------------------------------

    def evaluate(self):
        """Metric, reference and error of each run. Returns why the study is bad input (every run
        refused, a metric or exact value no finished run reports), or None."""
        ok = [r for r in self.runs if r.status == "ok"]
        for r in self.runs:
            metrics = (r.summary or {}).get("metrics") or {}
            value = metrics.get(self.metric)
            r.values = {"metric": value if isinstance(value, (int, float)) else None, "reference": None, "error": None,
                        "message": (r.summary or {}).get("error") or ""}
            if r.status == "ok" and r.values["metric"] is None:
                r.values["message"] = f"no metric {self.metric}"
        finished = [r for r in self.runs if r.status in DONE_STATUSES]
        if finished and all(r.status == "error" and r.exit_code == 2 for r in finished):
            return (f"every run was refused as bad input; the first ({finished[0].id}): "
                    f"{finished[0].values['message']}")
        with_metric = [r for r in ok if r.values["metric"] is not None]
        if ok and not with_metric:
            names = sorted(set().union(*[(r.summary.get("metrics") or {}).keys() for r in ok]))
            close = difflib.get_close_matches(self.metric, names, n=3)
            return (f"no run reports the metric '{self.metric}'"
                    + (f"; did you mean {', '.join(close)}?" if close else "")
                    + f" (the runs' metrics: {', '.join(names)})")
        kind = self.reference["kind"]
        if kind == "value":
            for r in with_metric:
                r.values["reference"] = self.reference["value"]
        elif kind == "exact":
            key = self.reference["key"] or self.metric + "_exact"
            for r in with_metric:
                ref = (r.summary.get("metrics") or {}).get(key)
                if isinstance(ref, (int, float)):
                    r.values["reference"] = ref
                else:
                    r.values["message"] = f"no exact value {key}"
            if with_metric and all(r.values["reference"] is None for r in with_metric):
                names = sorted((with_metric[0].summary.get("metrics") or {}).keys())
                hint = [n for n in names if "exact" in n or n.endswith("_w0")] or names
                return (f"--reference exact: no run reports '{key}', the exact value of {self.metric}; name "
                        f"it with --reference exact:METRIC (candidates: {', '.join(hint)})")
        else:  # finest / richardson: per group of the other varied keys, along the resolution key
            key = self.numeric[0]
            for members in self.groups(key, self.resolved(key, with_metric)).values():
                finest = min(members, key=lambda r: self.h(r, key))
                if kind == "richardson":
                    three = sorted(members, key=lambda r: self.h(r, key))[:3]
                    ext = richardson([self.h(r, key) for r in three], [r.values["metric"] for r in three]) \
                        if len(three) == 3 else {"reason": "fewer than three runs"}
                    if "limit" in ext:
                        for r in members:
                            r.values["reference"] = ext["limit"]
                        continue
                    finest.values["message"] = f"the reference (the finest run: no Richardson limit, {ext['reason']})"
                else:
                    finest.values["message"] = "the reference (the finest run)"
                for r in members:
                    r.values["reference"] = finest.values["metric"]
        for r in with_metric:
            ref = r.values["reference"]
            if ref is not None:
                d = abs(r.values["metric"] - ref)
                r.values["error"] = d / abs(ref) if ref != 0 else d
        return None

    def level(self, key, value):
        """The resolution of a value of a varied key: its @LEVEL, else the number it is, else None."""
        levels = self.levels.get(key)
        return levels.get(value) if levels else numeric_value(value)

    def h(self, run, key):
        """The run's spacing along the numeric key `key`; None when its value is not positive."""
        v = self.level(key, run.settings[key])
        return spacing(key, v) if v is not None and v > 0 else None

    def resolved(self, key, runs):
        return [r for r in runs if self.h(r, key) is not None]

    def groups(self, key, runs):
        """Runs by the values of every varied key but `key`."""
        out = {}
        for r in runs:
            out.setdefault(tuple((n, v) for n, v in r.settings.items() if n != key), []).append(r)
        return out

    def columns(self):
        iters, timers = set(), set()
        for r in self.runs:
            if r.summary:
                iters |= {k for k in (r.summary.get("metrics") or {}) if "iterations" in k.lower()}
                timers |= set((r.summary.get("timers") or {}).keys())
        return sorted(iters), sorted(timers)

    def write_csv(self):
        iters, timers = self.columns()
        head = (["id"] + self.names + ["status", "steps", "wall_s", "cpu_s", "process_s", "max_rss_mb", "metric",
                                        "reference", "error"] + iters + ["timer:" + t for t in timers] + ["message"])
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(head)
        for r in self.runs:
            s = r.summary or {}
            m, t = s.get("metrics") or {}, s.get("timers") or {}
            w.writerow([r.id] + [r.settings[n] for n in self.names]
                       + [r.status, fmt(s.get("steps")), fmt(s.get("wall_s", s.get("wallSeconds"))), fmt(r.cpu_s),
                          fmt(r.process_s), fmt(r.max_rss_mb), fmt(r.values.get("metric")), fmt(r.values.get("reference")),
                          fmt(r.values.get("error"))]
                       + [fmt(m.get(k)) for k in iters] + [fmt(t.get(k)) for k in timers]
                       + [r.values.get("message", "")])
        write_atomically(os.path.join(self.out, "study.csv"), buf.getvalue())

    def plotted(self):
        """Runs with a positive error and a wall time: what the plots and fits use."""
        return [r for r in self.runs if r.status == "ok" and r.values.get("error") is not None
                and r.values["error"] > 0 and isinstance((r.summary or {}).get("wall_s"), (int, float))]

    def fits(self):
        orders, extrapolated = [], []
        pts = self.plotted()
        for key in self.numeric:
            for group, members in self.groups(key, self.resolved(key, pts)).items():
                h = [self.h(r, key) for r in members]
                if len(set(h)) < 2:
                    continue
                p, c = observed_order(h, [r.values["error"] for r in members])
                orders.append({"key": key, "series": dict(group), "order": p, "constant": c,
                               "runs": [r.id for r in members]})
        if self.reference["kind"] in ("finest", "richardson"):
            key = self.numeric[0]
            ok = [r for r in self.runs if r.status == "ok" and r.values.get("metric") is not None]
            for group, members in self.groups(key, self.resolved(key, ok)).items():
                members = sorted(members, key=lambda r: self.h(r, key))[:3]
                entry = {"key": key, "series": dict(group), "runs": [r.id for r in members]}
                if len(members) < 3:
                    entry["reason"] = "fewer than three runs"
                else:
                    entry.update(richardson([self.h(r, key) for r in members],
                                            [r.values["metric"] for r in members]))
                    if "limit" in entry and entry["limit"] != 0:
                        entry["finest_error"] = abs(members[0].values["metric"] - entry["limit"]) / abs(entry["limit"])
                extrapolated.append(entry)
        return orders, extrapolated

    def cheapest(self):
        out = []
        pts = [r for r in self.runs if r.status == "ok" and r.values.get("error") is not None
               and isinstance((r.summary or {}).get("wall_s"), (int, float))]
        # The reference runs (finest, or richardson without a limit) have no error of their own.
        pts = [r for r in pts if not r.values["message"].startswith("the reference")]
        for thr in THRESHOLDS:
            good = [r for r in pts if r.values["error"] <= thr]
            best = min(good, key=lambda r: r.summary["wall_s"]) if good else None
            out.append({"error_at_most": thr, "run": best.id if best else None,
                        "settings": best.settings if best else None,
                        "wall_s": best.summary["wall_s"] if best else None,
                        "error": best.values["error"] if best else None})
        return out

    # -- plots --------------------------------------------------------------------------------

    def save(self, fig, name):
        path = os.path.join(self.out, name)
        tmp = path + ".part"
        fig.savefig(tmp, format="png", dpi=110)
        os.replace(tmp, path)
        return path

    def plot(self, orders, extrapolated):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.ticker import FuncFormatter, NullFormatter

        plain = FuncFormatter(lambda v, _: f"{v:g}")

        def plain_ticks(ax):
            """0.05 rather than 5x10^-2; minor ticks labelled too on an axis spanning less than a decade."""
            for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
                axis.set_major_formatter(plain)
                axis.set_minor_formatter(plain if hi < 10 * lo else NullFormatter())
                axis.set_tick_params(which="minor", labelsize=7)

        pts = self.plotted()
        if not pts:
            print("no plots: no run finished ok with a non-zero error", flush=True)
            return []
        files = []
        relative = self.reference["kind"] != "value" or self.reference["value"] != 0
        ref_text = {"exact": "exact value", "finest": "finest run", "richardson": "Richardson limit",
                    "value": "reference value"}[self.reference["kind"]]
        ylabel = f"{'relative ' if relative else ''}error of {self.metric}"

        def label(r, skip=None):
            return ", ".join(v for n, v in r.settings.items() if n != skip)

        # Error against wall time, the Pareto front marked.
        fig, ax = plt.subplots(figsize=(7, 5))
        cost = [r.summary["wall_s"] for r in pts]
        err = [r.values["error"] for r in pts]
        ax.loglog(cost, err, "o", color="tab:blue", label="runs")
        for r, x, y in zip(pts, cost, err):
            ax.annotate(label(r), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
        front = pareto_front(cost, err)
        ax.loglog([cost[i] for i in front], [err[i] for i in front], "-", drawstyle="steps-post", color="tab:red",
                  lw=1.2)
        ax.loglog([cost[i] for i in front], [err[i] for i in front], "o", mfc="none", mec="tab:red", ms=11,
                  label="Pareto front")
        if relative:
            for thr, text in zip(THRESHOLDS, ("1 %", "0.1 %")):
                if not min(err) / 10 <= thr <= max(err) * 10:
                    continue  # far from the runs: it would only squash them
                ax.axhline(thr, color="grey", ls=":", lw=0.8)
                ax.annotate(text, (ax.get_xlim()[0], thr), fontsize=7, color="grey", va="bottom")
        ax.set_xlabel("wall time per run [s]")
        ax.set_ylabel(ylabel)
        ax.set_title(f"{self.scene_name}: error against cost ({ref_text}; label: {', '.join(self.names)})",
                     fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        plain_ticks(ax)
        fig.tight_layout()
        files.append(self.save(fig, "error_vs_wall.png"))
        plt.close(fig)

        # Error against each numeric key, with the observed order of each series.
        for key in self.numeric:
            fig, ax = plt.subplots(figsize=(7, 5))
            series = self.groups(key, self.resolved(key, pts))
            for group, members in series.items():
                members = sorted(members, key=lambda r: self.level(key, r.settings[key]))
                x = [self.level(key, r.settings[key]) for r in members]
                y = [r.values["error"] for r in members]
                fit = next((o for o in orders if o["key"] == key and o["series"] == dict(group)), None)
                name = ", ".join(f"{n.split('.')[-1]}={v}" for n, v in group) or "runs"
                lines = ax.loglog(x, y, "o-", label=name + (f": order {fit['order']:.2f}" if fit else ""))
                if fit:
                    xs = [min(x), max(x)]
                    ax.loglog(xs, [fit["constant"] * spacing(key, v) ** fit["order"] for v in xs], "--",
                              color=lines[0].get_color(), lw=0.8)
            notes = [f"reference: {ref_text}"]
            for e in extrapolated:
                if e["key"] == key and "limit" in e:
                    name = ", ".join(f"{n.split('.')[-1]}={v}" for n, v in e["series"].items())
                    notes.append(f"Richardson limit{' (' + name + ')' if name else ''}: {e['limit']:.8g} "
                                 f"(order {e['order']:.2f})")
            ax.text(0.02, 0.02, "\n".join(notes), transform=ax.transAxes, fontsize=8, va="bottom")
            ax.set_xlabel(key + (" (finer when smaller)" if finer_when_smaller(key) else " (finer when larger)"))
            ax.set_ylabel(ylabel)
            ax.set_title(f"{self.scene_name}: observed order (least squares, dashed)", fontsize=9)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
            plain_ticks(ax)
            ticks = sorted({(self.level(key, r.settings[key]), os.path.basename(r.settings[key]))
                            for r in self.resolved(key, pts)})
            ax.set_xticks([t for t, _ in ticks])  # the settings themselves
            ax.set_xticklabels([text for _, text in ticks])
            ax.xaxis.set_minor_formatter(NullFormatter())
            fig.tight_layout()
            safe = re.sub(r"[^A-Za-z0-9._+-]", "_", short_names(self.names)[self.names.index(key)])
            files.append(self.save(fig, f"error_vs_{safe}.png"))
            plt.close(fig)
        return files

    # -- report -------------------------------------------------------------------------------

    def report(self, reused, ran):
        bad = self.evaluate()
        if bad:
            self.write_csv()  # the runs are done: their table is kept
            raise BadInput(bad + f" (the runs are in {os.path.join(self.out, 'study.csv')}; rerunning reuses them)")
        orders, extrapolated = self.fits()
        cheapest = self.cheapest()
        self.write_csv()
        files = self.plot(orders, extrapolated)
        pts = self.plotted()
        front = pareto_front([r.summary["wall_s"] for r in pts], [r.values["error"] for r in pts]) if pts else []
        statuses = {}
        for r in self.runs:
            statuses[r.status] = statuses.get(r.status, 0) + 1
        summary = {
            "scene": self.scene_name, "scene_file": self.scene_file, "metric": self.metric,
            "reference": self.reference,
            "error": "|metric - reference| / |reference| (|metric - reference| when the reference is 0)",
            "vary": {n: vals for n, _, vals, _ in self.vary},
            "levels": {n: lv for n, lv in self.levels.items() if lv}, "set": list(self.args.set),
            "jobs": self.jobs, "threads_per_run": self.threads, "runs": len(self.runs), "reused": reused, "ran": ran,
            "statuses": statuses, "orders": orders, "richardson": extrapolated, "cheapest": cheapest,
            "pareto_front": [pts[i].id for i in front],
            "files": ["study.csv"] + [os.path.basename(f) for f in files],
        }
        write_atomically(os.path.join(self.out, "study.json"), json.dumps(summary, indent=2) + "\n")

        # The table, the orders, the limit and the cheapest settings.
        head = self.names + ["status", "wall_s", "cpu_s", "metric", "error"]
        rows = [[r.settings[n] for n in self.names]
                + [r.status, short((r.summary or {}).get("wall_s")), short(r.cpu_s), short(r.values.get("metric")),
                   short(r.values.get("error"))] for r in self.runs]
        widths = [max(len(str(x)) for x in col) for col in zip(head, *rows)]
        for row in [head] + rows:
            print("  ".join(str(x).rjust(w) for x, w in zip(row, widths)))
        for o in orders:
            series = ", ".join(f"{n}={v}" for n, v in o["series"].items())
            print(f"observed order along {o['key']}{' (' + series + ')' if series else ''}: {o['order']:.3f} "
                  f"({len(o['runs'])} runs)")
        for e in extrapolated:
            series = ", ".join(f"{n}={v}" for n, v in e["series"].items())
            where = f"{e['key']}{' (' + series + ')' if series else ''}"
            if "limit" in e:
                print(f"Richardson limit of {self.metric} from the three finest of {where}: {e['limit']:.10g} "
                      f"(order {e['order']:.3f}; the finest run is {100 * e.get('finest_error', 0):.3g} % from it)")
            else:
                print(f"no Richardson estimate along {where}: {e['reason']}")
        for c in cheapest if pts else []:
            if c["run"]:
                print(f"cheapest run with error <= {c['error_at_most']:g}: {c['run']} ({c['wall_s']:.3g} s, "
                      f"error {c['error']:.3g})")
            else:
                print(f"no run reaches error <= {c['error_at_most']:g}")
        print(f"wrote {os.path.join(self.out, 'study.csv')}, study.json"
              + "".join(", " + os.path.basename(f) for f in files), flush=True)


def main(argv):
    if sys.version_info < (3, 9):
        print(f"error: study.py needs Python 3.9 or newer, not {sys.version.split()[0]} ({sys.executable}); "
              "name another interpreter in MFSI_PLOT_PYTHON", file=sys.stderr)
        return EXIT_BAD_INPUT
    ap = argparse.ArgumentParser(prog="mfsi study", description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", help="scene file or built-in scene name")
    ap.add_argument("--mfsi", help="the mfsi executable")
    ap.add_argument("--vary", action="append", default=[], help="KEY=V1,V2,... (repeatable: the product grid)")
    ap.add_argument("--set", action="append", default=[], help="KEY=VALUE for every run (repeatable)")
    ap.add_argument("--metric", help="metric of summary.json")
    ap.add_argument("--reference", default="exact", help="exact | exact:KEY | finest | richardson | a number")
    ap.add_argument("--jobs", type=int, default=1, help="runs at once")
    ap.add_argument("--threads", type=int, default=None, help="threads of the whole study (split between the jobs)")
    ap.add_argument("--out", help="study folder (default results/<scene>-study)")
    ap.add_argument("--self-test", action="store_true", help="check the fits on synthetic data and exit")
    args = ap.parse_args(argv)
    if args.self_test:
        return self_test()
    # Until the runs start (Study.execute installs its own handlers), a signal just ends the study.
    signal.signal(signal.SIGINT, stop_at_once)
    signal.signal(signal.SIGTERM, stop_at_once)
    try:
        if not args.scene:
            raise BadInput("give a scene (a file or a built-in scene name)")
        if not args.mfsi or not shutil.which(args.mfsi):
            raise BadInput(f"give the mfsi executable with --mfsi (not found: '{args.mfsi or ''}')")
        args.mfsi = os.path.abspath(shutil.which(args.mfsi))
        if args.threads is not None and args.threads < 1:
            raise BadInput("--threads must be at least 1")
        study = Study(args)
        os.makedirs(study.out, exist_ok=True)
        reused, ran = study.execute()
        study.report(reused, ran)
        if study.stop_signal:
            print(f"stopped by {signal.Signals(study.stop_signal).name}: run the same command again to continue "
                  "(finished runs are kept)", flush=True)
            return 128 + study.stop_signal
        return EXIT_OK
    except BadInput as e:
        print(f"error: {e}", file=sys.stderr, flush=True)
        return EXIT_BAD_INPUT
    except Stopped as e:
        print(f"stopped by {e} before any run started", file=sys.stderr, flush=True)
        return 128 + e.signum
    except ImportError as e:
        print(f"error: {e}: this interpreter ({sys.executable}) needs numpy and matplotlib", file=sys.stderr,
              flush=True)
        return EXIT_BAD_INPUT
    except OSError as e:
        print(f"error: {e}", file=sys.stderr, flush=True)
        return EXIT_FAILED


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
