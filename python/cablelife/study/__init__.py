"""Variant studies: a base scene, parameters to vary, every variant simulated and analysed as a
Dask task, and a summary table ranking them by pseudo-damage."""

from cablelife.study.runner import StudyOutcome, run_study
from cablelife.study.spec import StudyError, StudyFile, load_study
from cablelife.study.task import run_variant
from cablelife.study.variants import Variant, expand

__all__ = [
    "StudyError",
    "StudyFile",
    "StudyOutcome",
    "Variant",
    "expand",
    "load_study",
    "run_study",
    "run_variant",
]
