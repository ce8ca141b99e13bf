"""The workbench (``cablelife workbench SCENE.toml``): a local web page where the engineer
drags clips in 3D and the cable answers with its static equilibrium, coloured by a section
quantity (docs/workbench.md). The server (:mod:`.server`, tornado) is imported by the command
only; the solving and editing live in :mod:`.session`, testable without a browser."""
