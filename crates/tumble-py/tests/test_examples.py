"""Every example in examples/ runs (short, with --quick) and writes its PNG; each checks its
own numbers (orders, energy trends, the flip) and fails if they are off."""

import os
import subprocess
import sys

import pytest

EXAMPLES = [
    "free_fall",
    "integrator_order",
    "spring_energy",
    "dzhanibekov",
    "restitution_sweep",
    "cartpole_pd_batch",
]


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_runs(root, tmp_path, name):
    out = tmp_path / f"{name}.png"
    env = dict(os.environ, MPLBACKEND="Agg")
    result = subprocess.run(
        [sys.executable, str(root / "examples" / f"{name}.py"), "--quick", "--out", str(out)],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_every_example_is_tested(root):
    found = {p.stem for p in (root / "examples").glob("*.py") if not p.stem.startswith("_")}
    assert found == set(EXAMPLES)
