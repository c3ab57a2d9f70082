#!/usr/bin/env python3
"""What ParaView reads from a run's fields.xdmf: its times, and per grid the points, cells (VTK cell
type of the first one), point and cell arrays at the last time.

    /usr/bin/python3 scripts/paraview_summary.py results/flexible-cavity/fields.xdmf

Needs ParaView's Python modules (Debian: apt-get install python3-paraview); it is a check of the
files, not part of the build or of `make test`.
"""
import sys

from paraview.simple import Xdmf3ReaderS, servermanager


def walk(block, name):
    if block is None:
        return
    if block.IsA("vtkDataSet"):
        pd, cd = block.GetPointData(), block.GetCellData()
        first = block.GetCellType(0) if block.GetNumberOfCells() > 0 else None
        print(f"{name}: {block.GetNumberOfPoints()} points, {block.GetNumberOfCells()} cells (first VTK type {first})")
        print("  point arrays:", [pd.GetArrayName(k) for k in range(pd.GetNumberOfArrays())])
        print("  cell arrays: ", [cd.GetArrayName(k) for k in range(cd.GetNumberOfArrays())])
        return
    pieces = block.IsA("vtkMultiPieceDataSet")
    for i in range(block.GetNumberOfPieces() if pieces else block.GetNumberOfBlocks()):
        child = block.GetPiece(i) if pieces else block.GetBlock(i)
        label = name
        if not pieces and block.HasMetaData(i):
            label = block.GetMetaData(i).Get(block.NAME())
        walk(child, label)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    reader = Xdmf3ReaderS(FileName=[sys.argv[1]])
    reader.UpdatePipelineInformation()
    times = reader.TimestepValues
    times = list(times) if hasattr(times, "__iter__") else [times]
    print("times:", times)
    reader.UpdatePipeline(max(times))
    walk(servermanager.Fetch(reader), "dataset")


if __name__ == "__main__":
    main()
