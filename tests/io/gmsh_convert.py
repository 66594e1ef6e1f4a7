#!/usr/bin/python3
"""Has Gmsh rewrite a mesh file, so that tests can read files Gmsh wrote in every encoding.

Usage: gmsh_convert.py IN.msh OUT.msh VERSION(2.2|4.1) BINARY(0|1)
Exit code 77 (and a message) when the gmsh module is missing.
"""
import sys

try:
    import gmsh
except ImportError as e:
    print(f"gmsh Python module not available: {e}", file=sys.stderr)
    sys.exit(77)

src, dst, version, binary = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
gmsh.initialize(["-noenv"], readConfigFiles=False)
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(src)
gmsh.option.setNumber("Mesh.MshFileVersion", version)
gmsh.option.setNumber("Mesh.Binary", binary)
gmsh.option.setNumber("Mesh.SaveAll", 1)
gmsh.write(dst)
gmsh.finalize()
