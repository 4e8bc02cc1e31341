"""Render bedexport's STL output with ParaView (pvbatch), as in the README.

    xvfb-run -a pvbatch tools/bedexport/paraview/render_stl.py out/bed.stl out/tube.stl out/bed.png

Opens the pellets' STL and the tube's STL with ParaView's own STL reader,
draws the pellets as shaded surfaces and the tube as a translucent shell,
and saves a PNG.
"""
import sys

from paraview.simple import (GetActiveViewOrCreate, ColorBy, Connectivity, Render, SaveScreenshot, Show,
                             STLReader, ResetCamera)

pellets_path, tube_path, png_path = sys.argv[1:4]
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [900, 1100]
view.Background = [1.0, 1.0, 1.0]
try:
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
view.OrientationAxesVisibility = 1

pellets = STLReader(FileNames=[pellets_path])
# One region per pellet (its own closed surface), so each gets a colour.
regions = Connectivity(Input=pellets)
shown = Show(regions, view)
ColorBy(shown, ("POINTS", "RegionId"))
shown.LookupTable.ApplyPreset("Turbo", True)
shown.Specular = 0.3

tube = STLReader(FileNames=[tube_path])
tube_shown = Show(tube, view)
tube_shown.Opacity = 0.15
tube_shown.DiffuseColor = [0.5, 0.6, 0.8]
tube_shown.AmbientColor = [0.5, 0.6, 0.8]
tube_shown.ColorArrayName = ["POINTS", ""]

ResetCamera(view)
camera = view.GetActiveCamera()
camera.Elevation(-70)
camera.Azimuth(30)
view.CameraViewUp = [0.0, 0.0, 1.0]
ResetCamera(view)
Render(view)
SaveScreenshot(png_path, view, ImageResolution=[900, 1100])
print("saved", png_path)
