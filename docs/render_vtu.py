#!/usr/bin/env python3
"""docs/render_vtu.py - renders one frame of sph.h's ParaView output with VTK itself (the library
ParaView is built on), as a check that the files are what a VTK reader expects and to make the
picture docs/paraview_dambreak.png. Needs Debian's python3-vtk9 and a display (xvfb-run):

    make paraview
    xvfb-run -a /usr/bin/python3 docs/render_vtu.py out/paraview/dambreak_0010.vtu docs/paraview_dambreak.png

Fluid particles (kind 0) are coloured by speed |velocity|, boundary particles (kind 1) grey; the
title gives the file's TimeValue.
"""
import sys

import vtk


def threshold_kind(grid, kind):
    t = vtk.vtkThreshold()
    t.SetInputData(grid)
    t.SetInputArrayToProcess(0, 0, 0, vtk.vtkDataObject.FIELD_ASSOCIATION_POINTS, "kind")
    t.SetLowerThreshold(kind - 0.5)
    t.SetUpperThreshold(kind + 0.5)
    t.SetThresholdFunction(vtk.vtkThreshold.THRESHOLD_BETWEEN)
    t.Update()
    return t.GetOutput()


def main(src, dst):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(src)
    r.Update()
    grid = r.GetOutput()
    fluid, walls = threshold_kind(grid, 0), threshold_kind(grid, 1)
    speed = vtk.vtkArrayCalculator()
    speed.SetInputData(fluid)
    speed.SetAttributeTypeToPointData()
    speed.AddVectorArrayName("velocity")
    speed.SetFunction("mag(velocity)")
    speed.SetResultArrayName("speed")
    speed.Update()
    lut = vtk.vtkLookupTable()
    lut.SetHueRange(0.66, 0.0)
    lut.Build()
    fm = vtk.vtkDataSetMapper()
    fm.SetInputConnection(speed.GetOutputPort())
    fm.SetScalarModeToUsePointFieldData()
    fm.SelectColorArray("speed")
    fm.SetScalarRange(0, 4.5)
    fm.SetLookupTable(lut)
    fa = vtk.vtkActor()
    fa.SetMapper(fm)
    fa.GetProperty().SetRepresentationToPoints()
    fa.GetProperty().SetPointSize(5)
    wm = vtk.vtkDataSetMapper()
    wm.SetInputData(walls)
    wm.ScalarVisibilityOff()
    wa = vtk.vtkActor()
    wa.SetMapper(wm)
    wa.GetProperty().SetRepresentationToPoints()
    wa.GetProperty().SetPointSize(3)
    wa.GetProperty().SetColor(0.55, 0.55, 0.55)
    ren = vtk.vtkRenderer()
    ren.AddActor(wa)
    ren.AddActor(fa)
    ren.SetBackground(1, 1, 1)
    bar = vtk.vtkScalarBarActor()
    bar.SetLookupTable(lut)
    bar.SetTitle("speed [m/s]")
    bar.SetNumberOfLabels(4)
    bar.GetTitleTextProperty().SetColor(0, 0, 0)
    bar.GetLabelTextProperty().SetColor(0, 0, 0)
    bar.SetWidth(0.08)
    ren.AddActor2D(bar)
    t = grid.GetFieldData().GetArray("TimeValue").GetValue(0)
    title = vtk.vtkTextActor()
    title.SetInput("%s  t = %.2f s  (%d fluid, %d wall particles; rendered by VTK %s)" %
                   (src.split("/")[-1], t, fluid.GetNumberOfPoints(), walls.GetNumberOfPoints(),
                    vtk.vtkVersion.GetVTKVersion()))
    title.GetTextProperty().SetColor(0, 0, 0)
    title.GetTextProperty().SetFontSize(16)
    title.SetPosition(10, 10)
    ren.AddActor2D(title)
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.AddRenderer(ren)
    win.SetSize(1000, 520)
    ren.ResetCamera()
    ren.GetActiveCamera().Zoom(1.25)
    win.Render()
    w2i = vtk.vtkWindowToImageFilter()
    w2i.SetInput(win)
    w2i.Update()
    wr = vtk.vtkPNGWriter()
    wr.SetFileName(dst)
    wr.SetInputConnection(w2i.GetOutputPort())
    wr.Write()
    print("rendered %s: %d points at t = %.3f s -> %s" % (src, grid.GetNumberOfPoints(), t, dst))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print(__doc__)
        sys.exit(2)
    main(sys.argv[1], sys.argv[2])
