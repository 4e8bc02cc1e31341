"""Open bedexport's files with ParaView's own readers and print what they hold.

    cd out && xvfb-run -a pvbatch ../tools/bedexport/paraview/check_files.py

Expects bed.vtp, centres.vtp, bed.vti and bed.stl in the current directory.
"""
from paraview.simple import XMLPolyDataReader, XMLImageDataReader, STLReader
from paraview import servermanager as sm
for name, reader in [("bed.vtp", XMLPolyDataReader), ("centres.vtp", XMLPolyDataReader), ("bed.vti", XMLImageDataReader), ("bed.stl", STLReader)]:
    r = reader(FileName=[name]) if reader is not STLReader else reader(FileNames=[name])
    r.UpdatePipeline()
    d = sm.Fetch(r)
    info = r.GetDataInformation()
    arrays = []
    for assoc in (r.CellData, r.PointData):
        for k in assoc.keys():
            arrays.append("%s%s" % (k, assoc[k].GetRange()))
    print(name, "points", info.GetNumberOfPoints(), "cells", info.GetNumberOfCells(), "bounds", [round(b, 3) for b in info.GetBounds()], arrays)
