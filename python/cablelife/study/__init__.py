"""Variant studies: a base scene, parameters to vary, every variant simulated and analysed as a
Dask task, and a summary table ranking them by pseudo-damage."""

from cablelife._lazy import lazy_package

__all__ = lazy_package(
    __name__,
    {
        "cablelife.study.runner": ["StudyOutcome", "run_study"],
        "cablelife.study.spec": ["StudyError", "StudyFile", "load_study"],
        "cablelife.study.task": ["run_variant"],
        "cablelife.study.variants": ["Variant", "expand"],
    },
)
