"""Inputs from Python go through the CLI's validator: the same InputError, with its fields."""
import subprocess

import pytest

import cairn
from conftest import BINARY, two_blocks_text


def test_input_error_carries_file_line_and_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(two_blocks_text().replace('update = "flip"', 'update = "flop"'))
    with pytest.raises(cairn.InputError) as caught:
        cairn.Simulation.from_toml(bad)
    e = caught.value
    assert e.file == str(bad) and e.key == "method.update" and "flop" in e.found
    assert e.line == bad.read_text().splitlines().index('update = "flop"') + 1
    cli = subprocess.run([str(BINARY), "check", str(bad)], capture_output=True, text=True)
    assert cli.returncode == 2 and str(e) in cli.stderr


def test_set_overrides_are_validated(tmp_path):
    path = tmp_path / "in.toml"
    path.write_text(two_blocks_text())
    sim = cairn.Simulation.from_toml(path, set={"method.update": "fmpm", "method.order": 4}, output=False)
    assert 'order = 4' in sim.toml
    with pytest.raises(cairn.InputError) as caught:
        cairn.Simulation.from_toml(path, set={"method.order": -1})
    assert caught.value.key == "method.order" and caught.value.file.startswith("--set")


def two_blocks_dict():
    return {
        "simulation": {"dimension": 2, "mode": "plane_strain", "end_time": 1e-4, "cfl": 0.2},
        "grid": {"origin": [0.0, 0.0], "extent": [0.124, 0.04], "cell_size": 1e-3},
        "method": {"shape": "ugimp", "update": "flip"},
        "material": [{"name": "rubber", "model": "neo_hookean", "form": "j_squared", "density": 1500.0,
                      "lambda": 7.29766e6, "shear_modulus": 3.7594e6}],
        "body": [
            {"name": "left", "material": "rubber", "particles_per_cell": 2, "velocity": [8.165, 0.0],
             "shape": {"box": {"min": [0.010, 0.010], "max": [0.060, 0.030]}}},
            {"name": "right", "material": "rubber", "particles_per_cell": 2, "velocity": [-8.165, 0.0],
             "shape": {"box": {"min": [0.064, 0.010], "max": [0.114, 0.030]}}},
        ],
    }


def test_from_dict_equals_the_file():
    d = two_blocks_dict()
    from_dict = cairn.Simulation.from_dict(d)  # (nothing is written before a step)
    from_text = cairn.Simulation.from_text(cairn.to_toml(d), name="dict")
    assert from_dict.toml == from_text.toml
    assert len(from_dict.particles) == 2 * 50 * 20 * 4


def test_from_dict_errors_name_the_key():
    d = two_blocks_dict()
    d["method"]["shpe"] = "gimp"
    with pytest.raises(cairn.InputError) as caught:
        cairn.Simulation.from_dict(d, name="study")
    e = caught.value
    assert e.file == "study" and e.line > 0 and "shpe" in str(e)
    d = two_blocks_dict()
    d["material"][0]["density"] = -1.0
    with pytest.raises(cairn.InputError) as caught:
        cairn.Simulation.from_dict(d)
    assert caught.value.key.endswith("density")


def test_keys_are_the_declared_keys():
    keys = cairn.keys()
    order = keys["method.order"]
    assert order["type"] and order["doc"] and order["range"]
    assert "material[neo_hookean].shear_modulus" in keys
    cli = subprocess.run([str(BINARY), "keys"], capture_output=True, text=True, check=True)
    assert cairn.keys_text() == cli.stdout


def test_a_refused_input_leaves_no_temporary_folder(tmp_path, monkeypatch):
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    d = two_blocks_dict()
    d["grid"]["cell_size"] = -1.0
    with pytest.raises(cairn.InputError):
        cairn.Simulation.from_dict(d, output=False)
    assert list(tmp_path.iterdir()) == []
