"""The engine's C++ unit tests (deck reader, meshes, insertion, output), run through pytest."""

import re
import subprocess
from pathlib import Path

import pytest

from .conftest import ROOT

pytestmark = pytest.mark.engine


def test_cpp_unit_tests_pass():
    binary = ROOT / "build" / "engine" / "dem_engine_tests"
    if not binary.is_file():
        pytest.fail(f"{binary} not found; run `make engine`", pytrace=False)
    res = subprocess.run(
        [str(binary)], capture_output=True, text=True, timeout=300, cwd=Path("/tmp")
    )
    summary = re.search(r"^(\d+) passed, (\d+) failed$", res.stdout, re.MULTILINE)
    assert summary, res.stdout[-2000:]
    assert int(summary.group(2)) == 0, res.stdout[-4000:]
    assert int(summary.group(1)) >= 40
    assert res.returncode == 0
