#!/usr/bin/env python3
"""Small helpers for the OpenFOAM reference scripts of perf/openfoam/ (standard library only).

    foamtools.py instantiate TEMPLATE_DIR CASE_DIR KEY=VALUE ...   copy a case, replacing @KEY@
    foamtools.py set-patch-types CASE_DIR NAME=TYPE ...             edit constant/polyMesh/boundary

The rest is imported by the other scripts: ASCII field / polyMesh readers and a log parser.
"""
import os
import re
import shutil
import statistics
import sys

NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def instantiate(template, case, subs):
    """Copy `template` to `case`, replacing @KEY@ by subs[KEY] in every file; unknown keys are errors."""
    if os.path.exists(case):
        shutil.rmtree(case)
    shutil.copytree(template, case)
    for root, _, files in os.walk(case):
        for name in files:
            path = os.path.join(root, name)
            with open(path) as f:
                text = f.read()
            for k, v in subs.items():
                text = text.replace("@%s@" % k, str(v))
            left = re.findall(r"@[A-Z_0-9]+@", text)
            if left:
                sys.exit("%s: no value for %s" % (path, ", ".join(sorted(set(left)))))
            with open(path, "w") as f:
                f.write(text)


def set_patch_types(case, types):
    """Set the `type` (and drop gmshToFoam's physicalType) of named patches in polyMesh/boundary."""
    path = os.path.join(case, "constant/polyMesh/boundary")
    with open(path) as f:
        text = f.read()
    for name, typ in types.items():
        pat = re.compile(r"(\n\s*%s\s*\{)(.*?)(\})" % re.escape(name), re.S)
        m = pat.search(text)
        if not m:
            sys.exit("%s: no patch %s" % (path, name))
        body = re.sub(r"\n\s*physicalType\s+\w+;", "", m.group(2))
        body = re.sub(r"(\n\s*type\s+)\w+;", r"\g<1>%s;" % typ, body)
        if typ == "wall" and "inGroups" not in body:
            body = body.rstrip() + "\n        inGroups        List<word> 1(wall);\n    "
        text = text[:m.start()] + m.group(1) + body + m.group(3) + text[m.end():]
    with open(path, "w") as f:
        f.write(text)


def _list_after(text, key):
    """The parenthesised list that follows `key` (and an optional count), as a string."""
    i = text.index(key)
    start = text.index("(", i)
    depth = 0
    for j in range(start, len(text)):
        c = text[j]
        if c == "(":
            depth += 1
        elif c == ")":
            depth -= 1
            if depth == 0:
                return text[start + 1:j]
    raise ValueError("unbalanced list after " + key)


def _strip_header(text):
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    i = text.index("FoamFile")
    return text[text.index("}", i) + 1:]


def read_internal_field(path, ncells=None):
    """internalField of an ASCII volScalarField / volVectorField: a list of floats or of 3-tuples."""
    with open(path) as f:
        text = _strip_header(f.read())
    m = re.search(r"internalField\s+uniform\s+(\([^)]*\)|" + NUMBER + ")", text)
    if m:
        v = m.group(1)
        val = tuple(float(x) for x in v.strip("()").split()) if v.startswith("(") else float(v)
        return [val] * (ncells or 1)
    body = _list_after(text, "internalField")
    if "(" in body:
        return [tuple(float(x) for x in t.split()) for t in re.findall(r"\(([^()]*)\)", body)]
    return [float(x) for x in body.split()]


def read_points(case):
    with open(os.path.join(case, "constant/polyMesh/points")) as f:
        body = _list_after(_strip_header(f.read()), "(")
    return [tuple(float(x) for x in t.split()) for t in re.findall(r"\(([^()]*)\)", body)]


def read_faces(case):
    with open(os.path.join(case, "constant/polyMesh/faces")) as f:
        text = _strip_header(f.read())
    return [tuple(int(x) for x in t.split()) for t in re.findall(r"\d+\(([^()]*)\)", text)]


def read_patches(case):
    """{name: (startFace, nFaces)} from polyMesh/boundary."""
    with open(os.path.join(case, "constant/polyMesh/boundary")) as f:
        text = _strip_header(f.read())
    out = {}
    for m in re.finditer(r"(\w+)\s*\{([^}]*)\}", text):
        d = dict(re.findall(r"(\w+)\s+([^;]+);", m.group(2)))
        if "startFace" in d:
            out[m.group(1)] = (int(d["startFace"]), int(d["nFaces"]))
    return out


def face_centre(points, face):
    """Area centroid of a (planar or slightly warped) polygon, by triangle fan about the vertex mean."""
    pts = [points[i] for i in face]
    c0 = [sum(p[k] for p in pts) / len(pts) for k in range(3)]
    acc, atot = [0.0, 0.0, 0.0], 0.0
    for a, b in zip(pts, pts[1:] + pts[:1]):
        u = [a[k] - c0[k] for k in range(3)]
        v = [b[k] - c0[k] for k in range(3)]
        cr = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        area = 0.5 * sum(x * x for x in cr) ** 0.5
        for k in range(3):
            acc[k] += area * (a[k] + b[k] + c0[k]) / 3.0
        atot += area
    return tuple(x / atot for x in acc)


def read_force_y(path, dt):
    """{step index: (total, pressure, viscous) y components} of a `forces` function object's
    force.dat written every step of dt."""
    out = {}
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            t, rest = line.split(None, 1)
            groups = re.findall(r"\(([^()]*)\)", rest)  # (total) (pressure) (viscous)
            if len(groups) != 3:
                raise ValueError("%s: cannot read line %r" % (path, line))
            out[int(round(float(t) / dt))] = tuple(float(re.findall(NUMBER, g)[1]) for g in groups)
    return out


def parse_log(path):
    """Per time step of a solver log: [(time, executionTime, clockTime)] and the last residual lines."""
    steps, t = [], None
    with open(path) as f:
        for line in f:
            m = re.match(r"^Time = (" + NUMBER + ")", line)
            if m:
                t = float(m.group(1))
                continue
            m = re.match(r"^ExecutionTime = (" + NUMBER + r") s\s+ClockTime = (" + NUMBER + ") s", line)
            if m and t is not None:
                steps.append((t, float(m.group(1)), float(m.group(2))))
    return steps


def case_settings(case):
    """The exact numerical settings of a case, for the result files: fvSchemes, fvSolution
    (comments and the FoamFile header dropped, whitespace collapsed) and the controlDict times."""
    out = {}
    for name in ("fvSchemes", "fvSolution"):
        text = _strip_header(open(os.path.join(case, "system", name)).read())
        out[name] = re.sub(r"\s+", " ", text).strip()
    ctrl = _strip_header(open(os.path.join(case, "system/controlDict")).read())
    for key in ("deltaT", "endTime"):
        m = re.search(r"\b%s\s+([^;]+);" % key, ctrl)
        out[key] = m.group(1) if m else None
    return out


def median(xs):
    return statistics.median(xs)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    cmd = sys.argv[1]
    if cmd == "instantiate":
        subs = dict(a.split("=", 1) for a in sys.argv[4:])
        instantiate(sys.argv[2], sys.argv[3], subs)
    elif cmd == "set-patch-types":
        set_patch_types(sys.argv[2], dict(a.split("=", 1) for a in sys.argv[3:]))
    else:
        sys.exit("unknown command " + cmd)


if __name__ == "__main__":
    main()
