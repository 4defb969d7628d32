"""Pictures of a run, made from what it wrote: history plots and a rendered last frame."""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np


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
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    for k in groups:
        T = np.array([float(r[k]) for r in rows])
        ax1.plot(t * 1e3, T - T[0], label=f"group {k[7:]} (from {T[0]:.5g} K)")
    ax1.set_xlabel("time [ms]")
    ax1.set_ylabel("mean temperature change [K]")
    ax1.legend()
    ax1.grid(alpha=0.3)
    ax2.plot(t * 1e3, [int(r["collisions"]) for r in rows])
    ax2.set_xlabel("time [ms]")
    ax2.set_ylabel("collisions so far")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    path = out / "temperatures.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def render_particles(out: Path) -> Path:
    """The last VTK frame, spheres coloured by temperature, rendered off screen -> out/particles.png."""
    import pyvista

    pyvista.OFF_SCREEN = True
    reader = pyvista.get_reader(str(out / "vtk" / "particles.pvd"))
    reader.set_active_time_value(reader.time_values[-1])
    cloud = reader.read()[0]
    spheres = cloud.glyph(geom=pyvista.Sphere(theta_resolution=12, phi_resolution=12), scale="radius",
                          factor=2.0, orient=False)
    plotter = pyvista.Plotter(off_screen=True, window_size=(900, 700))
    plotter.add_mesh(spheres, scalars="temperature", cmap="coolwarm",
                     scalar_bar_args={"title": "temperature [K]"})
    plotter.add_text(f"t = {reader.time_values[-1] * 1e3:.3g} ms", font_size=10)
    plotter.view_isometric()
    path = out / "particles.png"
    plotter.screenshot(str(path))
    plotter.close()
    return path
