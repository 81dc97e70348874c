"""Render frames of a casca run with ParaView: the bodies at chosen times, coloured by the
speed (the thesis' Figs. 8 and 14). Run with ParaView's batch interpreter:

    xvfb-run -a pvbatch render.py out/two_rings 0.0 0.01 0.02 0.03

writes out/two_rings/frame_t<time>.png for each time (the nearest frame)."""
import os
import sys

from paraview.simple import (Calculator, ColorBy, GetActiveViewOrCreate, GetColorTransferFunction,
                             GetScalarBar, PVDReader, Render, ResetCamera, SaveScreenshot, Show, Text,
                             UpdatePipeline)

folder = sys.argv[1]
times = [float(t) for t in sys.argv[2:]] or [0.0]
reader = PVDReader(FileName=os.path.join(folder, "run.pvd"))
speed = Calculator(Input=reader, ResultArrayName="speed", Function="mag(velocity)")
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [1200, 700]
view.UseColorPaletteForBackground = 0
view.Background = [1, 1, 1]
view.OrientationAxesVisibility = 1
display = Show(speed, view)
ColorBy(display, ("POINTS", "speed"))
lut = GetColorTransferFunction("speed")
lut.ApplyPreset("Viridis (matplotlib)", True)
display.SetScalarBarVisibility(view, True)
bar = GetScalarBar(lut, view)
bar.Title = "speed [m/s]"
bar.ComponentTitle = ""
bar.TitleColor = [0, 0, 0]   # the default white is lost on the white background
bar.LabelColor = [0, 0, 0]
label = Text()
label_display = Show(label, view)
label_display.Color = [0, 0, 0]
available = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
view.CameraPosition = [1.0, 0.0, 8.0]
view.CameraFocalPoint = [1.0, 0.0, 0.0]
view.CameraViewUp = [0.0, 1.0, 0.0]
for t in times:
    tt = min(available, key=lambda a: abs(a - t))
    view.ViewTime = tt
    UpdatePipeline(tt, speed)
    lut.RescaleTransferFunction(0.0, 12.0)
    label.Text = "t = %.2f ms   (colour: speed [m/s])" % (1e3 * tt)
    ResetCamera(view)
    Render(view)
    out = os.path.join(folder, "frame_t%.4f.png" % tt)
    SaveScreenshot(out, view, ImageResolution=[1200, 700])
    print(out)
