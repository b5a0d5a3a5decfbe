"""ParaView 5.11 opens chansph's particle snapshots with its default reader (issue 13, point 11):
run by pvpython (tests/paraview_check.sh). The reader ParaView picks for particles.xdmf must
give, at the first snapshot's time, as many points and vertex cells as particles.nc has fluid
particles, the attributes velocity, pressure, density (and eddy_viscosity with --les), and a
Points render of them must not be blank (pixels other than the background).
usage: pvpython paraview_check.py RUN_DIR PNG [--les]"""
import os
import sys

from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetAnimationScene, OpenDataFile,
                             Render, SaveScreenshot, Show)
from vtkmodules.vtkIOImage import vtkPNGReader
from vtkmodules.util.numpy_support import vtk_to_numpy
import netCDF4

run, png = sys.argv[1], sys.argv[2]
les = "--les" in sys.argv[3:]
with netCDF4.Dataset(os.path.join(run, "particles.nc")) as d:
    n = len(d.dimensions["particle"])
r = OpenDataFile(os.path.join(run, "snapshots", "particles.xdmf"))
reader = r.GetXMLName()
tv = r.TimestepValues  # a float, not a list, for a single snapshot
times = list(tv) if hasattr(tv, "__iter__") else [tv]
# as the GUI does after Apply: the animation goes to the data's first time step (a temporal
# Xdmf3 reader asked for no time at all, UpdatePipeline() without a time, returns nothing)
GetAnimationScene().UpdateAnimationUsingDataTimeSteps()
r.UpdatePipeline(times[0])
info = r.GetDataInformation()
points, cells = info.GetNumberOfPoints(), info.GetNumberOfCells()
arrays = sorted(r.PointData.keys())
want = ["density", "pressure", "velocity"] + (["eddy_viscosity"] if les else [])
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [600, 300]
view.UseColorPaletteForBackground = 0
view.Background = [0.0, 0.0, 0.0]
view.OrientationAxesVisibility = 0
shown = Show(r, view)
shown.SetRepresentationType("Points")
shown.PointSize = 3
ColorBy(shown, ("POINTS", "eddy_viscosity" if les else "pressure"))
shown.RescaleTransferFunctionToDataRange(True)
view.ResetCamera()
Render(view)
SaveScreenshot(png, view, ImageResolution=[600, 300])
img = vtkPNGReader()
img.SetFileName(png)
img.Update()
pix = vtk_to_numpy(img.GetOutput().GetPointData().GetScalars())
lit = int((pix[:, :3].astype(int).sum(axis=1) > 0).sum())
print(f"{reader}: {len(times)} time steps, at t = {times[0]:.6g}: {points} points, {cells} cells "
      f"(particles.nc: {n}), point arrays {arrays}; Points render {png}: {lit} of {len(pix)} "
      f"pixels lit")
ok = points == n and cells == n and all(a in arrays for a in want) and lit > 0.005 * len(pix)
print("PASS" if ok else "FAIL", flush=True)
# leave without pvpython's teardown, which under Xvfb can fail with GLXBadContext after the
# check is done
os._exit(0 if ok else 1)
