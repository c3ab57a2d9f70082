"""The moved mesh points in a run's checkpoint files (used by distributed_fsi.cmake).

    python3 checkpoint_points.py parts CHECKPOINT.h5 RANKS ONE_RANK_CHECKPOINT.h5
        Each rank's file holds its part's points (/mesh/points, tagged as node rows), none the
        whole mesh's (the one-rank checkpoint's rows), and together they cover it: exit 0, else 1.
    python3 checkpoint_points.py legacy ONE_RANK_CHECKPOINT.h5
        Make it (in place) as the checkpoints written before the parts held their points were: the
        whole mesh's points in the file, untagged.

Exit 77 without h5py/numpy.
"""
import sys

try:
    import h5py
    import numpy as np
except ImportError:
    print("no h5py/numpy for this interpreter: skipped")
    sys.exit(77)


def part_file(main, rank):
    return main if rank == 0 else main[: -len(".h5")] + f".rank{rank}.h5"


def parts(main, ranks, one_rank):
    with h5py.File(one_rank, "r") as f:
        global_nodes = f["mesh/points"].shape[0]
    problems, covered = [], set()
    for r in range(ranks):
        with h5py.File(part_file(main, r), "r") as f:
            if "mesh/points" not in f or "entities/mesh/points" not in f:
                problems.append(f"rank {r}: no tagged /mesh/points")
                continue
            rows = f["mesh/points"].shape[0]
            ids = np.asarray(f["run/part/nodes"][()])
            if rows != len(ids) or rows >= global_nodes:
                problems.append(f"rank {r}: {rows} point rows for {len(ids)} part nodes of {global_nodes}")
            if not np.all(np.isfinite(f["mesh/points"][()])):
                problems.append(f"rank {r}: points not finite")
            covered.update(ids.tolist())
    if len(covered) != global_nodes:
        problems.append(f"the parts cover {len(covered)} of {global_nodes} nodes")
    print("\n".join(problems) if problems else f"{ranks} parts, each with its own points")
    return 1 if problems else 0


def legacy(checkpoint):
    with h5py.File(checkpoint, "r+") as f:
        del f["entities/mesh/points"]
        if len(f["entities/mesh"]) == 0:
            del f["entities/mesh"]
    return 0


if sys.argv[1] == "parts":
    sys.exit(parts(sys.argv[2], int(sys.argv[3]), sys.argv[4]))
sys.exit(legacy(sys.argv[2]))
