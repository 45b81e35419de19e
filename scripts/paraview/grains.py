"""Render the grains of a granflow run as disks coloured by speed, with the force chains.

    pvpython scripts/paraview/grains.py RUN_DIR OUT.png [--time T] [--size W H]

For `dem`, `granular` and `submerged` runs. Grains are filled circles of their own radius
(polygon grains, a collapse with `grains.sides`: regular polygons from `radius` and `angle`),
coloured by |velocity| (m/s); grain–grain contacts are black tubes from centre to centre whose
width grows linearly with the normal force, from 0.04 to 0.5 of the mean grain radius at the
frame's largest force. T is the simulated time (s) of the frame (the nearest frame is taken;
the last frame if omitted).
"""

import builtins
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import granflow_pv as g  # noqa: E402
from paraview import simple as pv  # noqa: E402


def main():
    a = g.render_arguments(__doc__)
    reader, kind = g.open_run(a.run)
    if kind not in ("dem", "granular", "submerged"):
        g.fail(f"{a.run}: a {kind} run has no grains (fluid.py and points.py draw the others)")
    t = g.pick_time(reader, a.time)
    grains = g.fetch_part(reader, 0, t)
    if grains.GetNumberOfPoints() == 0:
        g.fail(f"{a.run}: the frame at t = {t} s has no grains")
    radius = grains.GetPointData().GetArray("radius")
    mean_r = sum(radius.GetValue(i) for i in range(radius.GetNumberOfTuples())) / radius.GetNumberOfTuples()
    x0, x1, y0, y1, _, _ = grains.GetBounds()
    r_max = radius.GetRange(0)[1]
    bounds = (x0 - 2 * r_max, x1 + 2 * r_max, y0 - 2 * r_max, y1 + 2 * r_max)

    view = g.render_view(a.size[0], a.size[1], t)
    sides = g.scenario(a.run).get("grains", {}).get("sides")
    if sides:
        drawn = g.polygons(g.part(reader, 0), sides)
        shown = g.flat(pv.Show(drawn, view))
        g.colour(shown, view, "cell", "velocity", "Magnitude", title="speed (m/s)")
        pv.UpdatePipeline(t, drawn)
        print(f"polygons: {drawn.GetDataInformation().GetNumberOfCells()} of {sides} sides")
    else:
        shown = g.flat(pv.Show(g.disks(g.part(reader, 0)), view))
        g.colour(shown, view, "point", "velocity", "Magnitude", title="speed (m/s)")

    contacts = g.fetch_part(reader, 1, t)
    if "normal_force" in g.arrays(contacts, "cell"):
        # builtins.max: running a Programmable Filter (polygons) star-imports VTK's numpy
        # algorithms, whose `max` replaces the builtin in this module.
        f_max = builtins.max(g.array_range(contacts, "cell", "normal_force")[1], 1e-300)
        chains = g.force_chains(g.part(reader, 1), 0.04 * mean_r, 0.5 * mean_r, z=2 * r_max)
        # Tube's "By Scalar" maps the scalar range onto Radius … Radius × RadiusFactor.
        line = pv.Show(chains, view)
        g.plain(line, [0.0, 0.0, 0.0])
        print(f"force chains: largest normal force {f_max:.3e} N")
    g.save(view, a.png, bounds)


main()
