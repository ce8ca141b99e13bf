"""Motion volumes: the space a cable sweeps over its saved steps, as watertight meshes, and
comparisons of two volumes. See docs/visuals.md."""

from cablelife.volume.compare import Excess, VolumeComparison, compare_volumes
from cablelife.volume.field import Capsules, VoxelField, grid_for, signed_distance
from cablelife.volume.mesh import TriangleMesh, level_set_mesh
from cablelife.volume.motion import MotionVolume, motion_volume, save_mesh, volume_of_capsules
from cablelife.volume.sweep import cable_capsules, result_capsules, tube_capsules

__all__ = [
    "Capsules",
    "Excess",
    "MotionVolume",
    "TriangleMesh",
    "VolumeComparison",
    "VoxelField",
    "cable_capsules",
    "compare_volumes",
    "grid_for",
    "level_set_mesh",
    "motion_volume",
    "result_capsules",
    "save_mesh",
    "signed_distance",
    "tube_capsules",
    "volume_of_capsules",
]
