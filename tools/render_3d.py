"""Render a 3D mixsph run (its run.xdmf) headless with ParaView: the particles as points coloured by
a field, at one snapshot, into a PNG (docs/validation/three_d.md).

    pvbatch tools/render_3d.py RUN_DIR/run.xdmf OUT.png [--field pressure|velocity|...]
                               [--time T] [--size 800x500] [--no-walls]

Run by ParaView's pvbatch (Debian package paraview), not by the project's python. The snapshot is
the last one at or before --time (default: the last). With --no-walls the wall particles (field
``state`` = 2, docs/output.md) and lost ones (3) are left out by a threshold on ``state``;
velocity is coloured by its magnitude. The camera looks from the front-left-above at the whole
cloud (an isometric-like view), so the same script serves any 3D case.
"""
import argparse

from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetColorTransferFunction, GetScalarBar, Render, ResetCamera, SaveScreenshot, Show, Threshold, XDMFReader)

ap = argparse.ArgumentParser()
ap.add_argument("xdmf")
ap.add_argument("png")
ap.add_argument("--field", default="pressure")
ap.add_argument("--time", type=float)
ap.add_argument("--size", default="800x500")
ap.add_argument("--no-walls", action="store_true")
args = ap.parse_args()

reader = XDMFReader(FileNames=[args.xdmf])
times = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
t = times[-1] if args.time is None else max([x for x in times if x <= args.time + 1e-9] or [times[0]])
source = reader
if args.no_walls:
    source = Threshold(Input=reader, Scalars=["POINTS", "state"])
    source.LowerThreshold, source.UpperThreshold = 0, 1
view = GetActiveViewOrCreate("RenderView")
w, h = (int(v) for v in args.size.split("x"))
view.ViewSize = [w, h]
view.ViewTime = t
view.Background = [1, 1, 1]
try:
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
view.OrientationAxesVisibility = 1
shown = Show(source, view)
shown.SetRepresentationType("Points")
shown.PointSize = 3
if args.field == "velocity":
    ColorBy(shown, ("POINTS", "velocity", "Magnitude"))
else:
    ColorBy(shown, ("POINTS", args.field))
shown.RescaleTransferFunctionToDataRange(True, False)
shown.SetScalarBarVisibility(view, True)
lut = GetColorTransferFunction(args.field)
lut.ApplyPreset("Viridis (matplotlib)", True)
bar = GetScalarBar(lut, view)
bar.TitleColor, bar.LabelColor = [0, 0, 0], [0, 0, 0]
bar.Title = f"{args.field} [{'m/s' if args.field == 'velocity' else 'Pa' if args.field == 'pressure' else ''}]"
view.CameraPosition = [-1.0, -2.0, 1.2]
view.CameraFocalPoint = [0.0, 0.0, 0.0]
view.CameraViewUp = [0, 0, 1]
ResetCamera(view)
Render(view)
SaveScreenshot(args.png, view, ImageResolution=[w, h])
print(f"{args.png}: {args.field} at t = {t:g} s of {args.xdmf}")
