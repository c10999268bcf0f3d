"""Render one time of a Cairn particles.xdmf with ParaView, coloured by an array: the pictures of
README.md and docs/tutorial.md.

  pvbatch --force-offscreen-rendering docs/render_paraview.py OUT/particles.xdmf TIME ARRAY COMPONENT PNG \
      [VIEW [RANGE [SPACING]]]

COMPONENT is a component name (XX, XY, ..., X, Y, Z) or "-" for a scalar; VIEW is "xy" (default,
looking down z) or "iso" (3D); RANGE "lo,hi" fixes the colour range (default: the data's);
SPACING is the particle spacing, for the size of the drawn discs (default 5e-4). Without a display, run it under xvfb-run (package xvfb):
  xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" pvbatch --force-offscreen-rendering ...
Example (the README picture):
  build/release/cairn run examples/two_blocks.toml
  pvbatch --force-offscreen-rendering docs/render_paraview.py examples/out/two_blocks/particles.xdmf \
      5e-4 stress XX docs/two_blocks_stress.png xy -1.2e6,0
"""
import os
import sys

from paraview.simple import (ColorBy, CreateRenderView, GetColorTransferFunction, GetScalarBar,
                             OpenDataFile, ResetCamera, SaveScreenshot, Show)


def main():
    xdmf, time, array, component, png = sys.argv[1:6]
    view_kind = sys.argv[6] if len(sys.argv) > 6 else "xy"
    value_range = [float(v) for v in sys.argv[7].split(",")] if len(sys.argv) > 7 else None
    spacing = float(sys.argv[8]) if len(sys.argv) > 8 else 5e-4
    reader = OpenDataFile(xdmf)
    times = list(reader.TimestepValues)
    time = min(times, key=lambda t: abs(t - float(time)))  # the nearest snapshot
    view = CreateRenderView(ViewSize=[1400, 560] if view_kind == "xy" else [900, 900])
    view.ViewTime = time
    view.OrientationAxesVisibility = 1
    view.Background = [1.0, 1.0, 1.0]
    try:  # ParaView 5.10+ keeps its own background unless told to use this one
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    display = Show(reader, view)
    display.SetRepresentationType("Point Gaussian")
    display.GaussianRadius = 0.5 * spacing
    display.ShaderPreset = "Plain circle"
    ColorBy(display, ("POINTS", array) if component == "-" else ("POINTS", array, component))
    lut = GetColorTransferFunction(array)
    lut.ApplyPreset("Cool to Warm", True)
    if value_range:
        lut.RescaleTransferFunction(*value_range)
    else:
        display.RescaleTransferFunctionToDataRange(False, True)
    bar = GetScalarBar(lut, view)
    bar.Title = f"{array} {component if component != '-' else ''} (t = {time:.3g})"
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0.1, 0.1, 0.1]
    display.SetScalarBarVisibility(view, True)
    if view_kind == "iso":
        view.CameraPosition = [1.0, -1.6, 0.9]
        view.CameraFocalPoint = [0.0, 0.0, 0.0]
        view.CameraViewUp = [0.0, 0.0, 1.0]
    ResetCamera(view)
    if view_kind == "xy":  # fit the particles' box tightly, not their bounding sphere
        view.CameraParallelProjection = 1
        reader.UpdatePipeline(time)
        b = reader.GetDataInformation().GetBounds()
        width, height = b[1] - b[0], b[3] - b[2]
        aspect = view.ViewSize[0] / view.ViewSize[1]
        view.CameraParallelScale = 0.5 * max(1.4 * height, 1.3 * width / aspect)
    SaveScreenshot(png, view, ImageResolution=view.ViewSize)
    print(f"wrote {png} ({array} {component} at t = {time})")


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)  # skip ParaView's teardown (it can fail on Xvfb's software GLX after success)
