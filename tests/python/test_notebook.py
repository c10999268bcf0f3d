"""The notebook examples run: examples/notebooks/*.ipynb executed with jupyter nbconvert."""
import os
import pathlib
import subprocess

import pytest

from conftest import SOURCE

NOTEBOOKS = sorted((SOURCE / "examples" / "notebooks").glob("*.ipynb"))


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_executes(notebook, tmp_path):
    result = subprocess.run(["jupyter", "nbconvert", "--to", "notebook", "--execute", "--output-dir", str(tmp_path),
                             "--ExecutePreprocessor.timeout=600", str(notebook)],
                            capture_output=True, text=True, env=dict(os.environ))
    assert result.returncode == 0, result.stderr[-4000:]
    assert (tmp_path / notebook.name).exists()


def test_there_is_a_notebook():
    assert pathlib.Path(SOURCE / "examples" / "notebooks" / "first_steps.ipynb") in NOTEBOOKS
