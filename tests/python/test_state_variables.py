"""Material state variables by name and unit (issue 32, item 10): the Taylor bar's copper
(Mie-Grueneisen + J2) shows its equivalent plastic strain, its rate and its internal energy in
the snapshots (with units, listed in particles.xdmf for ParaView) and from Python."""
import numpy as np

import cairn
from conftest import SOURCE


def test_taylor_bar_plastic_strain(tmp_path):
    sim = cairn.Simulation.from_toml(SOURCE / "examples" / "taylor_bar.toml",
                                     set={"simulation.max_steps": 40}, output=tmp_path)
    assert {"equivalent_plastic_strain", "plastic_strain_rate", "internal_energy"} <= set(sim.particles.fields)
    alpha = sim.particles.equivalent_plastic_strain
    assert not alpha.flags.writeable and np.shares_memory(alpha, sim.particles.state)
    sim.run(progress=False)
    assert sim.steps == 40
    # The bar's foot, at the wall, yields at 190 m/s; its top has not felt the impact yet.
    z = sim.particles.position[:, 2]
    assert alpha[z < 1e-3].max() > 0.01 and np.all(alpha[z > 20e-3] == 0.0)
    assert sim.particles.plastic_strain_rate.max() > 0.0
    snap = cairn.read_output(tmp_path).snapshot(-1)
    assert snap["step"] == 40
    assert np.array_equal(snap["equivalent_plastic_strain"], alpha)
    assert snap["units"]["equivalent_plastic_strain"] == "1"
    assert snap["units"]["plastic_strain_rate"] == "1/s"
    assert snap["units"]["internal_energy"] == "J/kg"
    xdmf = (tmp_path / "particles.xdmf").read_text()
    assert 'Attribute Name="equivalent_plastic_strain"' in xdmf


def test_materials_without_a_variable_show_nan(tmp_path):
    """Two materials, one without plastic strain: the array is NaN on the elastic one's particles."""
    text = (SOURCE / "examples" / "taylor_bar.toml").read_text()
    text += """
[[material]]
name = "anvil"
model = "linear_elastic"
density = 7800.0
youngs_modulus = 200e9
poissons_ratio = 0.3
"""
    text = text.replace('material = "copper"', 'material = "anvil"')  # the bar is elastic now
    sim = cairn.Simulation.from_text(text, set={"simulation.max_steps": 1}, output=tmp_path)
    assert np.all(np.isnan(sim.particles.equivalent_plastic_strain))
    sim.run(progress=False)
    assert np.all(np.isnan(cairn.read_output(tmp_path).snapshot(-1)["equivalent_plastic_strain"]))
