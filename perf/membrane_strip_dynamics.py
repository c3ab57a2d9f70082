#!/usr/bin/python3
"""Membrane dynamics against an independent solver: a strip clamped at x = 0 and 1 (E = 250, nu = 0,
h = 0.002, rho = 500: the flexible cavity's membrane), at rest, loaded at t = 0 by a uniform follower
pressure of 0.1 Pa, no damping. Ours: `mfsi run` of a membrane-only scene (32 quads, lumped mass,
Newmark, dt = 0.002). Reference: a nonlinear string of the same 32 St. Venant-Kirchhoff elements with
lumped masses, integrated by explicit central differences at dt = 2e-5. Prints the mid-point
deflection of both every 0.5 s to t = 6 s and the largest difference.

    /usr/bin/python3 perf/membrane_strip_dynamics.py [path/to/mfsi]
"""
import csv
import os
import subprocess
import sys
import tempfile

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MFSI = sys.argv[1] if len(sys.argv) > 1 else os.path.join(REPO, "build", "apps", "mfsi")
E, NU, H, RHO, P, N, T_END = 250.0, 0.0, 0.002, 500.0, 0.1, 32, 6.0

SCENE = f"""name: strip-dynamics
time: {{endTime: {T_END}, dt: 0.002}}
membranes:
  - name: s
    mesh: {{rectangle: {{size: [1.0, 0.05], cells: [{N}, 1]}}}}
    material: {{E: {E}, nu: {NU}, thickness: {H}, density: {RHO}}}
    loads: {{pressure: {P}}}
    analysis: dynamic
    dynamics: {{integrator: newmark, mass: lumped}}
    solver: {{tolerance: 1.0e-10}}
    boundary: {{clamp: [xmin, xmax], motionPlaneNormal: [0, 1, 0]}}
"""


def ours():
    with tempfile.TemporaryDirectory() as d:
        scene = os.path.join(d, "strip.yaml")
        with open(scene, "w") as f:
            f.write(SCENE)
        env = dict(os.environ, OMP_PROC_BIND="false")
        subprocess.run([MFSI, "run", scene, "--out", os.path.join(d, "out"), "--threads", "1"], check=True,
                       stdout=subprocess.DEVNULL, env=env)
        rows = list(csv.DictReader(open(os.path.join(d, "out", "steps.csv"))))
    return {round(float(r["time"]), 3): float(r["membrane.s.centreDeflection"]) for r in rows}


def string_reference(times):
    """Nonlinear string: element tension per unit width h * lambda * S, S = E (lambda^2 - 1) / 2."""
    L0 = 1.0 / N
    x = np.stack([np.linspace(0, 1, N + 1), np.zeros(N + 1)], 1)
    v = np.zeros_like(x)
    m = RHO * H * L0 * np.ones(N + 1)
    m[0] = m[-1] = RHO * H * L0 / 2

    def force(x):
        f = np.zeros_like(x)
        d = x[1:] - x[:-1]
        l = np.linalg.norm(d, axis=1)
        lam = l / L0
        T = H * lam * E * (lam ** 2 - 1) / 2
        t = d / l[:, None]
        f[:-1] += T[:, None] * t
        f[1:] -= T[:, None] * t
        normal = np.stack([-d[:, 1], d[:, 0]], 1)  # follower pressure on the current element
        f[:-1] += 0.5 * P * normal
        f[1:] += 0.5 * P * normal
        return f

    dt, t, out = 2e-5, 0.0, {}
    a = force(x) / m[:, None]
    a[0] = a[-1] = 0
    want = sorted(times)
    k = 0
    for step in range(1, int(round(T_END / dt)) + 1):
        v += 0.5 * dt * a
        x += dt * v
        a = force(x) / m[:, None]
        a[0] = a[-1] = 0
        v += 0.5 * dt * a
        t = step * dt
        while k < len(want) and abs(t - want[k]) < dt / 2:
            out[want[k]] = x[N // 2, 1]
            k += 1
    return out


if __name__ == "__main__":
    o = ours()
    times = [round(0.5 * i, 3) for i in range(1, int(T_END / 0.5) + 1)]
    ref = string_reference(times)
    print("# t [s]  mfsi membrane      string (central differences)")
    worst = 0.0
    for t in times:
        print(f"{t:6.2f}  {o[t]: .9f}  {ref[t]: .9f}")
        worst = max(worst, abs(o[t] - ref[t]))
    print(f"# max |difference| = {worst:.2e} m (peak deflection {max(abs(v) for v in ref.values()):.4f} m)")
