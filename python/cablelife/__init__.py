"""cablelife: digital mock-up of cables and hoses.

Cosserat rod simulation (static, quasistatic, dynamic), excitation signals, and a comparative
fatigue analysis (pseudo-damage) to choose the best mounting variant.

    scene = cablelife.load_scene("scene.toml")
    result = cablelife.simulate(scene, mode="quasistatic")
    result.save("run.h5")
"""

from cablelife import _core

__version__: str = _core.__version__

from cablelife.results import CableResult, Result, load_result  # noqa: E402
from cablelife.scene import Scene, SceneError, load_scene, scene_from_dict  # noqa: E402
from cablelife.simulate import SimulationError, simulate  # noqa: E402

__all__ = [
    "CableResult",
    "Result",
    "Scene",
    "SceneError",
    "SimulationError",
    "__version__",
    "load_result",
    "load_scene",
    "scene_from_dict",
    "simulate",
]
