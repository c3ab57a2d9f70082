#!/usr/bin/env python3
"""Write the pimpleFoam case of the flexible-bottom cavity's fluid (see flexible_cavity_fluid.sh).

    flexible_cavity_fluid.py N END_TIME [--bottom rigid|transpiring|moving|membrane] [--case DIR]
                             [--motion FILE] [--dt DT]

The fluid of cases/flexible-cavity.yaml with the membrane replaced by a prescribed bottom: a unit
square, DEPTH thick (one cell, z faces "empty"), N x N cells (N a multiple of 8: N * 7/8 rows below
y = 0.875, N/8 above). Lid y = 1: u = 1 - cos(2 pi t / 5). Left wall for 0.875 <= y <= 1: inflow
u = (1 - cos(2 pi t / 5)) (y - 0.875) / 0.125, taken at the face centres; right wall over the same
span: p = 0, zero-gradient U. Other walls no-slip. Bottom y = 0: `rigid` no-slip, `transpiring`
with v = TRANSPIRATION_V (1 - cos(2 pi t / 5)) into the cavity (u = 0), or `moving`: a rigid plate
lifted to y = LIFT (1 - cos(2 pi t / 5)), the mesh following it (dynamicMotionSolverFvMesh,
displacementLaplacian with uniform diffusivity; point displacement prescribed on the bottom, slip
on the side walls, zero on lid, inlets and outlet), U `movingWallVelocity` on the bottom, and
pimpleFoam's correctPhi on (pcorr), the mesh moved once per step (moveMeshOuterCorrectors no);
or `membrane`: as `moving`, but the bottom's nodes follow a recorded membrane motion (--motion, a
JSON file {"points": [[x, y, z], ...], "times": [...], "displacements": [[[dx, dy, dz], ...], ...]}
written from an mfsi FSI run by flexible_cavity_coupled.py), prescribed through
`timeVaryingMappedFixedValue` (nearest point; the times are the steps', so OpenFOAM's linear
interpolation in time is exact at every step).
rho = 1, nu = 0.01, dt = 0.1, backward (BDF2), Gauss linear everywhere, PIMPLE with 10 outer
correctors (residual control 1e-7), 2 pressure correctors, 1 non-orthogonal corrector. The
`forces` function object writes the bottom patch force (rho 1) every step to
postProcessing/forcesBottom/0/force.dat.

Time-dependent values are `uniformFixedValue` tables sampled every dt / 2, so OpenFOAM's linear
interpolation is exact at the step times. Each inlet face is its own patch (inlet0, inlet1, ...)
and so its own table: the upper band is built from N/8 one-row blocks.
"""
import argparse
import math
import os

DEPTH = 0.05            # z extent of cases/flexible-cavity.yaml
Y_INLET = 0.875         # the inlet / outlet span is Y_INLET <= y <= 1
PERIOD = 5.0            # 1 - cos(2 pi t / PERIOD) ramp of lid, inlet and transpiration
DT = 0.1
TRANSPIRATION_V = 0.02  # bottom normal velocity amplitude of --bottom transpiring
LIFT = 0.05             # bottom lift y = LIFT (1 - cos(2 pi t / PERIOD)) of --bottom moving
BOTTOMS = ("rigid", "transpiring", "moving", "membrane")
MOVING = ("moving", "membrane")


def header(cls, obj):
    return "FoamFile { version 2.0; format ascii; class %s; object %s; }\n" % (cls, obj)


def block_mesh_dict(n):
    """blockMeshDict: one N x 7N/8 block below Y_INLET, N/8 blocks of one row each above it."""
    n_low, n_up = n * 7 // 8, n // 8
    # vertices 0-3 at z = 0, 4-7 at z = DEPTH, counter-clockwise from (0, 0); then 4 per upper row
    verts = [(0, 0, 0), (1, 0, 0), (1, Y_INLET, 0), (0, Y_INLET, 0),
             (0, 0, DEPTH), (1, 0, DEPTH), (1, Y_INLET, DEPTH), (0, Y_INLET, DEPTH)]
    blocks = ["hex (0 1 2 3 4 5 6 7) (%d %d 1) simpleGrading (1 1 1)" % (n, n_low)]
    z_faces = ["(0 3 2 1)", "(4 5 6 7)"]
    inlet_faces, outlet_faces = [], []
    below = (3, 2, 6, 7)  # the row's lower edge: (x0 z0) (x1 z0) (x1 zD) (x0 zD)
    for i in range(n_up):
        y = Y_INLET + (i + 1) * (1 - Y_INLET) / n_up
        a, b, c, d = range(len(verts), len(verts) + 4)
        verts += [(0, y, 0), (1, y, 0), (1, y, DEPTH), (0, y, DEPTH)]
        blocks.append("hex (%d %d %d %d %d %d %d %d) (%d 1 1) simpleGrading (1 1 1)"
                      % (below[0], below[1], b, a, below[3], below[2], c, d, n))
        inlet_faces.append("(%d %d %d %d)" % (below[0], below[3], d, a))
        outlet_faces.append("(%d %d %d %d)" % (below[1], b, c, below[2]))
        z_faces += ["(%d %d %d %d)" % (below[0], a, b, below[1]),
                    "(%d %d %d %d)" % (below[3], below[2], c, d)]
        below = (a, b, c, d)
    out = [header("dictionary", "blockMeshDict"), "convertToMeters 1;\nvertices\n(\n"]
    out += ["    (%.10g %.10g %.10g)\n" % p for p in verts]
    out.append(");\nblocks\n(\n%s\n);\nedges ();\nboundary\n(\n" % "\n".join("    " + b for b in blocks))
    out.append("    lid { type wall; faces ((%d %d %d %d)); }\n" % (below[0], below[3], below[2], below[1]))
    out.append("    bottom { type wall; faces ((0 1 5 4)); }\n")
    out.append("    walls { type wall; faces ((0 4 7 3) (1 2 6 5)); }\n")
    for i, face in enumerate(inlet_faces):
        out.append("    inlet%d { type patch; faces (%s); }\n" % (i, face))
    out.append("    outlet { type patch; faces (%s); }\n" % " ".join(outlet_faces))
    out.append("    frontBack { type empty; faces (%s); }\n" % " ".join(z_faces))
    out.append(");\nmergePatchPairs ();\n")
    return "".join(out)


def ramp_table(vector, end_time):
    """Function1 table of vector * (1 - cos(2 pi t / PERIOD)) at t = k dt / 2 up to past end_time."""
    rows = []
    for k in range(int(round(end_time / (DT / 2))) + 5):
        t = k * DT / 2
        s = 1 - math.cos(2 * math.pi * t / PERIOD)
        rows.append("    (%.6f (%.12g %.12g %.12g))" % ((t,) + tuple(s * c for c in vector)))
    return "table\n    (\n%s\n    )" % "\n".join(rows)


def velocity_field(n, end_time, bottom):
    n_up = n // 8
    out = [header("volVectorField", "U"),
           "dimensions [0 1 -1 0 0 0 0];\ninternalField uniform (0 0 0);\nboundaryField\n{\n"]
    out.append("lid { type uniformFixedValue; uniformValue %s; }\n" % ramp_table((1, 0, 0), end_time))
    for i in range(n_up):  # linear profile at the face centre y = Y_INLET + (i + 1/2) h
        out.append("inlet%d { type uniformFixedValue; uniformValue %s; }\n"
                   % (i, ramp_table(((i + 0.5) / n_up, 0, 0), end_time)))
    if bottom == "rigid":
        out.append("bottom { type noSlip; }\n")
    elif bottom in MOVING:  # the wall's velocity from the mesh motion
        out.append("bottom { type movingWallVelocity; value uniform (0 0 0); }\n")
    else:
        out.append("bottom { type uniformFixedValue; uniformValue %s; }\n"
                   % ramp_table((0, TRANSPIRATION_V, 0), end_time))
    out.append("walls { type noSlip; }\noutlet { type zeroGradient; }\nfrontBack { type empty; }\n}\n")
    return "".join(out)


PRESSURE = header("volScalarField", "p") + """dimensions [0 2 -2 0 0 0 0];
internalField uniform 0;
boundaryField
{
    outlet { type fixedValue; value uniform 0; }
    frontBack { type empty; }
    ".*" { type zeroGradient; }
}
"""

def point_displacement(n, end_time, bottom):
    """0/pointDisplacement of --bottom moving or membrane: the bottom lifted (moving) or following the
    recorded motion in constant/boundaryData (membrane), side walls sliding, rest fixed."""
    out = [header("pointVectorField", "pointDisplacement"),
           "dimensions [0 1 0 0 0 0 0];\ninternalField uniform (0 0 0);\nboundaryField\n{\n"]
    if bottom == "moving":
        out.append("bottom { type uniformFixedValue; uniformValue %s; }\n" % ramp_table((0, LIFT, 0), end_time))
    else:
        out.append("bottom { type timeVaryingMappedFixedValue; mapMethod nearest; offset (0 0 0); "
                   "setAverage false; value uniform (0 0 0); }\n")
    out.append("walls { type slip; }\n")
    for patch in ["lid"] + ["inlet%d" % i for i in range(n // 8)] + ["outlet"]:
        out.append("%s { type fixedValue; value uniform (0 0 0); }\n" % patch)
    out.append("frontBack { type empty; }\n}\n")
    return "".join(out)


DYNAMIC_MESH = header("dictionary", "dynamicMeshDict") + """dynamicFvMesh dynamicMotionSolverFvMesh;
motionSolverLibs ("libfvMotionSolvers.so");
motionSolver displacementLaplacian;
solver displacementLaplacian;
displacementLaplacianCoeffs { diffusivity uniform; }
"""

TRANSPORT = header("dictionary", "transportProperties") + "transportModel Newtonian;\nnu 0.01;\n"

TURBULENCE = header("dictionary", "turbulenceProperties") + "simulationType laminar;\n"

SCHEMES = header("dictionary", "fvSchemes") + """ddtSchemes { default backward; }
gradSchemes { default Gauss linear; }
divSchemes { default none; div(phi,U) Gauss linear; div((nuEff*dev2(T(grad(U))))) Gauss linear; }
laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
"""

def solution(bottom):
    """fvSolution; --bottom moving adds the mesh motion's solvers and PIMPLE settings."""
    moving = bottom in MOVING
    return header("dictionary", "fvSolution") + """solvers
{
    p { solver PCG; preconditioner DIC; tolerance 1e-10; relTol 0.01; }
    pFinal { $p; relTol 0; }
    U { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-10; relTol 0.01; }
    UFinal { $U; relTol 0; }
%s}
PIMPLE
{
%s    nOuterCorrectors 10;
    nCorrectors 2;
    nNonOrthogonalCorrectors 1;
    residualControl { p { tolerance 1e-7; relTol 0; } U { tolerance 1e-7; relTol 0; } }
}
""" % ("""    pcorr { solver PCG; preconditioner DIC; tolerance 1e-10; relTol 0; }
    pcorrFinal { $pcorr; }
    cellDisplacement { solver PCG; preconditioner DIC; tolerance 1e-12; relTol 0; }
""" if moving else "", "    correctPhi yes;\n    moveMeshOuterCorrectors no;\n" if moving else "")


def control_dict(end_time):
    return header("dictionary", "controlDict") + """application pimpleFoam;
startFrom startTime;
startTime 0;
stopAt endTime;
endTime %.10g;
deltaT %g;
writeControl timeStep;
writeInterval 100000;
purgeWrite 0;
writeFormat ascii;
writePrecision 12;
timeFormat general;
timePrecision 8;
runTimeModifiable false;
functions
{
    forcesBottom
    {
        type forces; libs ("libforces.so"); patches (bottom);
        rho rhoInf; rhoInf 1; CofR (0.5 0 0);
        writeControl timeStep; writeInterval 1; log false;
    }
}
""" % (end_time, DT)


def vector_list(rows):
    return "%d\n(\n%s\n)\n" % (len(rows), "\n".join("(%.12g %.12g %.12g)" % tuple(r) for r in rows))


def boundary_data(motion_file, end_time):
    """{relative path: text} of constant/boundaryData/bottom from a recorded membrane motion."""
    import json
    with open(motion_file) as f:
        motion = json.load(f)
    points, times, disps = motion["points"], motion["times"], motion["displacements"]
    if len(times) != len(disps) or any(len(d) != len(points) for d in disps):
        raise SystemExit("%s: %d times, %d displacement sets, %d points" % (motion_file, len(times), len(disps), len(points)))
    if times[0] > 1e-12 or times[-1] < end_time - 1e-9:
        raise SystemExit("%s: times %g..%g do not cover 0..%g" % (motion_file, times[0], times[-1], end_time))
    files = {"constant/boundaryData/bottom/points": vector_list(points)}
    for t, d in zip(times, disps):
        files["constant/boundaryData/bottom/%.8g/pointDisplacement" % t] = vector_list(d)
    return files


def write_case(case, n, end_time, bottom, motion=None):
    files = {
        "system/blockMeshDict": block_mesh_dict(n),
        "system/controlDict": control_dict(end_time),
        "system/fvSchemes": SCHEMES,
        "system/fvSolution": solution(bottom),
        "constant/transportProperties": TRANSPORT,
        "constant/turbulenceProperties": TURBULENCE,
        "0/U": velocity_field(n, end_time, bottom),
        "0/p": PRESSURE,
    }
    if bottom in MOVING:
        files["constant/dynamicMeshDict"] = DYNAMIC_MESH
        files["0/pointDisplacement"] = point_displacement(n, end_time, bottom)
    if bottom == "membrane":
        files.update(boundary_data(motion, end_time))
    for rel, text in files.items():
        path = os.path.join(case, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w") as f:
            f.write(text)


def main():
    global DT
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("n", type=int, metavar="N", help="cells per side (a multiple of 8)")
    ap.add_argument("end_time", type=float, metavar="END_TIME", help="simulated time [s]")
    ap.add_argument("--bottom", choices=BOTTOMS, default="rigid")
    ap.add_argument("--case", default=".", help="case directory (default: the current one)")
    ap.add_argument("--motion", help="recorded bottom motion (JSON) for --bottom membrane")
    ap.add_argument("--dt", type=float, default=DT, help="time step (default %g)" % DT)
    args = ap.parse_args()
    DT = args.dt
    if (args.bottom == "membrane") != (args.motion is not None):
        ap.error("--motion goes with --bottom membrane, and only with it")
    if args.n < 8 or args.n % 8:
        ap.error("N must be a positive multiple of 8 (got %d)" % args.n)
    if args.end_time <= 0:
        ap.error("END_TIME must be positive")
    write_case(args.case, args.n, args.end_time, args.bottom, args.motion)


if __name__ == "__main__":
    main()
