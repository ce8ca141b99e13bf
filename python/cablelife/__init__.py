"""cablelife: digital mock-up of cables and hoses.

Cosserat rod simulation (static, quasistatic, dynamic), excitation signals, and a comparative
fatigue analysis (pseudo-damage) to choose the best mounting variant.
"""

from cablelife import _core

__version__: str = _core.__version__

from cablelife.results import CableResult, Result, load_result  # noqa: E402

__all__ = ["CableResult", "Result", "load_result", "__version__"]
