#!/usr/bin/python3
"""Writes a planar high-order mesh made by Gmsh for the agreement test of
gmsh_high_order_test.cpp: the unit square with a wavy top edge (a spline), meshed coarsely
(size 0.3) and raised to ORDER, so that some elements along the wave are invalid.

    make_wavy_high_order.py triangle|quadrangle ORDER complete|incomplete OUT.msh
"""
import math
import sys

import gmsh

family, order, kind, out = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
gmsh.initialize()
gmsh.option.setNumber("General.Verbosity", 0)
gmsh.model.add("wavy")
geo = gmsh.model.geo
wave = [geo.addPoint(i / 20.0, 1 + 0.15 * math.sin(6 * math.pi * i / 20.0), 0) for i in range(21)]
top = geo.addSpline(wave)
a, b = geo.addPoint(0, 0, 0), geo.addPoint(1, 0, 0)
left, bottom, right = geo.addLine(wave[0], a), geo.addLine(a, b), geo.addLine(b, wave[-1])
# Counter-clockwise, so that J > 0 with the normal +z.
surface = geo.addPlaneSurface([geo.addCurveLoop([bottom, right, -top, left])])
geo.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
if family == "quadrangle":
    gmsh.model.mesh.setRecombine(2, surface)
if kind == "incomplete":
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)
gmsh.model.mesh.generate(2)
gmsh.model.mesh.setOrder(order)
gmsh.write(out)
gmsh.finalize()
