"""The surroundings of the cables: geometry on the bodies (meshes and analytic primitives) and
the clearance of the cables to it.

Modules: ``models`` (scene keys), ``meshes`` (mesh files: loading and checks), ``build`` (the
distance-query object of a scene and the body maps per step), ``clearance`` (clearance of a
result), ``data`` (the clearance arrays of a cable result, HDF5), ``summary`` (key figures).
This package imports nothing heavy at import time.
"""
