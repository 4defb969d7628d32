"""What a run's start imports, by what its scene needs (issue 47: start-up within half a second):
each library left out is proven absent from sys.modules in a fresh interpreter."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def probe(code: str) -> str:
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    return r.stdout.strip().splitlines()[-1]


def test_a_dry_run_imports_neither_foamlib_nor_meshio_in_its_own_thread():
    """A run's start loads what its scene needs: a dry scene (a box, a user's script) with
    every effect's module loaded for the totals imports no foamlib (0.1-0.2 s: CFDEM and fluid
    cases only), and the frames' meshio (0.1-0.25 s) is imported by the output thread
    (``output.preload``) while the engines start, not by the run's own thread."""
    code = ("import sys\nfrom pathlib import Path\nfrom pyhost.scene import load_scene\n"
            "import pyhost.commands.run, pyhost.world, pyhost.run_scene, pyhost.effects as e\n"
            "for case in ('hot-cold-box', 'silo-heat'):\n"
            "    load_scene(Path('cases', case, 'case.toml').absolute())\n"
            "e.totals()\n"
            "before = sorted(m for m in ('foamlib', 'meshio') if m in sys.modules)\n"
            "from pyhost import output\noutput.preload()\noutput._output_writer().submit(int).result()\n"
            "print(before, 'meshio' in sys.modules)")
    assert probe(code) == "[] True"


def test_a_box_of_lattices_is_checked_for_overlaps_without_scipy(tmp_path):
    """Particles placed on each group's lattice in regions that share no volume cannot touch
    (validate._apart_as_placed): loading such a box scene imports no scipy.spatial (0.2-0.5 s);
    where two regions overlap, the check still runs and finds the spheres placed into each
    other."""
    code = ("import sys\nfrom pathlib import Path\nfrom pyhost.scene import load_scene\n"
            "load_scene(Path('cases/hot-cold-box/case.toml').absolute())\nprint('scipy.spatial' in sys.modules)")
    assert probe(code) == "False"
    from pyhost.scene import SceneError, load_scene
    text = (ROOT / "cases" / "hot-cold-box" / "case.toml").read_text()
    old = "region = [0.0, 0.02, 0.0, 0.02, 0.02, 0.04]"
    assert old in text
    (tmp_path / "case.toml").write_text(text.replace(old, "region = [0.0, 0.02, 0.0, 0.02, 0.0101, 0.0301]"))
    with pytest.raises(SceneError, match="overlap by"):
        load_scene(tmp_path / "case.toml")
