#!/usr/bin/python3
"""An independent coupled solution of the flexible-bottom cavity (cases/flexible-cavity.yaml), to check
the FSI answer and the published first peak with code that shares nothing with mfsi:

  fluid      OpenFOAM v1912 pimpleFoam on the moving mesh, the bottom's nodes prescribed
             (flexible_cavity_fluid.py --bottom membrane: the same case as the fluid comparisons);
  structure  the membrane as a nonlinear string of N St. Venant-Kirchhoff elements (E h = 0.5 N/m,
             rho_s h = 1 kg/m^2, clamped ends), lumped masses, explicit central differences at
             dt / SUBSTEPS, loaded by the wall pressure of the bottom row of cells (OpenFOAM's
             zero-gradient wall value) as a follower load, the step's end value throughout a step;
  coupling   implicit, window by window (by default a window is one step): within a window the
             bottom's trajectory at the step times is the unknown; OpenFOAM is run from t = 0 over the
             converged past and the window's iterate (it has no restart on a moving mesh), the string
             from t = 0 on the resulting pressures, and IQN-ILS updates the trajectory until the
             residual (the norm of the trajectory's change over the norm of the trajectory, or of
             FLOOR metres per unknown if that is larger) is below TOL. Longer windows (waveform
             iteration) stall: the fluid's stiff response to the wall's velocity makes the map's
             Jacobian over many steps badly conditioned. Viscous traction is left out (0.07 % of
             the first peak in mfsi).

    /usr/bin/python3 flexible_cavity_coupled.py WORK [--end T] [--dt DT] [--window W] [--tol TOL] [--floor F]
                     [--start MOTION.json | --start MFSI_RUN_DIR] [--verbose]

Prints, per window, the iterations and the mid-point displacement; writes WORK/coupled.csv (t, mid-point
vertical displacement). The OpenFOAM environment must be set (foam_env.sh). A --start trajectory (the
JSON of flexible_cavity_fluid.py --motion, or an mfsi run) only seeds each window's first iterate.
About 35 minutes on one core for 12 s.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

import numpy as np

import foamtools

HERE = os.path.dirname(os.path.abspath(__file__))
GEN = os.path.join(HERE, "flexible_cavity_fluid.py")
N, DEPTH = 32, 0.05
E, H, RHO = 250.0, 0.002, 500.0
SUBSTEPS = 100
X0 = np.linspace(0, 1, N + 1)


def run_fluid(work, disp, dt, n_steps, outer):
    """OpenFOAM over steps 1..n_steps with the bottom displacements disp (n_steps + 1, N + 1, 2) ->
    bottom-row pressure (n_steps + 1, N)."""
    case = os.path.join(work, "case")
    shutil.rmtree(case, ignore_errors=True)
    t_end = n_steps * dt
    pts = [[X0[i], 0.0, z] for z in (0.0, DEPTH) for i in range(N + 1)]
    motion = {"points": pts, "times": [k * dt for k in range(n_steps + 1)],
              "displacements": [[[disp[k, i, 0], disp[k, i, 1], 0.0] for _ in (0, 1) for i in range(N + 1)]
                                for k in range(n_steps + 1)]}
    with open(os.path.join(work, "motion.json"), "w") as f:
        json.dump(motion, f)
    subprocess.run([sys.executable, GEN, str(N), repr(t_end), "--bottom", "membrane", "--dt", repr(dt),
                    "--motion", os.path.join(work, "motion.json"), "--case", case], check=True)
    edits = [("system/controlDict", "writeInterval 100000;", "writeInterval 1;"),
             ("system/fvSolution", "nOuterCorrectors 10;", "nOuterCorrectors %d;" % outer),
             # the momentum solver: symmetric Gauss-Seidel diverges on some far iterates; BiCGStab does not
             ("system/fvSolution", "solver smoothSolver; smoother symGaussSeidel;",
              "solver PBiCGStab; preconditioner DILU;")]
    for rel, old, new in edits:
        path = os.path.join(case, rel)
        text = open(path).read()
        if old not in text:
            sys.exit("%s: no %r" % (path, old))
        with open(path, "w") as f:
            f.write(text.replace(old, new))
    for tool in ("blockMesh", "pimpleFoam"):
        with open(os.path.join(case, "log." + tool), "w") as log:
            done = subprocess.run([tool], cwd=case, stdout=log, stderr=subprocess.STDOUT)
        if done.returncode != 0:
            return None
    p = np.zeros((n_steps + 1, N))
    for k in range(1, n_steps + 1):  # the bottom row: cells 0..N-1
        p[k] = foamtools.read_internal_field(os.path.join(case, "%.8g" % (k * dt), "p"))[:N]
    return p


def run_string(p, dt):
    """The string from rest under the pressures p -> displacements at the steps. Step k to k + 1 takes
    the fluid's pressure of k + 1 throughout (the fluid's implicit answer for that step): with the
    pressure linear in time instead, the fluid's stiff response to the wall's velocity (a dashpot)
    is integrated by the trapezoidal rule, which leaves a step-to-step sawtooth undamped, and the
    coupled run oscillates from t = 1.2 s."""
    L0 = 1.0 / N
    x = np.stack([X0.copy(), np.zeros(N + 1)], 1)
    v = np.zeros_like(x)
    a = np.zeros_like(x)
    m = RHO * H * L0 * np.ones(N + 1)
    m[0] = m[-1] = RHO * H * L0 / 2

    def accel(x, pe):
        f = np.zeros_like(x)
        d = x[1:] - x[:-1]
        lam = np.linalg.norm(d, axis=1) / L0
        tension = H * lam * E * (lam ** 2 - 1) / 2
        t = d / (lam * L0)[:, None]
        f[:-1] += tension[:, None] * t
        f[1:] -= tension[:, None] * t
        load = -pe[:, None] * np.stack([-d[:, 1], d[:, 0]], 1)  # pressure on the fluid side (above)
        f[:-1] += 0.5 * load
        f[1:] += 0.5 * load
        acc = f / m[:, None]
        acc[0] = acc[-1] = 0
        return acc

    h = dt / SUBSTEPS
    out = np.zeros((len(p), N + 1, 2))
    for k in range(len(p) - 1):
        for j in range(1, SUBSTEPS + 1):
            v += 0.5 * h * a
            x += h * v
            a = accel(x, p[k + 1])
            v += 0.5 * h * a
        out[k + 1, :, 0] = x[:, 0] - X0
        out[k + 1, :, 1] = x[:, 1]
    return out


def motion_from_mfsi(run, dt, out):
    """The membrane's node displacements of an mfsi run (fields/fields_<step>.h5, one per step) as the
    JSON of flexible_cavity_fluid.py --motion; returns its path."""
    import glob
    import h5py
    files = sorted(glob.glob(os.path.join(run, "fields", "fields_*.h5")))
    if not files:
        sys.exit("%s: no field frames (run with --set output.fields.everySteps=1)" % run)
    ref, times, disps = None, [0.0], []
    for k, name in enumerate(files, start=1):
        if int(os.path.basename(name)[len("fields_"):-len(".h5")]) != k:
            sys.exit("%s: expected the frame of step %d" % (name, k))
        with h5py.File(name, "r") as f:
            d = f["membrane.bottom/point/displacement"][...]
            x = f["membrane.bottom/points"][...]
        if ref is None:
            ref = x - d
            disps.append(np.zeros_like(ref).tolist())
        times.append(k * dt)
        disps.append(d.tolist())
    with open(out, "w") as f:
        json.dump({"points": ref.tolist(), "times": times, "displacements": disps}, f)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("work")
    ap.add_argument("--end", type=float, default=10.0)
    ap.add_argument("--dt", type=float, default=0.1)
    ap.add_argument("--window", type=float, default=0.1)
    ap.add_argument("--tol", type=float, default=1e-4)
    ap.add_argument("--outer", type=int, default=30, help="PIMPLE outer correctors per step")
    ap.add_argument("--max-iter", type=int, default=60)
    ap.add_argument("--floor", type=float, default=0.01,
                    help="displacement [m] below which the residual is measured against this scale, not the iterate")
    ap.add_argument("--max-cols", type=int, default=15, help="IQN-ILS columns kept (the newest)")
    ap.add_argument("--start", help="trajectory seeding each window's first iterate: a --motion JSON, or an "
                    "mfsi run directory with a field frame every step")
    ap.add_argument("--verbose", action="store_true", help="print every iteration's residual")
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    dt = args.dt
    n_total = int(round(args.end / dt))
    per_window = int(round(args.window / dt))
    disp = np.zeros((n_total + 1, N + 1, 2))
    if args.start and os.path.isdir(args.start):  # an mfsi run with a field frame every step
        args.start = motion_from_mfsi(args.start, dt, os.path.join(args.work, "start.json"))
    if args.start:
        motion = json.load(open(args.start))
        pts = np.array(motion["points"])
        row = np.where(pts[:, 2] < 1e-9)[0]
        row = row[np.argsort(pts[row, 0])]
        seed = np.array(motion["displacements"])[:, row, :2]
        seeded = min(len(seed), n_total + 1)
        if np.abs(np.array(motion["times"])[:seeded] - dt * np.arange(seeded)).max() > 1e-9:
            sys.exit("%s: its times are not the steps of dt = %g" % (args.start, dt))
        disp[:seeded] = seed[:seeded]
    else:
        seeded = 1
    k0 = 0
    total_its = 0
    worst = 0.0
    while k0 < n_total:
        k1 = min(k0 + per_window, n_total)
        window = slice(k0 + 1, k1 + 1)
        if k0 > 0:  # past the seed: extrapolate the last converged velocity
            for k in range(max(k0 + 1, seeded), k1 + 1):
                disp[k] = disp[k0] + (k - k0) * (disp[k0] - disp[k0 - 1])
        V, W = [], []
        r_prev = xt_prev = None
        xk = disp[window, 1:-1].ravel().copy()
        x_good = None
        best = (np.inf, None)
        for it in range(1, args.max_iter + 1):
            disp[window, 1:-1] = xk.reshape(k1 - k0, N - 1, 2)
            p = run_fluid(args.work, disp[: k1 + 1], dt, k1, args.outer)
            if p is None:  # an iterate too far for the fluid: half way back, history restarted
                if x_good is None:
                    sys.exit("window %g-%g s, iteration %d: pimpleFoam failed (%s/case/log.pimpleFoam)"
                             % (k0 * dt, k1 * dt, it, args.work))
                xk = 0.5 * (xk + x_good)
                V, W, r_prev, xt_prev = [], [], None, None
                print("  iteration %d: pimpleFoam failed; half way back" % it, flush=True)
                continue
            x_good = xk.copy()
            xt = run_string(p, dt)[window, 1:-1].ravel()
            r = xt - xk
            res = np.linalg.norm(r) / max(np.linalg.norm(xt), args.floor * np.sqrt(len(xt)), 1e-12)
            if args.verbose:
                mid = np.concatenate([disp[: k0 + 1, N // 2, 1], xt.reshape(k1 - k0, N - 1, 2)[:, N // 2 - 1, 1]])
                print("  iteration %d: residual %.2e, mid-point max %.5f at %g s" % (it, res, mid.max(), mid.argmax() * dt),
                      flush=True)
            if res < best[0]:
                best = (res, xt.copy())
            if res < args.tol:
                disp[window, 1:-1] = xt.reshape(k1 - k0, N - 1, 2)
                break
            if r_prev is not None:
                V.insert(0, r - r_prev)
                W.insert(0, xt - xt_prev)
                del V[args.max_cols:], W[args.max_cols:]
            r_prev, xt_prev = r, xt
            if V:  # least squares over all kept columns (a QR filter that drops columns stalls here)
                alpha = np.linalg.lstsq(np.array(V).T, -r, rcond=1e-10)[0]
                xk = xt + np.array(W).T @ alpha
            else:
                xk = xk + 0.1 * r
        else:  # keep the best iterate, say so, and go on: the caller sees the residual
            res = best[0]
            disp[window, 1:-1] = best[1].reshape(k1 - k0, N - 1, 2)
            print("window %g-%g s: NOT converged in %d iterations; best residual %.2e kept"
                  % (k0 * dt, k1 * dt, args.max_iter, res), flush=True)
            worst = max(worst, res)
        total_its += it
        mid = disp[: k1 + 1, N // 2, 1]
        print("window %5.2f-%5.2f s: %2d iterations (residual %.1e), mid-point %.5f at %g s, max so far %.5f at %g s"
              % (k0 * dt, k1 * dt, it, res, mid[k1], k1 * dt, mid.max(), mid.argmax() * dt), flush=True)
        k0 = k1
    with open(os.path.join(args.work, "coupled.csv"), "w") as f:
        f.write("t_s,midpoint_dy\n")
        for k in range(n_total + 1):
            f.write("%.10g,%.10g\n" % (k * dt, disp[k, N // 2, 1]))
    print("total %d fluid runs; first peak %.5f at %g s%s" % (
        total_its, disp[:, N // 2, 1].max(), disp[:, N // 2, 1].argmax() * dt,
        "; NOT CONVERGED (worst window residual %.2e)" % worst if worst else ""))
    return 1 if worst else 0


if __name__ == "__main__":
    sys.exit(main())
