"""cablelife: digital mock-up of cables and hoses.

Cosserat rod simulation (static, quasistatic, dynamic), excitation signals, and a comparative
fatigue analysis (pseudo-damage) to choose the best mounting variant.

    scene = cablelife.load_scene("scene.toml")
    result = cablelife.simulate(scene, mode="quasistatic")
    result.save("run.h5")

The names below are imported on first use (``cablelife._lazy``): ``import cablelife`` is fast.
"""

from cablelife._cpu import check_processor

check_processor(__path__)  # before the compiled core loads: a clear error, not SIGILL

from cablelife import _core  # noqa: E402
from cablelife._lazy import lazy_package  # noqa: E402

__version__: str = _core.__version__

__all__ = [
    "__version__",
    *lazy_package(
        __name__,
        {
            "cablelife.results": ["CableResult", "Result", "load_result"],
            "cablelife.scene": ["Scene", "SceneError", "load_scene", "scene_from_dict"],
            "cablelife.simulate": ["SimulationError", "simulate"],
        },
    ),
]
