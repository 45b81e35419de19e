"""Render the fluid of a granflow run, with the grains or obstacles in front of it.

    pvpython scripts/paraview/fluid.py RUN_DIR OUT.png [--field pressure|vorticity|speed]
                                       [--time T] [--size W H]

For `fluid` and `submerged` runs. The lattice's cell data are drawn as they are (one flat
colour per cell): `pressure` (Pa) on a sequential map, `vorticity` (1/s, counter-clockwise
positive) on a diverging map centred on 0, `speed` = |velocity| (m/s). A submerged run's grains
are drawn over the fluid as light grey disks of their radius; a fluid run's obstacle cells
(`solid` = 1) in grey. T is the frame's simulated time in s (nearest frame; the last if
omitted).
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import granflow_pv as g  # noqa: E402
from paraview import simple as pv  # noqa: E402

GREY = [0.75, 0.75, 0.75]


def main():
    a = g.render_arguments(__doc__,
                           ("--field", dict(choices=["pressure", "vorticity", "speed"],
                                            default="vorticity")))
    reader, kind = g.open_run(a.run)
    if kind not in ("fluid", "submerged"):
        g.fail(f"{a.run}: a {kind} run has no fluid")
    k = 0 if kind == "fluid" else 2
    t = g.pick_time(reader, a.time)
    lattice = g.fetch_part(reader, k, t)
    x0, x1, y0, y1, _, _ = lattice.GetBounds()
    view = g.render_view(a.size[0], a.size[1], t)

    fluid = g.flat(pv.Show(g.part(reader, k), view))
    fluid.Representation = "Surface"
    if a.field == "vorticity":
        lo, hi = g.array_range(lattice, "cell", "vorticity")
        m = max(abs(lo), abs(hi), 1e-300)
        g.colour(fluid, view, "cell", "vorticity", preset="Cool to Warm",
                 title="vorticity (1/s)", data_range=(-m, m))
    elif a.field == "pressure":
        g.colour(fluid, view, "cell", "pressure", title="pressure (Pa)")
    else:
        g.colour(fluid, view, "cell", "velocity", "Magnitude", title="speed (m/s)")

    lift = 1e-3 * max(x1 - x0, y1 - y0)
    if kind == "submerged":
        grains = g.flat(pv.Show(g.disks(g.part(reader, 0), z=lift), view))
        g.plain(grains, GREY)
    else:
        cells = pv.Threshold(Input=g.part(reader, k), Scalars=["CELLS", "solid"],
                             LowerThreshold=0.5, UpperThreshold=1.5)
        lifted = pv.Transform(Input=cells)
        lifted.Transform.Translate = [0.0, 0.0, lift]
        solid = g.flat(pv.Show(lifted, view))
        g.plain(solid, GREY)
    g.save(view, a.png, (x0, x1, y0, y1))


main()
