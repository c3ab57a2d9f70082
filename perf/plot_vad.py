#!/usr/bin/env python3
"""The pulsatile VAD's cycle from a run's steps.csv (perf/vad_attempt.sh writes it): a table per
cycle and a figure of the membrane's centre, the pressures, the volume balance, the mesh quality
and the coupling iterations over time.

    /usr/bin/python3 perf/plot_vad.py OUT_DIR [--png FILE] [--period 0.75]

Volumes: the air chamber gains exactly the air port's inflow each step (coupling.chamberVolumeStep,
the inflow integrated over the step) and the membrane sweeps it to the coupling's tolerance
(coupling.chamberVolumeMiss, the largest miss of any iterate); the blood leaves through the inlet
and outlet (fluid.<patch>.flowRate, out of the fluid, integrated by the trapezoidal rule).
"""
import argparse
import csv
import json
import sys

MMHG = 133.322


def read(out):
    rows = list(csv.DictReader(open(out + "/steps.csv")))
    cols = {k: [float(r[k]) for r in rows] for k in rows[0]} if rows else {}
    return cols, json.load(open(out + "/summary.json"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--png", default="")
    ap.add_argument("--period", type=float, default=0.75)
    ap.add_argument("--ejection", type=float, default=0.3)
    a = ap.parse_args()
    c, summary = read(a.out)
    if not c:
        print("no steps in", a.out)
        return 1
    t = c["time"]
    n = len(t)
    dt = t[0] if n == 1 else t[1] - t[0]
    # The volume balance. Air: the chamber's gain, step by step (the inflow's exact integral).
    # Blood: the outflow through the valves, the fluid's flux q_n times the step; under BDF2 (the
    # first step Euler) the flux is the membrane's swept volume (3/2 dV_n - 1/2 dV_n-1) / dt, so
    # the balance per step is q_n dt - (3/2 dV_n - 1/2 dV_n-1), and the running sums agree once
    # half of the last step's dV is taken off the blood's and half of the first step's put back.
    dv = [x * 1e6 for x in c["coupling.chamberVolumeStep"]]  # [mL]
    q = [(c["fluid.bloodInlet.flowRate"][i] + c["fluid.bloodOutlet.flowRate"][i]) * dt * 1e6 for i in range(n)]
    air, blood, balance = [], [], []
    va = vb = 0.0
    for i in range(n):
        va += dv[i]
        vb += q[i]
        swept = dv[i] if i == 0 else 1.5 * dv[i] - 0.5 * dv[i - 1]
        balance.append(q[i] - swept)
        air.append(va)
        blood.append(vb if i == 0 else vb - 0.5 * dv[i] + 0.5 * dv[0])
    p_air = [p / MMHG for p in c["coupling.chamberPressure"]]
    # The blood chamber's volume mean where the blood is the whole fluid (cases/vad.yaml); with the
    # air meshed too (cases/vad-two-chambers.yaml) the pressure at the blood chamber's middle.
    blood_column = "fluid.meanPressure" if "fluid.meanPressure" in c else "fluid.probe.blood"
    blood_mean = blood_column == "fluid.meanPressure"
    blood_label = "blood chamber (volume mean)" if blood_mean else "blood chamber (middle)"
    jump_label = "air − blood mean" if blood_mean else "air − blood (middle)"
    p_blood = [p / MMHG for p in c[blood_column]]
    p_out = [p / MMHG for p in c["fluid.bloodOutlet.pressure"]]
    w_mm = [1000 * w for w in c["membrane.membrane.centreDeflection"]]
    jac = c["coupling.minScaledJacobian"]
    its = c["coupling.iterations"]
    wall = c["wall_s"]

    print("status: %s %s" % (summary["status"], summary.get("error") or ""))
    print("reached t = %.3f s (%d steps of %.4g s), wall %.0f s" % (t[-1], n, dt, summary["wall_s"]))
    print("| cycle | from–to [s] | wall [s] | FSI its/step (max) | min scaled Jacobian | centre [mm] | "
          "outlet p, ejection [mmHg] | " + jump_label + " p [mmHg] | membrane's volume miss [mL] | blood out − swept, per step [mL] | air in − blood out at the end [mL] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    k = 0
    while k * a.period < t[-1] - 1e-9:
        idx = [i for i in range(n) if k * a.period < t[i] <= (k + 1) * a.period + 1e-9]
        if not idx:
            break
        ej = [i for i in idx if (t[i] - k * a.period) <= a.ejection + 1e-9 and (t[i] - k * a.period) > 0.02]
        w0 = wall[idx[0] - 1] if idx[0] > 0 else 0.0
        jump = [p_air[i] - p_blood[i] for i in idx]
        print("| %d | %.3f–%.3f | %.0f | %.2f (%d) | %.3f | %.1f to %.1f | %s | %.1f to %.1f | %.2g | %.2g | %+.2g |" % (
            k + 1, t[idx[0]] - dt, t[idx[-1]], wall[idx[-1]] - w0, sum(its[i] for i in idx) / len(idx),
            max(its[i] for i in idx), min(jac[i] for i in idx), min(w_mm[i] for i in idx), max(w_mm[i] for i in idx),
            ("%.1f to %.1f" % (min(p_out[i] for i in ej), max(p_out[i] for i in ej))) if ej else "—",
            min(jump), max(jump), 1e6 * max(c["coupling.chamberVolumeMiss"][i] for i in idx),
            max(abs(balance[i]) for i in idx), air[idx[-1]] - blood[idx[-1]]))
        k += 1

    if a.png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(3, 2, figsize=(11, 9), sharex=True)
        ax[0][0].plot(t, w_mm)
        ax[0][0].set_ylabel("membrane centre [mm]")
        ax[0][1].plot(t, p_air, label="air chamber")
        ax[0][1].plot(t, p_blood, label=blood_label)
        ax[0][1].plot(t, p_out, label="outlet")
        ax[0][1].set_ylabel("pressure [mmHg]")
        ax[0][1].legend(fontsize=8)
        ax[1][0].plot(t, air, label="air in")
        ax[1][0].plot(t, blood, "--", label="blood out")
        ax[1][0].set_ylabel("volume since t = 0 [mL]")
        ax[1][0].legend(fontsize=8)
        ax[1][1].plot(t, [p_air[i] - p_blood[i] for i in range(n)])
        ax[1][1].set_ylabel(jump_label + " pressure [mmHg]")
        ax[2][0].plot(t, jac)
        ax[2][0].set_ylabel("min scaled Jacobian")
        ax[2][0].set_xlabel("t [s]")
        ax[2][1].plot(t, its, ".", ms=2)
        ax[2][1].set_ylabel("FSI iterations")
        ax[2][1].set_xlabel("t [s]")
        for row in ax:
            for x in row:
                x.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(a.png, dpi=110)
        print("wrote", a.png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
