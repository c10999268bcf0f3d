"""examples/python/energy_loss_sweep.py reproduces verification/two_blocks's energy-loss table
(seed 000 Sec. 3.2) from a Python loop: the losses its README states, to the printed digits."""
import re
import runpy
import sys

from conftest import SOURCE


def readme_losses():
    """FLIP's loss and the FMPM(k), XPIC(k) losses per k from the README's full-run table."""
    text = (SOURCE / "verification" / "two_blocks" / "README.md").read_text()
    flip = float(re.search(r"^FLIP: ([0-9.]+) %$", text, re.M).group(1))
    rows = {int(k): (float(f), float(x)) for k, f, x in
            re.findall(r"^\|\s+(\d+) \|\s+([0-9.]+) \|\s+([0-9.]+) \|", text, re.M)}
    return flip, rows


def test_sweep_reproduces_the_table(monkeypatch, tmp_path, capsys):
    flip_stated, rows = readme_losses()
    monkeypatch.setattr(sys, "argv", ["energy_loss_sweep.py", "--orders", "1,2", "--plot", str(tmp_path / "loss.png")])
    namespace = runpy.run_path(str(SOURCE / "examples" / "python" / "energy_loss_sweep.py"))
    table, flip = namespace["main"]()
    assert round(flip, 3) == flip_stated
    for k in (1, 2):
        assert round(table["fmpm"][k], 3) == rows[k][0]
        assert round(table["xpic"][k], 3) == rows[k][1]
    assert (tmp_path / "loss.png").stat().st_size > 0
    assert "| FMPM(k) |" in capsys.readouterr().out
