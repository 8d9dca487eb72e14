#!/usr/bin/python3
"""VTK's CPU volume ray caster as the baseline of `synthvis bench` on volume scenes (BENCH.md
`volume`, issue 33): vtkFixedPointVolumeRayCastMapper, from Debian's python3-vtk9, drawing the
volumes synthvis draws — the same 16-bit codes, transfer function, opacity unit, sample distance,
light, camera and image size — in an X window (run under Xvfb: `xvfb-run -a`).

synthvis (src/reference/vtk_volume.cpp) starts this script with a job file and drives it a frame at
a time over stdin and stdout, so that its frames alternate with synthvis's in the same run:

    render        -> "ms <milliseconds>"   one frame: the ray cast and its display
    image <path>  -> "ok"                  the last frame, 8-bit RGB rows top down, no header
    quit

The job (JSON) holds width, height, threads, background (linear RGB), camera {position, target,
up, yfov, near, far}, light {on, direction (travelling), color, ambient} and volumes: each {raw (a
file of little-endian uint16 codes, x fastest), dims, spacing, matrix (own space → world,
4×4 row-major), transfer [[code, r, g, b, opacity], …], opacity_unit (world), sample_distance
(world), shaded}. Colours are linear: VTK composites them as given, and the read-back image is
encoded to sRGB as synthvis's is (not timed). Every failure is one line on stderr and exit 1.
"""
import json
import os
import sys
import time


def fail(message):
    sys.stderr.write(f"vtk_volume: {message}\n")
    sys.exit(1)


try:
    import vtk
except ImportError as e:
    fail(f"python3-vtk9 is not installed ({e})")


def srgb_table():
    table = []
    for i in range(256):
        c = i / 255.0
        v = 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1 / 2.4) - 0.055
        table.append(min(255, max(0, round(v * 255))))
    return bytes(table)


def make_volume(v):
    nx, ny, nz = v["dims"]
    try:
        size = os.path.getsize(v["raw"])
    except OSError as e:
        fail(f"{v['raw']}: {e.strerror}")
    if size != 2 * nx * ny * nz:
        fail(f"{v['raw']}: {size} bytes, expected 2·{nx}·{ny}·{nz}")
    reader = vtk.vtkImageReader2()
    reader.SetFileName(v["raw"])
    reader.SetFileDimensionality(3)
    reader.SetDataScalarTypeToUnsignedShort()
    reader.SetDataByteOrderToLittleEndian()
    reader.SetNumberOfScalarComponents(1)
    reader.SetDataExtent(0, nx - 1, 0, ny - 1, 0, nz - 1)
    reader.SetDataSpacing(*v["spacing"])
    reader.SetDataOrigin(0, 0, 0)
    reader.FileLowerLeftOn()  # row 0 is y = 0, as synthvis's grids
    reader.Update()
    image = reader.GetOutput()

    color = vtk.vtkColorTransferFunction()
    opacity = vtk.vtkPiecewiseFunction()
    for code, r, g, b, a in v["transfer"]:
        color.AddRGBPoint(code, r, g, b)
        opacity.AddPoint(code, a)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(v["opacity_unit"])
    prop.SetInterpolationTypeToLinear()
    if v["shaded"]:
        prop.ShadeOn()
        prop.SetAmbient(v["ambient"])
        prop.SetDiffuse(1 - v["ambient"])
        prop.SetSpecular(0)
    else:
        prop.ShadeOff()

    mapper = vtk.vtkFixedPointVolumeRayCastMapper()
    mapper.SetInputData(image)
    mapper.SetNumberOfThreads(v["threads"])
    mapper.AutoAdjustSampleDistancesOff()
    mapper.LockSampleDistanceToInputSpacingOff()
    mapper.SetSampleDistance(v["sample_distance"])
    mapper.SetImageSampleDistance(1.0)

    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    matrix = vtk.vtkMatrix4x4()
    for row in range(4):
        for col in range(4):
            matrix.SetElement(row, col, v["matrix"][row * 4 + col])
    volume.SetUserMatrix(matrix)
    return volume


def main():
    if len(sys.argv) != 2:
        fail("usage: vtk_volume.py JOB.json")
    try:
        with open(sys.argv[1]) as f:
            job = json.load(f)
    except (OSError, ValueError) as e:
        fail(f"{sys.argv[1]}: {e}")

    renderer = vtk.vtkRenderer()
    renderer.SetBackground(*job["background"])
    renderer.AutomaticLightCreationOff()
    light = job["light"]
    if light["on"]:
        # synthvis lights a volume's gradient two-sided, by |n·l| (it points either way through a
        # surface); VTK's shading tables take max(n·l, 0): a second light, opposite, adds the other
        # side's max(−n·l, 0).
        d = light["direction"]
        for sign in (1, -1):
            sun = vtk.vtkLight()
            sun.SetLightTypeToSceneLight()
            sun.PositionalOff()
            sun.SetPosition(-sign * d[0], -sign * d[1], -sign * d[2])
            sun.SetFocalPoint(0, 0, 0)
            sun.SetColor(*light["color"])
            sun.SetIntensity(1.0)
            renderer.AddLight(sun)
    for v in job["volumes"]:
        v["threads"] = job["threads"]
        v["ambient"] = light["ambient"]
        renderer.AddVolume(make_volume(v))

    cam = job["camera"]
    camera = renderer.GetActiveCamera()
    camera.SetPosition(*cam["position"])
    camera.SetFocalPoint(*cam["target"])
    camera.SetViewUp(*cam["up"])
    camera.SetViewAngle(cam["yfov"])
    camera.SetClippingRange(cam["near"], cam["far"])

    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(job["width"], job["height"])
    window.AddRenderer(renderer)
    window.SetMultiSamples(0)
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    encode = srgb_table()

    sys.stdout.write(f"ready VTK {vtk.vtkVersion.GetVTKVersion()}\n")
    sys.stdout.flush()
    for line in sys.stdin:
        words = line.split()
        if not words:
            continue
        if words[0] == "render":
            t0 = time.perf_counter()
            window.Render()
            ms = (time.perf_counter() - t0) * 1e3
            sys.stdout.write(f"ms {ms:.4f}\n")
        elif words[0] == "image" and len(words) == 2:
            grab.Modified()
            grab.Update()
            out = grab.GetOutput()
            w, h, _ = out.GetDimensions()
            rgb = bytes(memoryview(out.GetPointData().GetScalars())).translate(encode)
            stride = 3 * w
            with open(words[1], "wb") as f:
                for y in range(h - 1, -1, -1):  # VTK's rows run bottom up
                    f.write(rgb[y * stride:(y + 1) * stride])
            sys.stdout.write("ok\n")
        elif words[0] == "quit":
            break
        else:
            fail(f"unknown request '{line.strip()}'")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
