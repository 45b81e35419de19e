"""Check that ParaView reads every frame of a granflow run and finds the advertised arrays.

    pvpython scripts/paraview/check_run.py RUN_DIR

Opens RUN_DIR/series.pvd with ParaView's PVD reader, loads every time step, and checks each
part of each frame: the data set is there, and every array docs/output.md lists for the
run's kind is present (a contacts part with no touching contact holds vertices and no arrays,
as documented). Exits with status 1 naming the first missing piece.
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import granflow_pv as g  # noqa: E402

VTK_VERTEX = 1


def main():
    if len(sys.argv) != 2:
        g.fail("usage: pvpython check_run.py RUN_DIR")
    run = sys.argv[1]
    reader, kind = g.open_run(run)
    frames = g.times(reader)
    for t in frames:
        for k, name, where, wanted in g.ADVERTISED[kind]:
            data = g.fetch_part(reader, k, t)
            if name == "contacts" and all(
                    data.GetCellType(c) == VTK_VERTEX for c in range(data.GetNumberOfCells())):
                continue  # no touching contact in this frame
            have = g.arrays(data, where)
            missing = [a for a in wanted if a not in have]
            if missing:
                g.fail(f"{run}: frame at t = {t} s, part {k} ({name}): {where} arrays "
                       f"{missing} missing (found {have})")
    print(f"{run}: {kind}, {len(frames)} frames, every advertised array present")


main()
