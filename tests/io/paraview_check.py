"""Open Cairn's XDMF outputs with ParaView's own readers and check what a user would see.

Run under pvbatch (Debian's `paraview` + `python3-paraview`), offscreen:
  pvbatch --force-offscreen-rendering paraview_check.py SPEC.json
SPEC lists, per case, the output folder and what ParaView must show (computed by
test_paraview.py from the input and the HDF5 files, not from ParaView). Prints one line per check
and exits non-zero on the first failure.
"""
import json
import math
import os
import sys

from paraview.simple import (ColorBy, CreateRenderView, Delete, GetActiveViewOrCreate,
                             OpenDataFile, ResetCamera, SaveScreenshot, Show, XDMFReader)
from paraview import servermanager


class CheckFailed(Exception):
    pass


def check(cond, message):
    if not cond:
        raise CheckFailed(message)
    print("  ok:", message.split(":")[0] if ":" in message else message)


def arrays(source):
    out = {}
    pd = source.PointData
    for name in pd.keys():
        a = pd[name]
        n = a.GetNumberOfComponents()
        out[name] = {
            "components": [a.GetComponentName(i) for i in range(n)] if n > 1 else [],
            "ranges": [a.GetRange(i) for i in range(n)],
        }
    return out


def check_dataset(label, source, time, expect):
    source.UpdatePipeline(time)
    info = source.GetDataInformation()
    points, cells = info.GetNumberOfPoints(), info.GetNumberOfCells()
    check(points == expect["points"], f"{label} points: ParaView shows {points}, expected {expect['points']}")
    check(cells == expect["cells"], f"{label} cells: ParaView shows {cells}, expected {expect['cells']}")
    bounds = info.GetBounds()
    for k, (lo, hi) in enumerate(zip(expect["bounds"][0::2], expect["bounds"][1::2])):
        tol = 1e-9 + 1e-6 * max(abs(lo), abs(hi), 1e-3)
        check(abs(bounds[2 * k] - lo) <= tol and abs(bounds[2 * k + 1] - hi) <= tol,
              f"{label} bounds on axis {'xyz'[k]}: ParaView shows [{bounds[2 * k]}, {bounds[2 * k + 1]}], "
              f"expected [{lo}, {hi}]")
    found = arrays(source)
    for name, components in expect["arrays"].items():
        check(name in found, f"{label} array {name}: missing; ParaView shows {sorted(found)}")
        check(found[name]["components"] == components,
              f"{label} array {name} components: ParaView shows {found[name]['components']}, expected {components}")
    for name, comp, lo, hi in expect.get("ranges", []):
        index = expect["arrays"][name].index(comp) if comp else 0
        r = found[name]["ranges"][index]
        tol = 1e-9 * max(abs(lo), abs(hi), 1.0)
        check(abs(r[0] - lo) <= tol and abs(r[1] - hi) <= tol,
              f"{label} {name} {comp or ''} range: ParaView shows {r}, the HDF5 file has [{lo}, {hi}]")
    return found


def check_times(label, source, times):
    shown = list(source.TimestepValues)
    check(len(shown) == len(times) and all(math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-300) for a, b in zip(shown, times)),
          f"{label} time steps: ParaView shows {shown}, the snapshots have {times}")


def render(source, time, array, component, png, size):
    view = CreateRenderView(ViewSize=size)
    view.ViewTime = time
    view.OrientationAxesVisibility = 0
    display = Show(source, view)
    display.SetRepresentationType("Points")
    display.PointSize = 4
    ColorBy(display, ("POINTS", array, component))
    display.RescaleTransferFunctionToDataRange(True, False)
    display.SetScalarBarVisibility(view, True)
    ResetCamera(view)
    SaveScreenshot(png, view, ImageResolution=size)
    # The picture must show something: more than one colour among its pixels.
    from vtkmodules.vtkIOImage import vtkPNGReader
    reader = vtkPNGReader()
    reader.SetFileName(png)
    reader.Update()
    scalars = reader.GetOutput().GetPointData().GetScalars()
    colours = {tuple(int(scalars.GetComponent(i, c)) for c in range(3))
               for i in range(0, scalars.GetNumberOfTuples(), 7)}
    check(len(colours) > 20, f"{png}: {len(colours)} distinct colours in the rendered picture")


def main():
    spec = json.load(open(sys.argv[1]))
    try:
        for case in spec["cases"]:
            label = case["label"]
            print(f"{label}: {case['particles_xdmf']}")
            # The default way: OpenDataFile picks the XDMF 3 reader.
            particles = OpenDataFile(case["particles_xdmf"])
            check(particles.GetXMLName().startswith("Xdmf3Reader"),
                  f"{label}: OpenDataFile chose {particles.GetXMLName()}, expected an Xdmf3 reader")
            check_times(f"{label} particles", particles, case["times"])
            last = case["times"][-1]
            check_dataset(f"{label} particles", particles, last, case["particles"])
            render(particles, last, "stress", "XX", case["png"], case["png_size"])
            # The legacy XDMF (2) reader shows the particles too.
            legacy = XDMFReader(FileNames=[case["particles_xdmf"]])
            legacy.UpdatePipeline(last)
            check(legacy.GetDataInformation().GetNumberOfCells() == case["particles"]["cells"],
                  f"{label} particles, legacy XDMF reader: {legacy.GetDataInformation().GetNumberOfCells()} "
                  f"cells, expected {case['particles']['cells']}")
            Delete(legacy)
            grid = OpenDataFile(case["grid_xdmf"])
            check_times(f"{label} grid", grid, case["times"])
            check_dataset(f"{label} grid", grid, last, case["grid"])
            legacy = XDMFReader(FileNames=[case["grid_xdmf"]])
            check_dataset(f"{label} grid, legacy XDMF reader", legacy, last, case["grid"])
            Delete(legacy)
    except CheckFailed as e:
        print(f"FAIL: {e}", file=sys.stderr)
        return 1
    print("RESULT: ParaView reads every output as expected")
    return 0


if __name__ == "__main__":
    status = main()
    # Leave without ParaView's teardown: on Xvfb's software GLX, Debian's ParaView 5.11 can fail
    # at exit with "GLXBadContext" after everything above succeeded, turning a pass into exit 1.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)
