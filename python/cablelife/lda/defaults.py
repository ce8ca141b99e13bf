"""Defaults of the LDA that the command line shows (a module without numpy, for a fast
``cablelife --help``)."""

#: Critical-plane step in degrees (worst-case amplitude loss 1.5 %, docs/lda.md).
DEFAULT_PLANE_STEP_DEG = 10.0
