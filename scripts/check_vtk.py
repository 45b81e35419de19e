#!/usr/bin/env python3
"""Open granflow output files with VTK itself and print what VTK sees.

Usage: check_vtk.py [--json OUT] FILE [FILE ...]    (FILE: .vti, .vtu or .pvd)

For each data set: the data set type, number of points and cells, dimensions / spacing /
origin for images, then every point and cell array with its number of tuples, components and
range per component (and all values of arrays of at most 12 tuples, since VTK reads a payload
of the wrong size without complaint). A .pvd is read with vtkPVDReader when this VTK build has it; otherwise the
collection XML is parsed here and every listed file is read in turn.

Exits non-zero if VTK reports an error or a warning while reading, or if an array does not
have one tuple per point/cell. (An empty data set is reported but is not an error.) Needs the `vtk` package (pip install vtk).

With `--json OUT`, every .vti/.vtu file's arrays as VTK read them are also written to OUT:
{file: {"points": [x, y, z, ...], "cell_types": [...], "point": {name: [values]},
"cell": {name: [values]}}}, values flattened tuple by tuple (the tests compare them with what
was written).
"""

import json

import os
import sys
import xml.etree.ElementTree as ET

import vtk

# Arrays with at most this many tuples are printed in full.
SHOW_VALUES = 12


class ErrorObserver:
    """Collects VTK error and warning events (which VTK otherwise only prints)."""

    def __init__(self):
        self.messages = []

    def __call__(self, obj, event):
        self.messages.append(f"{event} from {obj.GetClassName()}")


def watch(obj, observer):
    obj.AddObserver("ErrorEvent", observer)
    obj.AddObserver("WarningEvent", observer)
    # Also catch messages sent to the global output window.
    return obj


# Filled by describe() when --json is given: file label -> what VTK read.
DUMP = None


def flat(arr):
    """Every value of a numeric VTK array, tuple by tuple."""
    n = arr.GetNumberOfTuples() * arr.GetNumberOfComponents()
    return [arr.GetValue(i) for i in range(n)]


def describe_arrays(kind, data, expected, problems, dump=None):
    n = data.GetNumberOfArrays()
    for k in range(n):
        arr = data.GetAbstractArray(k)
        name = arr.GetName()
        ncomp = arr.GetNumberOfComponents()
        ntup = arr.GetNumberOfTuples()
        if dump is not None:
            dump[name] = flat(arr)
        ranges = []
        if hasattr(arr, "GetRange"):
            for c in range(ncomp):
                lo, hi = arr.GetRange(c)
                ranges.append(f"[{lo:.17g}, {hi:.17g}]")
        print(
            f"    {kind} array {name!r}: {arr.GetDataTypeAsString()}, "
            f"{ntup} tuples x {ncomp} components, range {' '.join(ranges)}"
        )
        if ntup <= SHOW_VALUES and hasattr(arr, "GetTuple"):
            # VTK does not notice a payload of the wrong size or header width (it reads
            # garbage), so show small arrays in full for a human to compare.
            values = [arr.GetTuple(t) for t in range(ntup)]
            print("      values " + " ".join(
                "(" + ", ".join(f"{v:.17g}" for v in tup) + ")" if ncomp > 1 else f"{tup[0]:.17g}"
                for tup in values))
        if ntup != expected:
            problems.append(f"{kind} array {name!r} has {ntup} tuples, expected {expected}")
    if n == 0:
        print(f"    ({kind} data: no arrays)")


def describe(ds, label, problems, path=None):
    print(f"  {label}: {ds.GetClassName()}, {ds.GetNumberOfPoints()} points, "
          f"{ds.GetNumberOfCells()} cells")
    if ds.IsA("vtkImageData"):
        print(f"    dimensions {ds.GetDimensions()} (points), extent {ds.GetExtent()}, "
              f"spacing {ds.GetSpacing()}, origin {ds.GetOrigin()}")
    if ds.IsA("vtkUnstructuredGrid") and ds.GetNumberOfCells() > 0:
        types = sorted({ds.GetCellType(c) for c in range(ds.GetNumberOfCells())})
        util = getattr(vtk, "vtkCellTypeUtilities", vtk.vtkCellTypes)
        names = [util.GetClassNameFromTypeId(t) for t in types]
        print(f"    cell types {types} {names}")
        first = ds.GetCell(0)
        ids = [first.GetPointId(i) for i in range(first.GetNumberOfPoints())]
        print(f"    cell 0 point ids {ids}")
    if ds.GetNumberOfPoints() == 0 and ds.GetNumberOfCells() == 0:
        print("    (empty data set)")
    entry = None
    if DUMP is not None and path is not None:
        entry = {"point": {}, "cell": {}, "points": [], "cell_types": []}
        if ds.IsA("vtkPointSet") and ds.GetPoints() is not None:
            entry["points"] = flat(ds.GetPoints().GetData())
        if ds.IsA("vtkUnstructuredGrid"):
            entry["cell_types"] = [ds.GetCellType(c) for c in range(ds.GetNumberOfCells())]
        DUMP[path] = entry
    describe_arrays("point", ds.GetPointData(), ds.GetNumberOfPoints(), problems,
                    entry and entry["point"])
    describe_arrays("cell", ds.GetCellData(), ds.GetNumberOfCells(), problems,
                    entry and entry["cell"])


def read_file(path, problems):
    ext = os.path.splitext(path)[1].lower()
    readers = {
        ".vti": vtk.vtkXMLImageDataReader,
        ".vtu": vtk.vtkXMLUnstructuredGridReader,
    }
    if ext not in readers:
        problems.append(f"{path}: unsupported extension {ext}")
        return
    observer = ErrorObserver()
    reader = watch(readers[ext](), observer)
    reader.SetFileName(path)
    if not reader.CanReadFile(path):
        problems.append(f"{path}: reader says it cannot read this file")
    reader.Update()
    problems.extend(f"{path}: {m}" for m in observer.messages)
    print(f"{path}")
    describe(reader.GetOutput(), os.path.basename(path), problems, path)


def walk_composite(data, problems, label="block"):
    if data is None:
        return
    if data.IsA("vtkCompositeDataSet"):
        it = data.NewIterator()
        it.InitTraversal()
        k = 0
        while not it.IsDoneWithTraversal():
            describe(it.GetCurrentDataObject(), f"{label} {k}", problems)
            k += 1
            it.GoToNextItem()
        if k == 0:
            problems.append("collection output has no blocks")
    else:
        describe(data, label, problems)


def read_pvd(path, problems):
    base = os.path.dirname(os.path.abspath(path))
    root = ET.parse(path).getroot()
    entries = [
        (float(d.get("timestep")), int(d.get("part", "0")), d.get("file"))
        for d in root.iter("DataSet")
    ]
    print(f"{path}: {len(entries)} DataSet entries, "
          f"times {sorted({t for t, _, _ in entries})}")
    if not entries:
        problems.append(f"{path}: no DataSet entries")
    if hasattr(vtk, "vtkPVDReader"):
        # vtkPVDReader ships with ParaView-flavoured VTK builds only.
        observer = ErrorObserver()
        reader = watch(vtk.vtkPVDReader(), observer)
        reader.SetFileName(path)
        reader.UpdateInformation()
        n = reader.GetNumberOfTimeSteps()
        print(f"  vtkPVDReader: {n} time steps")
        for k in range(n):
            reader.UpdateTimeStep(reader.GetTimeStep(k))
            walk_composite(reader.GetOutputDataObject(0), problems, f"step {k}")
        problems.extend(f"{path}: {m}" for m in observer.messages)
    else:
        print("  (this VTK has no vtkPVDReader; reading each listed file)")
        for t, part, name in entries:
            print(f"  t = {t!r}, part {part}:")
            read_file(os.path.join(base, name), problems)


def main(argv):
    global DUMP
    out = None
    if len(argv) > 2 and argv[1] == "--json":
        out, DUMP = argv[2], {}
        argv = argv[:1] + argv[3:]
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    # Capture VTK's global message window too, so that errors raised outside the readers
    # (e.g. by the XML parser) are not just printed and forgotten.
    window = vtk.vtkStringOutputWindow()
    vtk.vtkOutputWindow.SetInstance(window)
    print(f"VTK {vtk.vtkVersion.GetVTKVersion()}")
    problems = []
    for path in argv[1:]:
        if not os.path.isfile(path):
            problems.append(f"{path}: no such file")
            continue
        if path.lower().endswith(".pvd"):
            read_pvd(path, problems)
        else:
            read_file(path, problems)
    messages = window.GetOutput().strip()
    if messages:
        problems.append(f"VTK printed: {messages}")
    if out is not None:
        with open(out, "w") as f:
            json.dump(DUMP, f)
    if problems:
        print("PROBLEMS:")
        for p in problems:
            print(f"  {p}")
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
