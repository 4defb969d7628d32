"""particles.png of a fluid run: the particles over the fluid fraction, from a synthetic output
folder (no engines). The picture itself is drawn in its own process, as ``pyhost run`` does."""
import json
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from pyhost.output import VtkSeries
from pyhost.pictures import WINDOW, WINDOW_FLUID, fluid_grid

BOX = [0.0, 0.04, 0.0, 0.004, 0.0, 0.05]    # domain [m]; plenum 0.01 m below: fluid z -0.01..0.05
PLENUM = 0.01


def cells():
    """Centres of a 4 x 1 x 6 mesh of 10 mm (4 mm in y) cells, shuffled, with float noise as
    OpenFOAM writes them, and alpha 0.4 in the lower half (z < 0.02 m), 1.0 above."""
    x, y, z = np.meshgrid([0.005, 0.015, 0.025, 0.035], [0.002], np.arange(-0.005, 0.05, 0.01), indexing="ij")
    c = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    c = np.random.default_rng(1).permutation(c) + 1e-16 * np.random.default_rng(2).standard_normal(c.shape)
    return c, np.where(c[:, 2] < 0.02, 0.4, 1.0)


def write_run(out, fluid=True, thin_x=False):
    """``thin_x``: the same bed turned a quarter about z, thin in x (as DPMFoam's Goldschmidt)."""
    centres, alpha = cells()
    box = BOX
    x = np.array([[0.01, 0.002, 0.005], [0.02, 0.002, 0.005], [0.03, 0.002, 0.025]])
    if thin_x:
        centres, x, box = centres[:, [1, 0, 2]], x[:, [1, 0, 2]], BOX[2:4] + BOX[:2] + BOX[4:]
    history = out / "history.csv"
    history.write_text("time,T_group0,collisions\n0.0,300.0,0\n0.01,300.5,7\n")
    (out / "scene.json").write_text(json.dumps({"domain": {"box": box},
                                                "fluid": {"plenum": PLENUM, "cells": [4, 1, 6]}}))
    particles = VtkSeries(out / "vtk", "particles")
    if fluid:
        frames = VtkSeries(out / "vtk", "fluid")
    for t in (0.0, 0.01):
        particles.write(t, x, id=np.arange(1, 4), radius=np.full(3, 0.001), velocity=np.zeros((3, 3)),
                        temperature=np.array([300.0, 350.0, 400.0]))
        if fluid:
            frames.write(t, centres, alpha=alpha, velocity=np.zeros((24, 3)), pressure=np.zeros(24))


def test_fluid_grid_rebuilds_the_cells():
    centres, alpha = cells()
    grid = fluid_grid(centres, alpha, box=BOX[:4] + [BOX[4] - PLENUM, BOX[5]])
    assert grid.n_cells == 24
    assert grid.dimensions == (5, 2, 7)
    assert np.allclose(grid.spacing, (0.01, 0.004, 0.01))
    assert np.allclose(grid.bounds, (0.0, 0.04, 0.0, 0.004, -0.01, 0.05))
    a = grid.cell_data["alpha"]
    for point, value in [((0.005, 0.002, -0.005), 0.4), ((0.035, 0.002, 0.015), 0.4),
                         ((0.005, 0.002, 0.025), 1.0), ((0.035, 0.001, 0.045), 1.0)]:
        assert a[grid.find_containing_cell(point)] == value
    assert np.sum(a == 0.4) == 12 and np.sum(a == 1.0) == 12


def test_fluid_grid_without_box_and_not_uniform():
    centres, alpha = cells()
    assert np.allclose(fluid_grid(centres, alpha).spacing, (0.01, 0.01, 0.01))   # 1 cell in y: the others' spacing
    with pytest.raises(ValueError, match="uniform"):
        fluid_grid(centres[1:], alpha[1:])


@pytest.mark.parametrize("fluid, thin_x", [(True, False), (False, False), (True, True)])
def test_particles_png(tmp_path, fluid, thin_x):
    """The fluid fraction is seen across the bed's thin horizontal side, y or x (thin in x, it
    was seen edge on before session 39: a strip 4 mm wide)."""
    write_run(tmp_path, fluid, thin_x)
    r = subprocess.run([sys.executable, "-m", "pyhost", "pictures", str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    image = np.asarray(Image.open(tmp_path / "particles.png").convert("RGB")).astype(int)
    assert image.shape[1::-1] == (WINDOW_FLUID if fluid else WINDOW)
    # the lower half of the fluid (alpha 0.4, the bottom of the grey map) is drawn black behind the particles
    black = np.sum(np.all(image < 30, axis=2))
    assert black > 0.1 * image.shape[0] * image.shape[1] if fluid else black < 0.02 * image.shape[0] * image.shape[1]


def test_many_particles_are_drawn_as_sprites_that_cover_the_bed(tmp_path):
    """Above GLYPHS_UP_TO particles they are point sprites of their mean diameter: a block of
    6,000 touching particles still covers a good part of the picture in the colours of its
    temperatures (not the white background)."""
    from pyhost.pictures import GLYPHS_UP_TO

    n = 6000
    assert n > GLYPHS_UP_TO
    (tmp_path / "history.csv").write_text("time,T_group0,collisions\n0.0,300.0,0\n0.01,300.5,7\n")
    g = np.stack(np.meshgrid(*(np.arange(20),) * 2, np.arange(15), indexing="ij"), axis=-1).reshape(-1, 3)
    x = (g + 0.5) * 0.002
    particles = VtkSeries(tmp_path / "vtk", "particles")
    for t, T in ((0.0, np.full(n, 300.0)), (0.01, 300.0 + 10.0 * (x[:, 2] > 0.015))):
        particles.write(t, x, id=np.arange(1, n + 1), radius=np.full(n, 0.001), velocity=np.zeros((n, 3)),
                        temperature=T)
    particles.flush()
    r = subprocess.run([sys.executable, "-m", "pyhost", "pictures", str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    image = np.asarray(Image.open(tmp_path / "particles.png").convert("RGB")).astype(int)
    coloured = np.sum(np.max(image, axis=2) - np.min(image, axis=2) > 40)     # red (hot) or blue (cold), not grey
    assert coloured > 0.15 * image.shape[0] * image.shape[1]


def test_the_painter_started_with_a_run_draws_when_told_and_not_otherwise(tmp_path):
    """``run`` starts the picture process with the run (its imports overlap the simulation):
    told to draw, it writes both pictures; its input closed without that (a failed run), it
    ends at once with exit 0 and draws nothing."""
    from pyhost.commands.pictures import draw, painter

    write_run(tmp_path, fluid=False)
    idle = painter(tmp_path)
    idle.stdin.close()
    assert idle.wait(timeout=60) == 0
    assert not list(tmp_path.glob("*.png"))
    assert draw(painter(tmp_path)) == 0
    assert (tmp_path / "temperatures.png").stat().st_size > 0 and (tmp_path / "particles.png").stat().st_size > 0


def test_no_x_server_warning_without_a_display(tmp_path):
    """On a machine without a display VTK printed a coloured 'bad X server connection'
    warning on stderr before falling back to off-screen rendering; the pictures go to EGL at
    once: stderr empty, both pictures drawn."""
    import os
    write_run(tmp_path, fluid=False)
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "VTK_DEFAULT_OPENGL_WINDOW")}
    r = subprocess.run([sys.executable, "-m", "pyhost", "pictures", str(tmp_path)], capture_output=True, text=True,
                       env=env)
    assert r.returncode == 0, r.stderr
    assert "X server" not in r.stderr and r.stderr == "", r.stderr
    assert (tmp_path / "particles.png").stat().st_size > 0 and (tmp_path / "temperatures.png").stat().st_size > 0


def test_the_painter_draws_the_history_in_a_forked_copy_and_reports_its_failure(tmp_path):
    """Told to draw, the painter plots the history in a forked copy while it renders the
    particles (``draw_both``): a history plot that cannot be written (its file's place taken
    by a folder) fails the pictures (non-zero exit, the file named on stderr), and the
    particles are drawn all the same."""
    from pyhost.commands.pictures import draw

    write_run(tmp_path, fluid=False)
    (tmp_path / "temperatures.png").mkdir()
    p = subprocess.Popen([sys.executable, "-m", "pyhost.commands.pictures", str(tmp_path), "--when-told"],
                         stdin=subprocess.PIPE, stderr=subprocess.PIPE)
    code = draw(p)
    assert code != 0 and str(tmp_path / "temperatures.png") in p.stderr.read().decode()
    assert (tmp_path / "particles.png").stat().st_size > 0
