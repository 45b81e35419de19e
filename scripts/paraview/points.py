"""Render the material points of a granflow MPM run, each as the square of its own area.

    pvpython scripts/paraview/points.py RUN_DIR OUT.png
                 [--field mean_stress|deviatoric_stress|plastic_strain|speed]
                 [--time T] [--size W H]

For `mpm` runs. A point of area V (the `volume` array, m³ per metre of depth) is drawn as a
filled square of side √V centred on it, coloured by the chosen field: `mean_stress` (Pa,
tension positive, so negative in a resting column), `deviatoric_stress` (Pa),
`plastic_strain` (continuum laws only) or `speed` = |velocity| (m/s). T is the frame's
simulated time in s (nearest frame; the last if omitted).
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import granflow_pv as g  # noqa: E402
from paraview import simple as pv  # noqa: E402


def main():
    a = g.render_arguments(__doc__,
                           ("--field", dict(default="mean_stress", choices=[
                               "mean_stress", "deviatoric_stress", "plastic_strain", "speed"])))
    reader, kind = g.open_run(a.run)
    if kind != "mpm":
        g.fail(f"{a.run}: a {kind} run has no material points")
    t = g.pick_time(reader, a.time)
    points = g.fetch_part(reader, 0, t)
    if a.field != "speed" and a.field not in g.arrays(points, "point"):
        g.fail(f"{a.run}: the points have no `{a.field}` array (an rve material has none)")
    x0, x1, y0, y1, _, _ = points.GetBounds()
    side = g.array_range(points, "point", "volume")[1] ** 0.5
    bounds = (x0 - side, x1 + side, y0 - side, y1 + side)

    view = g.render_view(a.size[0], a.size[1], t)
    sides = pv.Calculator(Input=g.part(reader, 0), ResultArrayName="side",
                          Function="sqrt(volume)")
    squares = pv.Glyph(Input=sides, GlyphType="2D Glyph")
    squares.GlyphType.GlyphType = "Square"
    squares.GlyphType.Filled = 1
    squares.OrientationArray = ["POINTS", "No orientation array"]
    squares.ScaleArray = ["POINTS", "side"]
    squares.ScaleFactor = 1.0
    squares.GlyphMode = "All Points"
    shown = g.flat(pv.Show(squares, view))
    if a.field == "speed":
        g.colour(shown, view, "point", "velocity", "Magnitude", title="speed (m/s)")
    else:
        unit = " (Pa)" if a.field.endswith("stress") else ""
        g.colour(shown, view, "point", a.field, title=a.field + unit)
    g.save(view, a.png, bounds)


main()
