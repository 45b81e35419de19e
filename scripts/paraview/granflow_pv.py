"""Shared helpers of the granflow ParaView scripts (run them with `pvpython`).

A run folder written by `granflow run` holds `series.pvd`, a collection with one part per file
kind of a frame (docs/output.md, "The output folder of `granflow run`"). ParaView's PVD reader
turns it into a multiblock with one block per part, in part order; `part()` takes one out.
"""

import argparse
import os
import sys
import tomllib

from paraview import servermanager as sm
from paraview import simple as pv

# The arrays each part of a frame advertises (docs/output.md), by scenario kind:
# (part, file prefix, "point" or "cell" data, arrays).
GRAINS = ["radius", "velocity", "angle", "angular_velocity", "contacts", "stress", "mean_pressure"]
CONTACTS = ["normal_force", "tangential_force", "wall"]
ADVERTISED = {
    "fluid": [(0, "fluid", "cell", ["density", "pressure", "velocity", "vorticity", "solid"])],
    "dem": [(0, "grains", "point", GRAINS), (1, "contacts", "cell", CONTACTS)],
    "granular": [(0, "grains", "point", GRAINS), (1, "contacts", "cell", CONTACTS)],
    "submerged": [
        (0, "grains", "point", GRAINS),
        (1, "contacts", "cell", CONTACTS),
        (2, "fluid", "cell",
         ["velocity", "pressure", "excess_pore_pressure", "vorticity", "solid_fraction"]),
    ],
    "mpm": [
        (0, "points", "point",
         ["velocity", "stress_xx", "stress_yy", "stress_xy", "stress_zz", "mean_stress",
          "deviatoric_stress", "volume"]),
        (1, "grid", "cell", ["density", "velocity"]),
    ],
}


def fail(message):
    """Stop the script with `message` on standard error and exit status 1."""
    print(f"error: {message}", file=sys.stderr)
    sys.exit(1)


def render_arguments(doc, *extra):
    """Parse a rendering script's command line: RUN PNG [--time T] [--size W H], plus the
    options `extra` gives as (flags, keyword arguments) of `add_argument`."""
    p = argparse.ArgumentParser(description=doc.splitlines()[0])
    p.add_argument("run")
    p.add_argument("png")
    for flags, kwargs in extra:
        p.add_argument(flags, **kwargs)
    p.add_argument("--time", type=float, default=None, help="frame time (s)")
    p.add_argument("--size", type=int, nargs=2, default=[1600, 700], metavar=("W", "H"))
    return p.parse_args()


def scenario(run):
    """The run's copy of its scenario (`scenario.toml`), as a dict."""
    path = os.path.join(run, "scenario.toml")
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError) as e:
        fail(f"{path}: {e}")


def run_kind(run):
    """The scenario kind of a run folder, read from its copy of the scenario."""
    kind = scenario(run).get("kind")
    if kind not in ADVERTISED:
        fail(f"{run}/scenario.toml: kind {kind!r} has no frames these scripts know")
    return kind


def open_run(run):
    """ParaView's reader of the run's `series.pvd` and the run's kind."""
    path = os.path.join(run, "series.pvd")
    if not os.path.isfile(path):
        fail(f"{path}: no such file (is {run} a granflow run folder?)")
    reader = pv.PVDReader(FileName=path)
    if not times(reader):
        fail(f"{path}: ParaView found no time steps")
    return reader, run_kind(run)


def times(reader):
    """The frames' times (s), oldest first (a one-frame series gives a bare number)."""
    t = reader.TimestepValues
    return [float(x) for x in t] if hasattr(t, "__iter__") else [float(t)]


def part(reader, k):
    """Part `k` of every frame as one data set (ExtractBlock, then MergeBlocks). A series of
    one part is read as that part's data set itself."""
    reader.UpdatePipeline()
    if not reader.GetDataInformation().DataInformation.IsCompositeDataSet():
        return reader
    block = pv.ExtractBlock(Input=reader, Selectors=[f"/Root/Block{k}"])
    return pv.MergeBlocks(Input=block)


def leaves(data):
    """The data sets of a fetched multiblock, depth first."""
    if data.IsA("vtkMultiBlockDataSet"):
        for i in range(data.GetNumberOfBlocks()):
            yield from leaves(data.GetBlock(i))
    elif data is not None:
        yield data


def fetch_part(reader, k, t):
    """Part `k` of the frame at time `t`, fetched to this process (a VTK data set)."""
    reader.UpdatePipeline(t)
    frame = sm.Fetch(reader)
    if not frame.IsA("vtkMultiBlockDataSet") and k == 0:
        return frame
    if frame.GetNumberOfBlocks() <= k:
        fail(f"the frame at t = {t} s has {frame.GetNumberOfBlocks()} parts, not {k + 1}")
    found = list(leaves(frame.GetBlock(k)))
    if len(found) != 1:
        fail(f"part {k} of the frame at t = {t} s holds {len(found)} data sets, not 1")
    return found[0]


def arrays(data, where):
    """Names of the point or cell arrays of a data set."""
    fields = data.GetPointData() if where == "point" else data.GetCellData()
    return [fields.GetArrayName(i) for i in range(fields.GetNumberOfArrays())]


def render_view(width, height, t):
    """A white view of `width` × `height` pixels at simulated time `t`."""
    view = pv.CreateRenderView()
    view.ViewTime = t
    view.ViewSize = [width, height]
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = [1.0, 1.0, 1.0]
    return view


def look_at(view, bounds):
    """Look down −z at `bounds` (xmin, xmax, ymin, ymax) with a parallel projection, leaving
    room at the bottom for the colour bar. Call after the last `Show`: showing the first data
    set resets the camera."""
    cx, cy = (bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2
    half_w, half_h = (bounds[1] - bounds[0]) / 2, (bounds[3] - bounds[2]) / 2
    scale = 1.08 * max(half_h, half_w * view.ViewSize[1] / view.ViewSize[0])
    view.CameraParallelProjection = 1
    view.CameraFocalPoint = [cx, cy - 0.25 * scale, 0.0]
    view.CameraPosition = [cx, cy - 0.25 * scale, 20.0 * scale]
    view.CameraViewUp = [0.0, 1.0, 0.0]
    view.CameraParallelScale = 1.3 * scale


def disks(grains, z=0.0):
    """Grains as balls of their `radius`, seen from above as disks (the sphere glyph has
    radius ½ at scale 1, hence the factor 2), every grain drawn, lifted to height `z`. Show
    them with `flat()` so that they read as disks."""
    glyph = pv.Glyph(Input=grains, GlyphType="Sphere")
    glyph.GlyphType.ThetaResolution = 24
    glyph.GlyphType.PhiResolution = 12
    glyph.OrientationArray = ["POINTS", "No orientation array"]
    glyph.ScaleArray = ["POINTS", "radius"]
    glyph.ScaleFactor = 2.0
    glyph.GlyphMode = "All Points"
    glyph.GlyphTransform.Translate = [0.0, 0.0, z]
    return glyph


def polygons(grains, sides, z=0.0):
    """Polygon grains (a collapse with `grains.sides` = n) as filled regular n-gons at height
    `z`: vertex k of grain i at x_i + R_i (cos(θ_i + 2πk/n), sin(θ_i + 2πk/n)), R_i its `radius`
    (the circumradius) and θ_i its `angle`; each polygon carries its grain's `velocity` as cell
    data."""
    f = pv.ProgrammableFilter(Input=grains)
    f.OutputDataSetType = "vtkPolyData"
    f.Script = f"""
import math
import vtk
n, z = {int(sides)}, {float(z)}
inp = self.GetInput()
out = self.GetOutput()
data = inp.GetPointData()
radius, angle, velocity = (data.GetArray(a) for a in ("radius", "angle", "velocity"))
points, cells = vtk.vtkPoints(), vtk.vtkCellArray()
vel = vtk.vtkDoubleArray()
vel.SetName("velocity")
vel.SetNumberOfComponents(3)
for i in range(inp.GetNumberOfPoints()):
    x, y, _ = inp.GetPoint(i)
    r, t = radius.GetValue(i), angle.GetValue(i)
    cells.InsertNextCell(n)
    for k in range(n):
        a = t + 2.0 * math.pi * k / n
        cells.InsertCellPoint(points.InsertNextPoint(x + r * math.cos(a), y + r * math.sin(a), z))
    vel.InsertNextTuple(velocity.GetTuple(i))
out.SetPoints(points)
out.SetPolys(cells)
out.GetCellData().AddArray(vel)
"""
    return f


def flat(display):
    """Unshaded colours: a ball seen from above is a disk of one colour."""
    display.Ambient = 1.0
    display.Diffuse = 0.0
    return display


def plain(display, rgb):
    """One colour for the whole display, no array."""
    display.ColorArrayName = ["POINTS", ""]
    display.AmbientColor = rgb
    display.DiffuseColor = rgb
    return display


def force_chains(contacts, thinnest, thickest, z=0.0):
    """Grain–grain contacts as tubes whose radius grows with `normal_force`, from `thinnest`
    to `thickest` (m). Shrink (factor 1) gives every line its own end points, so the point
    data made from a contact's cell data is that contact's force alone."""
    grain_pairs = pv.Threshold(Input=contacts, Scalars=["CELLS", "wall"],
                               LowerThreshold=0.0, UpperThreshold=0.5)
    separate = pv.Shrink(Input=grain_pairs, ShrinkFactor=1.0)
    at_points = pv.CellDatatoPointData(Input=separate)
    surface = pv.ExtractSurface(Input=at_points)
    lifted = pv.Transform(Input=surface)
    lifted.Transform.Translate = [0.0, 0.0, z]
    tube = pv.Tube(Input=lifted, Scalars=["POINTS", "normal_force"], VaryRadius="By Scalar",
                   Radius=thinnest, RadiusFactor=thickest / thinnest, NumberofSides=8)
    return tube


def colour(display, view, where, name, component=None, preset="Viridis (matplotlib)",
           title=None, data_range=None):
    """Colour a display by an array, with a horizontal colour bar titled `title`; the map
    spans `data_range` (lo, hi), or the data's range at the shown time if None."""
    key = ("POINTS" if where == "point" else "CELLS", name)
    pv.ColorBy(display, key if component is None else key + (component,))
    lut = pv.GetColorTransferFunction(name)
    lut.ApplyPreset(preset, True)
    if data_range is None:
        display.RescaleTransferFunctionToDataRange(False, True)
    else:
        lut.RescaleTransferFunction(*data_range)
    display.SetScalarBarVisibility(view, True)
    bar = pv.GetScalarBar(lut, view)
    bar.Title = title or name
    bar.ComponentTitle = ""
    bar.TitleColor = [0.0, 0.0, 0.0]
    bar.LabelColor = [0.0, 0.0, 0.0]
    bar.Orientation = "Horizontal"
    bar.WindowLocation = "Any Location"
    bar.Position = [0.3, 0.02]
    bar.ScalarBarLength = 0.4
    return lut


def array_range(data, where, name):
    """(min, max) of a one-component array of a fetched data set."""
    fields = data.GetPointData() if where == "point" else data.GetCellData()
    return fields.GetArray(name).GetRange(0)


def save(view, path, bounds):
    """Frame `bounds` (see `look_at`), render and write the PNG. (The first render resets
    the camera, so the camera is set after it.)"""
    pv.Render(view)
    look_at(view, bounds)
    pv.Render(view)
    pv.SaveScreenshot(path, view, ImageResolution=view.ViewSize, TransparentBackground=0)
    if not os.path.isfile(path) or os.path.getsize(path) == 0:
        fail(f"{path}: ParaView wrote no image")
    print(f"wrote {path}")


def pick_time(reader, requested):
    """The frame time nearest `requested` (s), or the last frame's if None."""
    all_t = times(reader)
    if requested is None:
        return all_t[-1]
    return min(all_t, key=lambda t: abs(t - requested))
