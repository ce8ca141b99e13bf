"""Motion volumes: the space a cable sweeps over its saved steps, as watertight meshes, and
comparisons of two volumes. See docs/visuals.md."""

from cablelife._lazy import lazy_package

__all__ = lazy_package(
    __name__,
    {
        "cablelife.volume.compare": ["Excess", "VolumeComparison", "compare_volumes"],
        "cablelife.volume.field": ["Capsules", "VoxelField", "grid_for", "signed_distance"],
        "cablelife.volume.mesh": ["TriangleMesh", "level_set_mesh"],
        "cablelife.volume.motion": [
            "MotionVolume",
            "motion_volume",
            "save_mesh",
            "volume_of_capsules",
        ],
        "cablelife.volume.sweep": ["cable_capsules", "result_capsules", "tube_capsules"],
    },
)
