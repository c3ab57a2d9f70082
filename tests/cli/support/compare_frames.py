"""Compare two field frames of the same run on different rank counts (used by distributed_run.cmake).

    python3 compare_frames.py ONE.h5 MANY.h5

The same datasets of the same shapes; the mesh's points and topology equal; every other value
within 1e-10 of the largest magnitude of its dataset. Exit 0 same, 1 different, 77 no h5py.
"""
import sys

try:
    import h5py
    import numpy as np
except ImportError:
    print("no h5py/numpy for this interpreter: skipped")
    sys.exit(77)


def datasets(path):
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
    return out


one, many = datasets(sys.argv[1]), datasets(sys.argv[2])
problems = []
if sorted(one) != sorted(many):
    problems.append(f"datasets {sorted(one)} against {sorted(many)}")
for name in sorted(set(one) & set(many)):
    a, b = one[name], many[name]
    if a.shape != b.shape:
        problems.append(f"{name}: shape {a.shape} against {b.shape}")
    elif name.endswith("topology") or name.endswith("points"):
        if not np.array_equal(a, b):
            problems.append(f"{name}: differs")
    else:
        scale = max(float(np.max(np.abs(a))), 1e-300)
        if float(np.max(np.abs(a - b))) > 1e-10 * scale:
            problems.append(f"{name}: differs by {float(np.max(np.abs(a - b)))} (largest {scale})")
print(f"{len(one)} datasets compared")
for p in problems:
    print(p)
sys.exit(1 if problems else 0)
