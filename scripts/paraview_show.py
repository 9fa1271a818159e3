"""Shows an icd run in ParaView: run with ParaView's Python, e.g.

    pvpython scripts/paraview_show.py results/main            # interactive window
    pvpython scripts/paraview_show.py results/main --save run.png   # last frame to a PNG
    pvbatch  scripts/paraview_show.py results/main --animation frames/run.png

It reads the run's collection vtu/run.pvd (every part of every written
frame) and loads each part as its own time series: the dense meshes (coloured
by displacement magnitude), the coarse tet meshes (wireframe, hidden when a
dense mesh exists) and the contact spheres drawn as sphere glyphs scaled by
their "radius" array (red: colliding leaves; grey: untested pairs). In the
ParaView GUI instead: File > Open run.pvd, then Filters > Glyph on a
contact-spheres block with Glyph Type Sphere, Scale Array "radius", Scale
Factor 2 (the sphere glyph has radius 0.5) and Glyph Mode "All Points".

Written against the paraview.simple API (ParaView 5.10+); ParaView is not
installed where icd is tested, so this script has not been run there.
"""
import argparse
import collections
import os
import xml.etree.ElementTree as ET

from paraview.simple import (  # noqa: E402 - pvpython provides paraview.simple
    ColorBy, GetActiveViewOrCreate, GetAnimationScene, Glyph, Hide, Interact, Render,
    ResetCamera, SaveAnimation, SaveScreenshot, Show, XMLUnstructuredGridReader)


def parts_of(pvd):
    """{part number: (label, [files in time order])} from a run.pvd."""
    folder = os.path.dirname(os.path.abspath(pvd))
    parts = collections.defaultdict(list)
    for d in ET.parse(pvd).getroot().iter("DataSet"):
        parts[int(d.get("part", "0"))].append((float(d.get("timestep")), d.get("file")))
    out = {}
    for p, entries in sorted(parts.items()):
        entries.sort()
        files = [os.path.join(folder, f) for _, f in entries]
        label = os.path.basename(files[0]).rsplit("_", 1)[0]  # <object>_coarse, ..._pair0
        out[p] = (label, files)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run", help="results folder of icd-run / icd-main (holding vtu/run.pvd)")
    ap.add_argument("--save", help="write the last frame to this PNG instead of a window")
    ap.add_argument("--animation", help="write every frame to PNGs named like this")
    args = ap.parse_args()
    pvd = os.path.join(args.run, "vtu", "run.pvd")
    parts = parts_of(pvd)
    view = GetActiveViewOrCreate("RenderView")
    dense_objects = {label[: -len("_dense")] for label, _ in parts.values()
                     if label.endswith("_dense")}
    for label, files in parts.values():
        reader = XMLUnstructuredGridReader(registrationName=label, FileName=files)
        if hasattr(reader, "TimeArray"):
            reader.TimeArray = "TimeValue"  # each file's simulated time (s)
        if "_contact_spheres" in label:
            glyph = Glyph(registrationName=label + "_glyphs", Input=reader, GlyphType="Sphere")
            glyph.OrientationArray = ["POINTS", "No orientation array"]
            glyph.ScaleArray = ["POINTS", "radius"]
            glyph.ScaleFactor = 2.0  # the sphere glyph's radius is 0.5
            glyph.GlyphMode = "All Points"
            display = Show(glyph, view)
            ColorBy(display, ("POINTS", "colliding_leaf"))
            lut = display.LookupTable
            lut.RGBPoints = [0.0, 0.6, 0.6, 0.6, 1.0, 0.85, 0.1, 0.1]
            display.Opacity = 0.6
            Hide(reader, view)
        else:
            display = Show(reader, view)
            ColorBy(display, ("POINTS", "displacement", "Magnitude"))
            if label.endswith("_coarse"):
                display.SetRepresentationType("Wireframe")
                if label[: -len("_coarse")] in dense_objects:
                    Hide(reader, view)
    ResetCamera(view)
    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    if args.animation:
        SaveAnimation(args.animation, view)
    elif args.save:
        scene.AnimationTime = scene.EndTime
        Render(view)
        SaveScreenshot(args.save, view)
    else:
        Render(view)
        Interact(view)


if __name__ == "__main__":
    main()
