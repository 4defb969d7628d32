"""``python -m pyhost paper`` writes every file it promises, with the numbers it plots."""
import subprocess
import sys

import numpy as np
import pytest

from pyhost.commands.paper import FIGURES


def test_paper_command_writes_every_promised_file(tmp_path):
    r = subprocess.run([sys.executable, "-m", "pyhost", "paper", "--out", str(tmp_path), "--points", "30"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert len(FIGURES) >= 13
    for name, (_, _, curves, _, _) in FIGURES.items():
        png, csv = tmp_path / f"{name}.png", tmp_path / f"{name}.csv"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert png.stat().st_size < 300_000
        data = np.genfromtxt(csv, delimiter=",", names=True)
        assert data.shape == (30,)
        assert set(data.dtype.names) == {"v0"} | {k for k, _ in curves}
        assert data["v0"][0] == pytest.approx(1e-3) and data["v0"][-1] == pytest.approx(20.0)
        assert np.all(np.isfinite(data.view((float, len(data.dtype.names)))))
    r2 = np.genfromtxt(tmp_path / "fig06_r2_r3.csv", delimiter=",", names=True)["r2"]
    assert r2[-1] == pytest.approx(1.1 / 2.8, abs=2e-4)


def test_paper_command_rejects_bad_range(tmp_path):
    r = subprocess.run([sys.executable, "-m", "pyhost", "paper", "--out", str(tmp_path), "--vmin", "2",
                        "--vmax", "1"], capture_output=True, text=True)
    assert r.returncode == 2 and "vmin" in r.stderr
