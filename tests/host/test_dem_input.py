"""The LIGGGHTS input built from a scene, run by the real ``liggghts`` binary (tiny cases)."""
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from conftest import steel_toml

from pyhost.engines.liggghts.box_input import input_lines, place_particles, write_data
from pyhost.scene import SceneError, load_scene

pytestmark = pytest.mark.engines

STEEL = "\n" + steel_toml("{{ youngs_modulus = 2e8, restitution = {e} }}")
HEAD_ON = STEEL + """
[[particles]]
material = "steel"
count = 2
radius = 2e-3
temperature = 300.0
positions = [[0.045, 0.005, 0.01], [0.055, 0.005, 0.01]]
velocity = [0.0, 0.0, 0.0]
[domain]
box = [0.0, 0.1, 0.0, 0.01, 0.0, 0.02]
gravity = [0.0, 0.0, 0.0]
[time]
dem_step = 1e-7
end = 0.02
"""


def run_liggghts(tmp_path, scene, particles, extra):
    data = write_data(tmp_path / "data.lmp", scene, particles)
    script = tmp_path / "in.case"
    script.write_text("\n".join(input_lines(scene, data) + extra) + "\n")
    r = subprocess.run(["stdbuf", "-o0", shutil.which("liggghts"), "-in", script.name, "-log", "log.case"],
                       cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-2000:]


def last_dump(path):
    lines = Path(path).read_text().splitlines()
    start = max(k for k, l in enumerate(lines) if l.startswith("ITEM: ATOMS"))
    return np.array([[float(x) for x in l.split()] for l in lines[start + 1:]])


@pytest.mark.parametrize("e", [0.5, 0.9])
def test_head_on_rebound_follows_dem_restitution(tmp_path, e):
    (tmp_path / "case.toml").write_text(HEAD_ON.format(e=e))
    scene = load_scene(tmp_path / "case.toml")
    p = place_particles(scene)
    p.velocity[0, 0], p.velocity[1, 0] = 0.5, -0.5
    run_liggghts(tmp_path, scene, p, ["dump d all custom 100000 dump.txt id vx", "dump_modify d sort id",
                                      "run 100000"])
    v = last_dump(tmp_path / "dump.txt")
    assert v[0, 1] == pytest.approx(-e * 0.5, rel=1e-3) and v[1, 1] == pytest.approx(e * 0.5, rel=1e-3)


BED = STEEL + """
[[particles]]
material = "steel"
count = 60
radius = 1e-3
temperature = 300.0
region = [0.0, 0.01, 0.0, 0.01, 0.0, 0.03]
[[walls]]
plane = "zlo"
material = "steel"
[domain]
box = [0.0, 0.01, 0.0, 0.01, 0.0, 0.03]
periodic = [true, true, false]
[time]
dem_step = 2e-6
end = 0.1
"""


def test_lattice_has_no_overlaps_and_settles_on_the_wall(tmp_path):
    (tmp_path / "case.toml").write_text(BED.format(e=0.5))
    scene = load_scene(tmp_path / "case.toml")
    p = place_particles(scene)
    gaps = np.linalg.norm(p.position[:, None] - p.position[None], axis=-1) + np.eye(60)
    assert gaps.min() > 2 * 1e-3
    run_liggghts(tmp_path, scene, p, ["dump d all custom 75000 dump.txt id z vz", "run 75000"])
    zv = last_dump(tmp_path / "dump.txt")
    assert zv[:, 1].min() > 0.99e-3 - 1e-5             # nobody through the wall
    assert np.abs(zv[:, 2]).max() < 0.05              # at rest after 0.15 s (free fall would give 1.5 m/s)


def test_region_too_small_is_reported(tmp_path):
    (tmp_path / "case.toml").write_text(BED.format(e=0.5).replace("count = 60", "count = 600"))
    with pytest.raises(SceneError, match=r"particles\[0\].region: holds"):
        place_particles(load_scene(tmp_path / "case.toml"))


def test_lattice_keeps_clear_of_the_region_faces(tmp_path):
    (tmp_path / "case.toml").write_text(BED.format(e=0.5))
    scene = load_scene(tmp_path / "case.toml")
    p = place_particles(scene)
    lo, hi = np.array(scene.particles[0].region[0::2]), np.array(scene.particles[0].region[1::2])
    assert np.all(p.position - p.radius[:, None] > lo) and np.all(p.position + p.radius[:, None] < hi)
