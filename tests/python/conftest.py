"""Shared set-up of the Python module's tests (docs/python.md): the module from the build
(ctest sets PYTHONPATH to build/<preset>/python), the cairn binary and the source tree."""
import os
import pathlib
import re

import pytest

SOURCE = pathlib.Path(os.environ.get("CAIRN_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BINARY = pathlib.Path(os.environ.get("CAIRN_BINARY", SOURCE / "build" / "release" / "cairn"))


def two_blocks_text(end_time=2e-4):
    """examples/two_blocks.toml, shortened: a few dozen steps, a snapshot every 1e-4."""
    text = (SOURCE / "examples" / "two_blocks.toml").read_text()
    return re.sub(r"end_time = [0-9.e-]+", f"end_time = {end_time!r}", text)


@pytest.fixture
def two_blocks(tmp_path):
    """The shortened two-blocks input as a file in a fresh folder."""
    path = tmp_path / "two_blocks.toml"
    path.write_text(two_blocks_text())
    return path
