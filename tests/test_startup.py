"""Start-up: `import cablelife` and the CLI module load no heavy library (they are imported by
the functions that use them), and a small static run needs neither scipy nor h5py. A fresh
interpreter per check (sys.modules of this test process is polluted by other tests)."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]

HEAVY = [
    "scipy",
    "scipy.signal",
    "scipy.interpolate",
    "scipy.spatial",
    "matplotlib",
    "plotly",
    "pandas",
    "dask",
    "distributed",
    "h5py",
    "trimesh",
    "skimage",
    "asammdf",
    "nptdms",
]


def loaded_after(code: str) -> list[str]:
    probe = f"{code}\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    out = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True, cwd=ROOT
    ).stdout
    return json.loads(out.strip().splitlines()[-1])


@pytest.mark.parametrize(
    "code", ["import cablelife", "import cablelife.cli", "from cablelife.cli import app"]
)
def test_import_loads_no_heavy_module(code):
    loaded = set(loaded_after(code))
    assert not loaded & set(HEAVY), f"{code!r} imports {sorted(loaded & set(HEAVY))}"
    assert "numpy" not in loaded and "pydantic" not in loaded


def test_help_loads_no_heavy_module():
    code = (
        "import sys\nfrom cablelife.cli import app\nsys.argv = ['cablelife', '--help']\n"
        "try:\n    app()\nexcept SystemExit:\n    pass"
    )
    loaded = set(loaded_after(code))
    assert not loaded & set(HEAVY), sorted(loaded & set(HEAVY))


def test_small_static_run_needs_no_scipy_or_h5py():
    scene = ROOT / "examples" / "hose-three-clips.toml"
    code = (
        "import sys\nfrom cablelife.cli import app\n"
        f"sys.argv = ['cablelife', 'run', {str(scene)!r}, '--quiet']\n"
        "try:\n    app()\nexcept SystemExit as e:\n    assert not e.code, e.code"
    )
    loaded = set(loaded_after(code))
    assert not loaded & set(HEAVY), sorted(loaded & set(HEAVY))


def test_lazy_names_resolve_like_eager_imports():
    """Package attributes are the exported functions, also when a submodule of the same name
    was imported first (cablelife.lda.compare, cablelife.simulate)."""
    code = (
        "import cablelife.lda.compare, cablelife.simulate\n"
        "import cablelife, cablelife.lda, cablelife.signals\n"
        "from cablelife.lda import compare\nfrom cablelife.signals import generate\n"
        "assert callable(compare) and callable(cablelife.lda.compare), compare\n"
        "assert callable(cablelife.simulate) and callable(generate)\n"
        "import cablelife.lda.compare as m\n"
        "assert m is compare or callable(m)\n"
        "for pkg in (cablelife, cablelife.lda, cablelife.signals):\n"
        "    for name in pkg.__all__:\n"
        "        getattr(pkg, name)"
    )
    loaded_after(code)


def test_rotations_match_scipy():
    from cablelife.rotations import euler_matrix, matrix_quaternions
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(3)
    angles = rng.uniform(-np.pi, np.pi, (50, 3))
    for a in angles:
        np.testing.assert_allclose(
            euler_matrix(a), Rotation.from_euler("xyz", a).as_matrix(), atol=1e-14
        )
    # every branch of Shepperd's method: random rotations and rotations by ~π about each axis
    mats = Rotation.random(200, random_state=4).as_matrix()
    near_pi = Rotation.from_rotvec(np.vstack([np.eye(3), -np.eye(3)]) * (np.pi - 1e-3))
    mats = np.concatenate([mats, near_pi.as_matrix(), np.eye(3)[None]])
    want = Rotation.from_matrix(mats).as_quat(scalar_first=True)
    np.testing.assert_allclose(matrix_quaternions(mats), want, atol=1e-14)
