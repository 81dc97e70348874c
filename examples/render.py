"""Render frames of a casca run with ParaView: the bodies at chosen times, coloured by the
speed (the thesis' Figs. 8 and 14). Run with ParaView's batch interpreter:

    xvfb-run -a pvbatch render.py out/two_rings 0.0 0.01 0.02 0.03

writes out/two_rings/frame_t<time>.png for each time (the nearest frame's time, 6 digits). Every picture has
the same camera and colour range, so that they compare: the camera looks along the thinnest
side of the box holding all bodies in all the chosen frames (down the axis of the rings; when
no side is under half the longest, as for a ball, along y with z up), turned TILT degrees up
and half that sideways so that a band or a plate is not seen edge-on,
with the box's longest side across the picture, and shows the whole box; the colours run
from 0 to the highest speed in those frames. A static run's frames (no velocities; t is the
load factor) are coloured by the displacement's magnitude and labelled with the load factor.
Rigid obstacles (run.pvd's part 1) are drawn grey where they are at each time, and are left
out of the box: the camera frames the bodies."""
import math
import os
import sys
import xml.etree.ElementTree as ET

from paraview.simple import (Calculator, ColorBy, ExtractBlock, GetActiveCamera, GetActiveViewOrCreate,
                             GetColorTransferFunction, GetScalarBar, PVDReader, Render, SaveScreenshot, Show, Text,
                             Threshold, UpdatePipeline)

WIDTH, HEIGHT = 1200, 700
MARGIN = 1.3   # room around the bodies (and for the colour bar), as a factor on the box
TILT = 25.0    # degrees off the thinnest side
GREY = [0.62, 0.62, 0.62]   # the obstacles'


def nearest_frames(reader, times):
    """The frame time nearest to each time asked for."""
    available = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
    return [min(available, key=lambda a: abs(a - t)) for t in times]


def bounds_and_top(shade, frames):
    """The box (xmin, xmax, ymin, ymax, zmin, zmax) holding the bodies in all frames, and the
    highest value of the colour's field in them."""
    box = [math.inf, -math.inf] * 3
    top = 0.0
    for tt in frames:
        UpdatePipeline(tt, shade)
        b = shade.GetDataInformation().GetBounds()
        box = [min(box[i], b[i]) if i % 2 == 0 else max(box[i], b[i]) for i in range(6)]
        top = max(top, shade.PointData["shade"].GetRange()[1])
    return box, top


def place_camera(view, box, floor=None):
    """Look along the box's thinnest side at its centre, its longest side across the picture
    pointing right, from the distance at which the whole box fits the view angle. floor: the
    axis a floor's normal is along (floor_axis), made the picture's up when it lies across it
    (a ring dropped on a floor: the floor below it, not beside it)."""
    centre = [0.5 * (box[2 * i] + box[2 * i + 1]) for i in range(3)]
    size = [box[2 * i + 1] - box[2 * i] for i in range(3)]
    thin, up, across = sorted(range(3), key=lambda i: size[i])
    if size[thin] > 0.5 * size[across]:   # no side much thinner (a ball): a side view, z up
        thin, up, across = 1, 2, 0
    if floor == across:
        up, across = across, up
    half = 0.5 * MARGIN * max(size[up], size[across] * HEIGHT / WIDTH, 1e-12)
    distance = half / math.tan(math.radians(0.5 * view.CameraViewAngle)) + 0.5 * size[thin]
    # from +thin, looking along -thin with `up` up, the right-hand side is (-thin) x up:
    # +across when (thin, up, across) is not a cyclic order of (x, y, z); else look from -thin
    side = 1.0 if (up - thin) % 3 == 2 else -1.0
    position = list(centre)
    position[thin] += side * distance
    view.CameraFocalPoint = centre
    view.CameraPosition = position
    view.CameraViewUp = [1.0 if i == up else 0.0 for i in range(3)]
    # turned a little off the thin side: straight along it a ring's band or a plate is seen
    # edge-on, a hairline that breaks up
    camera = GetActiveCamera()
    camera.Elevation(TILT)
    camera.Azimuth(-0.5 * TILT)


def floor_axis(obstacles, frame):
    """The axis (0, 1, 2) that the first obstacle drawn flat across one is normal to (a plane
    normal to x, y or z), or None"""
    UpdatePipeline(frame, obstacles)
    top = int(round(obstacles.CellData["obstacle"].GetRange()[1]))
    for k in range(1, top + 1):
        one = Threshold(Input=obstacles, Scalars=["CELLS", "obstacle"], LowerThreshold=k - 0.5,
                        UpperThreshold=k + 0.5)
        UpdatePipeline(frame, one)
        b = one.GetDataInformation().GetBounds()
        size = [b[2 * i + 1] - b[2 * i] for i in range(3)]
        flat = [i for i in range(3) if size[i] <= 1e-9 * max(size)]
        if flat:
            return flat[0]
    return None


def has_obstacles(pvd):
    """run.pvd lists obstacle files (part 1) beside the frames (part 0)"""
    return any(d.get("part") == "1" for d in ET.parse(pvd).getroot().iter("DataSet"))


folder = sys.argv[1]
times = [float(t) for t in sys.argv[2:]] or [0.0]
pvd = os.path.join(folder, "run.pvd")
reader = PVDReader(FileName=pvd)
obstacles = None
bodies = reader
if has_obstacles(pvd):   # the reader gives a block per part: bodies 0, obstacles 1
    bodies = ExtractBlock(Input=reader, Selectors=["/Root/Block0"])
    obstacles = ExtractBlock(Input=reader, Selectors=["/Root/Block1"])
shade = Calculator(Input=bodies, ResultArrayName="shade", Function="mag(velocity)")
frames = nearest_frames(reader, times)
box, top = bounds_and_top(shade, frames)
static = top == 0 and max(frames) > 0   # (no velocity after the start: statics)
if static:
    shade.Function = "mag(displacement)"
    box, top = bounds_and_top(shade, frames)
what = "displacement [m]" if static else "speed [m/s]"
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [WIDTH, HEIGHT]
view.UseColorPaletteForBackground = 0
view.Background = [1, 1, 1]
view.OrientationAxesVisibility = 1
display = Show(shade, view)
ColorBy(display, ("POINTS", "shade"))
# mostly ambient light: a face seen edge-on keeps a colour that reads on the bar
display.Ambient, display.Diffuse = 0.7, 0.3
lut = GetColorTransferFunction("shade")
lut.ApplyPreset("Viridis (matplotlib)", True)
lut.AutomaticRescaleRangeMode = "Never"   # keep the range below in every picture
display.SetScalarBarVisibility(view, True)
bar = GetScalarBar(lut, view)
bar.Title = what
bar.ComponentTitle = ""
bar.TitleColor = [0, 0, 0]   # the default white is lost on the white background
bar.LabelColor = [0, 0, 0]
floor = None
if obstacles is not None:
    floor = floor_axis(obstacles, frames[0])
    shown = Show(obstacles, view)
    shown.ColorArrayName = [None, ""]   # (a solid colour)
    shown.AmbientColor, shown.DiffuseColor = GREY, GREY
    shown.Ambient, shown.Diffuse = 0.4, 0.6   # (seen near edge-on a floor stays grey)
label = Text()
label_display = Show(label, view)
label_display.Color = [0, 0, 0]

Render(view)   # the view's first render resets the camera: place it after that one
place_camera(view, box, floor)
lut.RescaleTransferFunction(0.0, top if top > 0 else 1.0)
for tt in frames:
    view.ViewTime = tt
    UpdatePipeline(tt, shade)
    when = "load factor %.3f" % tt if static else "t = %.2f ms" % (1e3 * tt)
    label.Text = "%s   (colour: %s)" % (when, what)
    Render(view)
    out = os.path.join(folder, "frame_t%.6g.png" % tt)
    SaveScreenshot(out, view, ImageResolution=[WIDTH, HEIGHT])
    print(out)
