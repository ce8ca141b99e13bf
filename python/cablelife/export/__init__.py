"""Files for other tools: ParaView time series (.vtp + .pvd), STL and PLY meshes."""

from cablelife.export.mesh_files import read_ply, read_stl, write_ply, write_stl
from cablelife.export.paraview import write_paraview

__all__ = ["read_ply", "read_stl", "write_paraview", "write_ply", "write_stl"]
