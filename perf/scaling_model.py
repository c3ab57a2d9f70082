#!/usr/bin/env python3
"""A scaling model of the decomposed fluid (the 3D cube cavity) at 16, 256 and 4,096 ranks, built
from the costs measured on this machine by perf/distributed_fluid.sh and a stated network model.

    perf/scaling_model.py [perf/results/distributed_fluid.txt] [--alpha 2e-6] [--beta 2e9] ...

Measured (the results file's raw lines, the largest mesh measured):
  c      s per cell-step of the decomposed solver, 1 rank x 1 thread (its per-core compute rate);
  E, R, G  halo exchanges, collective reductions and coarse-level gathers per rank per step
         (2 ranks x 1 thread), with the pressure iterations per step they came with;
  b      halo bytes per cut face and side per step, every halo (the cells' and the AMG levels'):
         the bytes of the 2-rank run over twice its METIS edge cut;
  growth of the pressure iterations with the mesh: between the two meshes measured, per 8x cells.
Assumed (flags):
  alpha  latency of one message and of one step of a collective tree (2 us: InfiniBand-class);
  o      injection overhead of each further message of an exchange (0.5 us);
  beta   bandwidth per rank (2 GB/s: a 25 GB/s node link shared by ~12 ranks sending at once);
  k      neighbours of a rank (14, METIS in 3D; P - 1 when fewer);
  cut    faces a rank cuts: 1.2 * 6 * n^(2/3) for n cells (a cube's six faces; METIS cut 1.2x the
         plane in the 2-rank runs);
  coarse levels, as built (the first table): a level with fewer than 800 rows per rank moves onto
         fewer ranks (agglomerateRows), so coarsening goes on to 300 rows on one rank, which solves
         it at c_row s per row and V-cycle (6.7e-8: the AMG-CG iteration on the 64^3 Laplacian,
         perf/distributed_amg.sh), for log8(P) more levels of exchanges per V-cycle and, per
         V-cycle, a gather and a scatter within each group of ranks that merges (together about
         2 ceil(log2 P) tree steps); the second table (agglomerateRows 0): the coarsest level stays
         on every rank at max(300, 4 P) rows (decoupled aggregation leaves 2-8 rows per rank) and
         each V-cycle gathers it onto every rank, which all solve it by its one-process AMG. G is
         the V-cycles per step (measured with the coarsest gathered, one gather per V-cycle);
  share  of the step that grows with the pressure iterations (0.5).
Per rank and step: T = n c f + E f (alpha + (k - 1) o) + b f cut / beta
                      + R (alpha ceil(log2 P) + 16 P / beta)            (sums: an allgather of ~2 doubles)
                      + G f (m alpha ceil(log2 P) + 8 n_c / beta + n_c c_row)   (m: 2 moved, 1 gathered)
with f = its(N) / its(measured) and efficiency = n c f / T (perfect scaling of the measured
per-core rate = 100 %).
Overlap (solvers.pressure.overlapHalo, the last two columns of the first table): each exchange of
the pressure solve runs while its product multiplies the rows that read no ghost. Per pressure
iteration, the CG's product on the finest level and 2 x 2 + 2 = 6 products per level of the V-cycle
(Chebyshev degree 2), on levels of n_l = n / 8^l rows down to 800; an exchange costs
x_l = alpha + (k - 1) o + 8 * 1.2 * 6 n_l^(2/3) / beta and can hide at most the interior rows'
time (1 - 1.2 * 6 n_l^(-1/3)) n_l c_p, with c_p = c_row / 10 s per row and product (an AMG-CG
iteration is about ten products' worth of passes). What it hides is taken off the exchange and
byte terms (never more than they hold). It assumes a network that moves the data while the rank
computes; on one shared-memory node it does not (perf/RESULTS.md: overlap is measured slower there).
"""
import argparse
import math
import re
import sys


def measured(path):
    rows = []
    for line in open(path):
        counters_only = line.startswith("# counters: ")  # timings not to be used, counts valid
        line = line[len("# counters: "):] if counters_only else line
        m = re.match(r"n=(\d+)\^3 cells=(\d+) mode=(\w+) ranks=(\d) threads=(\d) edgecut=(\d+).*\| ([0-9.e+-]+) "
                     r"s/cell-step.*pressure its/step ([0-9.]+)", line)
        if not m:
            continue
        n, cells, mode, ranks, threads, cut, s, its = m.groups()
        row = dict(n=int(n), cells=int(cells), mode=mode, ranks=int(ranks), threads=int(threads), cut=int(cut),
                   s=None if counters_only else float(s), its=float(its))
        c = re.search(r"all halos per step \(all ranks\): ([0-9.]+) messages, ([0-9.]+) bytes; per rank ([0-9.]+) "
                      r"exchanges, ([0-9.]+) reductions, ([0-9.]+) coarse gathers", line)
        if c:
            row.update(halo_bytes=float(c.group(2)), exchanges=float(c.group(3)), reductions=float(c.group(4)),
                       gathers=float(c.group(5)))
        rows.append(row)
    return rows


def hidden(n, k, alpha, o, beta, c_p):
    """Seconds of exchange one pressure iteration can hide behind interior rows (see the docstring)."""
    total, level, nl = 0.0, 0, n
    while nl >= 800:
        x = alpha + (k - 1) * o + 8 * 1.2 * 6 * nl ** (2.0 / 3.0) / beta
        interior = max(0.0, 1 - 1.2 * 6 * nl ** (-1.0 / 3.0)) * nl * c_p
        total += (6 + (1 if level == 0 else 0)) * min(x, interior)
        level, nl = level + 1, nl / 8
    return total


def median(xs):
    xs = sorted(xs)
    return xs[len(xs) // 2] if len(xs) % 2 else 0.5 * (xs[len(xs) // 2 - 1] + xs[len(xs) // 2])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", nargs="?", default="perf/results/distributed_fluid.txt")
    ap.add_argument("--alpha", type=float, default=2e-6)
    ap.add_argument("--o", type=float, default=0.5e-6)
    ap.add_argument("--beta", type=float, default=2e9)
    ap.add_argument("--k", type=int, default=14)
    ap.add_argument("--share", type=float, default=0.5)
    ap.add_argument("--c-row", type=float, default=6.7e-8)
    a = ap.parse_args()

    rows = measured(a.results)
    dist = [r for r in rows if r["mode"] == "distributed"]
    big = max(r["n"] for r in dist)
    small = min(r["n"] for r in dist)
    one = [r for r in dist if r["n"] == big and r["ranks"] == 1 and r["threads"] == 1 and r["s"] is not None]
    two = [r for r in dist if r["n"] == big and r["ranks"] == 2 and r["threads"] == 1 and "exchanges" in r]
    if not one or not two:
        sys.exit("%s: no %d^3 runs of 1 and 2 ranks x 1 thread with counters (run perf/distributed_fluid.sh)"
                 % (a.results, big))
    c = median([r["s"] for r in one])
    its_big = median([r["its"] for r in two])
    its_small = median([r["its"] for r in dist if r["n"] == small and r["ranks"] == 2])
    cells_big, cells_small = two[0]["cells"], small ** 3
    growth = (its_big - its_small) / math.log(cells_big / cells_small, 8) if big != small else 0.0
    E = median([r["exchanges"] for r in two])
    R = median([r["reductions"] for r in two])
    G = median([r["gathers"] for r in two])
    b = median([r["halo_bytes"] for r in two]) / (2 * two[0]["cut"])
    c_row = a.c_row

    print("Measured (%s, %d^3): c = %.3g s/cell-step (decomposed, 1 rank x 1 thread); per rank and step on 2 "
          "ranks: %.0f exchanges, %.0f reductions, %.1f coarse gathers at %.2f pressure iterations; %.0f halo bytes "
          "per cut face and side; pressure iterations +%.2f per 8x cells" % (a.results, big, c, E, R, G, its_big, b,
                                                                           growth))
    print("Assumed: alpha = %g s, o = %g s, beta = %g B/s per rank, k = %d neighbours, share = %.2f\n"
          % (a.alpha, a.o, a.beta, a.k, a.share))
    for built in (True, False):
        print("\n%s\n" % ("As built: coarse levels move onto fewer ranks as they shrink, the coarsest solved on one "
                           "rank:" if built else
                           "Without moving them (agglomerateRows: 0): the coarsest level (about 4 rows per rank) "
                           "gathered onto every rank:"))
        print("| cells | ranks | cells per rank | pressure its/step | compute | exchanges (latency) | halo bytes | "
              "reductions | coarse gathers | modelled s/step | efficiency |" +
              (" overlap hides | efficiency with overlap |" if built else ""))
        print("|---|---|---|---|---|---|---|---|---|---|---|" + ("---|---|" if built else ""))
        for N in (1e6, 1e8):
            its = its_big + growth * math.log(N / cells_big, 8)
            f = 1 + a.share * (its / its_big - 1)
            fc = its / its_big  # communication counts scale with the iterations
            for P in (16, 256, 4096):
                n = N / P
                k = min(a.k, P - 1)
                lg = math.ceil(math.log2(P))
                comp = n * c * f
                extra = 6 * G * math.log(P, 8) if built else 0  # ~6 exchanges per level and V-cycle
                exch = (E * fc + extra * fc) * (a.alpha + (k - 1) * a.o)
                cut = 1.2 * 6 * n ** (2.0 / 3.0)
                byt = b * fc * cut / a.beta
                red = R * fc * (a.alpha * lg + 16 * P / a.beta)
                nc = 300 if built else max(300, 4 * P)
                gat = G * fc * ((2 if built else 1) * a.alpha * lg + 8 * nc / a.beta + nc * c_row)
                total = comp + exch + byt + red + gat
                ms = lambda t: "%.2f ms" % (1e3 * t)
                line = "| %.0e | %d | %.0f | %.1f | %s | %s | %s | %s | %s | %s | **%.0f %%** |" % (
                    N, P, n, its, ms(comp), ms(exch), ms(byt), ms(red), ms(gat), ms(total), 100 * comp / total)
                if built:
                    hide = min(exch + byt, its * hidden(n, k, a.alpha, a.o, a.beta, c_row / 10))
                    line += " %s | **%.0f %%** |" % (ms(hide), 100 * comp / (total - hide))
                print(line)

if __name__ == "__main__":
    main()
