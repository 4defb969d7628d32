"""Pictures of a run, made from what it wrote: history plots and a rendered last frame."""
from __future__ import annotations

import copy
import csv
import ctypes.util
import os
from pathlib import Path

import numpy as np

from pyhost.output import naming

# Pictures are drawn off screen. Without a display VTK first tries X, prints a coloured
# "bad X server connection" warning, then falls back to EGL: with EGL there, go to it at once
# (before VTK is imported; a user's own choice of window stays).
if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY") and ctypes.util.find_library("EGL"):
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


def warm_up() -> None:
    """Import the drawing libraries (matplotlib, pyvista: about 1 s), so that a picture process
    started with a run has them when the run ends (``pyhost.commands.pictures``)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot  # noqa: F401
    import pyvista
    import pyvista.plotting  # noqa: F401  (pyvista imports its plotting at first use)
    pyvista.OFF_SCREEN = True
    pyvista.Plotter(off_screen=True).close()     # the off-screen render context, once


def plot_history(out: Path) -> Path:
    """Change of each particle group's mean temperature (heat-capacity weighted) since the
    start, and the collision count, against time -> out/temperatures.png. Changes, because a
    collision moves little heat: they are what shows the populations approaching."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = list(csv.DictReader(open(out / "history.csv")))
    t = np.array([float(r["time"]) for r in rows])
    groups = sorted(k for k in rows[0] if k.startswith("T_group"))
    names = _group_names(out)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    for k in groups:
        T = np.array([float(r[k]) for r in rows])
        seen = np.flatnonzero(np.isfinite(T))
        if not len(seen):                   # a group with no particle (a material of walls only)
            continue
        name = names[int(k[7:])] if int(k[7:]) < len(names) else f"group {k[7:]}"
        ax1.plot(t * 1e3, T - T[seen[0]], label=f"{name} (from {T[seen[0]]:.5g} K)")
    ax1.set_xlabel("time [ms]")
    ax1.set_ylabel("mean temperature change [K]")
    if ax1.lines:
        ax1.legend()
    else:                                   # no particle temperatures (a dry, isothermal scene)
        ax1.text(0.5, 0.5, "no particle temperatures in this scene", ha="center", va="center",
                 transform=ax1.transAxes)
    ax1.grid(alpha=0.3)
    ax2.plot(t * 1e3, [int(r["collisions"]) for r in rows])
    ax2.set_xlabel("time [ms]")
    ax2.set_ylabel("collisions so far")
    ax2.grid(alpha=0.3)
    return _save(fig, out / "temperatures.png")


def _group_names(out: Path) -> list:
    """The names of the history's temperature groups, from the run's summary.json."""
    import json

    try:
        return list(json.loads((out / "summary.json").read_text()).get("groups", []))
    except (OSError, ValueError):
        return []


def temperature_change(pvd: Path, last=None):
    """Each particle's temperature change [K] in the last frame of a particle series: the
    frame's own ``temperature_change`` (since the particle came in, as the run knew it), or
    for a series written without it, since the first frame the particle appears in (each frame
    read: seconds for thousands of frames). ``last``: the last frame, if read already."""
    import pyvista

    if last is not None and "temperature_change" in last.point_data:
        return np.asarray(last.point_data["temperature_change"])
    reader = pyvista.get_reader(str(pvd))
    first = {}
    for time in reader.time_values:
        reader.set_active_time_value(time)
        frame = reader.read()[0]
        if frame.n_points:
            ids, T = np.asarray(frame.point_data["id"]), np.asarray(frame.point_data["temperature"])
            for i, value in zip(ids.tolist(), T.tolist()):
                first.setdefault(i, value)
    ids, T = np.asarray(frame.point_data["id"]), np.asarray(frame.point_data["temperature"])
    return T - np.array([first[i] for i in ids.tolist()])


def change_scale(dT):
    """Colour limits symmetric about zero, only as wide as the largest change, and the unit:
    mK below 1 K (a collision moves little heat: a scale over the temperatures would show none)."""
    top = float(np.nanmax(np.abs(dT))) if np.size(dT) and np.isfinite(dT).any() else 0.0
    factor, unit = (1e3, "mK") if top < 1.0 else (1.0, "K")
    top = max(top * factor, 1e-9)
    return factor, unit, (-top, top)


def _save(fig, path: Path) -> Path:
    """Tight layout, 100 dpi, figure closed (pictures are drawn in batches)."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    try:
        with naming(path):
            fig.savefig(path, dpi=100)
    finally:
        plt.close(fig)
    return path


WINDOW = (900, 700)          # particles.png [px], 3-D view of a scene without fluid
WINDOW_FLUID = (900, 800)    # particles.png [px], front view of a fluid run
GLYPHS_UP_TO = 5000          # particles drawn as sphere meshes; more are drawn as point sprites (a 27k bed
                             # as meshes is 4 M triangles, 3 s to render in software; as sprites 0.1 s)


def _levels(x, tol: float) -> tuple[int, float, float]:
    """Number of distinct values (apart by more than tol), lowest value and spacing of equally
    spaced coordinates x [m] (spacing 0 for one value)."""
    x = np.sort(np.asarray(x, float))
    n = 1 + int(np.sum(np.diff(x) > tol))
    return n, (x[0] + x[-1]) / 2 if n == 1 else x[0], (x[-1] - x[0]) / (n - 1) if n > 1 else 0.0


def fluid_grid(centres, alpha, box=None):
    """The fluid cells as a pyvista ImageData with cell data ``alpha`` (fluid volume fraction
    [-]), rebuilt from the cell centres [m] of a uniform box mesh, in any order. The spacing of
    each axis comes from its distinct centre coordinates; an axis with a single cell takes its
    width from ``box`` (xlo xhi ylo yhi zlo zhi [m], the fluid box) or else the mean spacing of
    the other axes."""
    import pyvista

    c = np.asarray(centres, float)
    tol = 1e-6 * np.ptp(c, axis=0).max()
    n, lo, h = map(np.array, zip(*(_levels(c[:, k], tol) for k in range(3))))
    for k in np.flatnonzero(n == 1):
        h[k] = box[2 * k + 1] - box[2 * k] if box is not None else (h[h > 0].mean() if np.any(h > 0) else 1.0)
    if np.prod(n) != len(c):
        raise ValueError(f"{len(c)} cell centres do not fill a uniform {n[0]} x {n[1]} x {n[2]} grid")
    ijk = np.rint((c - lo) / np.where(h > 0, h, 1.0)).astype(int) * (n > 1)
    values = np.full(len(c), np.nan)
    values[ijk[:, 0] + n[0] * (ijk[:, 1] + n[1] * ijk[:, 2])] = alpha   # VTK order: x fastest
    grid = pyvista.ImageData(dimensions=n + 1, spacing=h, origin=lo - h / 2)
    grid.cell_data["alpha"] = values
    return grid


def _frame(pvd: Path, t: float | None = None):
    """The frame of a .pvd series nearest time t [s] (the last frame without t), and its time."""
    import pyvista

    reader = pyvista.get_reader(str(pvd))
    times = np.asarray(reader.time_values)
    time = times[-1] if t is None else times[np.argmin(np.abs(times - t))]
    reader.set_active_time_value(time)
    return reader.read()[0], float(time)


def render_particles(out: Path) -> Path:
    """The last VTK frame rendered off screen -> out/particles.png: the particles as spheres
    (point sprites above GLYPHS_UP_TO particles) coloured by their temperature change since
    they first appear (``change_scale``). For a fluid run (out/vtk/fluid.pvd) they are drawn over the
    fluid volume fraction [-] of the same frame: the mid slice of the fluid cells (domain box
    and plenum below it) across the thinner horizontal axis (y for the host's boxes, x for
    DPMFoam's Goldschmidt), placed at the back face and viewed from the front, framed on the
    bed (plenum to a little above the highest particle), so a pseudo-2-D bed reads like the
    usual 2-D bed picture."""
    import pyvista

    pyvista.OFF_SCREEN = True
    cloud, t = _frame(out / "vtk" / "particles.pvd")
    dT = temperature_change(out / "vtk" / "particles.pvd", cloud)
    factor, unit, clim = change_scale(dT)
    cloud.point_data["change"] = dT * factor
    sprites = cloud.n_points > GLYPHS_UP_TO
    spheres = cloud if sprites else cloud.glyph(geom=pyvista.Sphere(theta_resolution=12, phi_resolution=12),
                                                scale="radius", factor=2.0, orient=False)
    grid = None
    if (out / "vtk" / "fluid.pvd").exists():
        cells, _ = _frame(out / "vtk" / "fluid.pvd", t)
        try:
            grid = fluid_grid(cells.points, cells.point_data["alpha"], _fluid_box(out))
        except ValueError as exc:           # a user's own mesh: not drawn as a slice (yet)
            print(f"note: fluid fraction not drawn: {exc}")
    has_fluid = grid is not None
    window = WINDOW_FLUID if has_fluid else WINDOW
    # edges smoothed by FXAA, a pass over the finished image, not by 8 samples a pixel (pyvista's
    # default): Mesa's software renderer took 0.75 s CPU for 900 spheres with those, 0.35 s now
    # (pyvista's enable_anti_aliasing("fxaa") falls back to supersampling off screen; VTK's works)
    theme = copy.deepcopy(pyvista.global_theme)
    theme.multi_samples = 0
    plotter = pyvista.Plotter(off_screen=True, window_size=window, theme=theme)
    plotter.renderer.SetUseFXAA(True)
    bar = dict(vertical=True, width=0.05, height=0.5, position_y=0.25, title_font_size=14, label_font_size=14)
    title = f"temperature change [{unit}]"
    # a sprite of the particles' mean diameter as seen at the window's height across the scene
    size = dict(render_points_as_spheres=True, point_size=max(2.0, 2.0 * float(np.mean(cloud.point_data["radius"]))
                                                              / max(cloud.length, 1e-300) * min(window))
                ) if sprites else {}
    plotter.add_mesh(spheres, scalars="change", cmap="coolwarm", clim=clim,
                     scalar_bar_args=dict(bar, title=f"T change [{unit}]\n", position_x=0.86, fmt="%.3g")
                     if has_fluid else {"title": title + "\n"}, **size)   # (the newline: the title clear of the labels)
    if has_fluid:
        b = np.array(grid.bounds).reshape(3, 2)
        depth = 0 if b[0, 1] - b[0, 0] < b[1, 1] - b[1, 0] else 1    # the thin horizontal axis: seen across
        across = 1 - depth
        (x0, x1), (y0, y1), (z0, z1) = b[across], b[depth], b[2]     # x: across the picture, y: depth
        # seen from -y (the host's boxes) or from +x (x thin): the across axis points right
        towards = -1.0 if depth == 1 else 1.0                         # where the camera is, along depth
        back = y1 if depth == 1 else y0
        shift = np.zeros(3)
        shift[depth] = back - towards * 0.02 * (y1 - y0) - grid.center[depth]
        sheet = grid.slice(normal="xy"[depth], origin=grid.center).translate(shift)
        lo = min(np.floor(10 * np.nanmin(grid.cell_data["alpha"])) / 10, 0.9)
        plotter.add_mesh(sheet, scalars="alpha", cmap="gray", clim=(lo, 1.0), lighting=False,
                         scalar_bar_args=dict(bar, title="fluid fraction [-]\n", position_x=0.04, fmt="%.1f",
                                              n_labels=round(10 * (1 - lo)) + 1))
        plotter.add_mesh(sheet.outline(), color="black")
        top = spheres.bounds[5]
        top = min(z1, top + 0.3 * (top - z0))                # the bed and a little above it
        centre = np.array([0.0, 0.0, (z0 + top) / 2])
        centre[across], centre[depth] = (x0 + x1) / 2, back
        view = np.zeros(3)
        view[depth] = towards * 10 * (x1 - x0 + top - z0)
        plotter.camera.focal_point = centre
        plotter.camera.position = centre + view
        plotter.camera.up = (0, 0, 1)
        plotter.enable_parallel_projection()
        width, height = WINDOW_FLUID
        plotter.camera.parallel_scale = 0.52 * max(top - z0, (x1 - x0) * height / (0.7 * width))
    else:
        plotter.view_isometric()
    plotter.add_text(f"t = {t * 1e3:.3g} ms", position="upper_left", font_size=12)
    path = out / "particles.png"
    with naming(path):
        plotter.screenshot(str(path))
    plotter.close()
    return path


def _fluid_box(out: Path):
    """The fluid box (domain box and the plenum below it), xlo xhi ylo yhi zlo zhi [m], from the
    run's scene.json; None if it has none."""
    import json

    if not (out / "scene.json").exists():
        return None
    scene = json.loads((out / "scene.json").read_text())
    if not scene.get("domain"):             # a script scene: the user's own fluid mesh
        return None
    box = list(scene["domain"]["box"])
    box[4] -= (scene.get("fluid") or {}).get("plenum", 0.0)
    return box


def plot_post(out: Path, last, pair_names, times, pair_heat) -> Path:
    """Offline heat of a dump folder -> out/post.png. Left: the last frame seen from the front
    (x, z), each particle coloured by its temperature change since the start, on a scale
    symmetric about zero and only as wide as the largest change, in mK when below 1 K (a
    collision moves little heat: a scale over the temperatures themselves would show none).
    Right: heat moved per pair of atom types ("1-wall": type 1 with walls) against time.
    ``last`` = (time [s], positions (n, 3) [m], temperature change (n,) [K], model)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t, x, dT, model = last
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    scale, unit, (low, high) = change_scale(dT)
    dots = ax1.scatter(x[:, 0] * 1e3, x[:, 2] * 1e3, c=dT * scale, cmap="coolwarm", vmin=low, vmax=high, s=12)
    fig.colorbar(dots, ax=ax1, label=f"temperature change [{unit}], model {model}")
    ax1.set_xlabel("x [mm]")
    ax1.set_ylabel("z [mm]")
    ax1.set_aspect("equal", adjustable="datalim")
    ax1.set_title(f"t = {t * 1e3:.4g} ms")
    heat = np.array(pair_heat).reshape(len(times), len(pair_names))
    for k, name in enumerate(pair_names):
        ax2.plot(np.array(times) * 1e3, heat[:, k], label=f"types {name}")
    ax2.set_xlabel("time [ms]")
    ax2.set_ylabel(f"heat moved so far, model {model} [J]")
    if pair_names:
        ax2.legend()
    ax2.grid(alpha=0.3)
    return _save(fig, out / "post.png")
