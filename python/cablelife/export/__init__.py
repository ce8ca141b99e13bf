"""Files for other tools: ParaView time series (.vtp + .pvd), STL and PLY meshes."""

from cablelife._lazy import lazy_package

__all__ = lazy_package(
    __name__,
    {
        "cablelife.export.mesh_files": ["read_ply", "read_stl", "write_ply", "write_stl"],
        "cablelife.export.paraview": ["write_paraview"],
    },
)
