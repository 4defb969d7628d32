"""pyhost.fluidization: Ergun, Wen-Yu and the fluidization curve of a synthetic history."""
import csv
import json

import numpy as np
import pytest

from plugins.bed import ergun_pressure_drop, ergun_umf, wen_yu_umf
from pyhost.fluidization import measure

AIR = dict(rho=1.2, mu=1.8e-5)


def test_wen_yu_reaches_its_small_and_large_particle_limits():
    """Kunii & Levenspiel (1991) eqs. 3.25-3.26: u_mf = d^2 (rho_p - rho) g / (1650 mu) for
    small Re_mf, u_mf^2 = d (rho_p - rho) g / (24.5 rho) for large."""
    d, rho_p = 20e-6, 2500.0
    assert wen_yu_umf(d, rho_p, **AIR) == pytest.approx(d**2 * (rho_p - 1.2) * 9.81 / (1650 * 1.8e-5), rel=0.01)
    d = 0.05
    assert wen_yu_umf(d, rho_p, **AIR) == pytest.approx(np.sqrt(d * (rho_p - 1.2) * 9.81 / (24.5 * 1.2)), rel=0.02)


def test_ergun_umf_balances_the_bed_weight():
    eps, d, rho_p = 0.41, 1e-3, 2700.0
    u = ergun_umf(eps, d, rho_p, **AIR)
    weight = (1 - eps) * (rho_p - 1.2) * 9.81 * 0.02          # Pa over a 20 mm bed
    assert ergun_pressure_drop(u, eps, d, 0.02, **AIR) == pytest.approx(weight, rel=1e-12)


def synthetic_run(path, dp_of_u, table, height=0.017):
    """scene.json and history.csv of a 1200-bead bed whose pressure drop follows dp_of_u."""
    scene = {"domain": {"box": [0, 0.008, 0, 0.008, 0, 0.048], "gravity": [0, 0, -9.81]},
             "fluid": {"density": 1.2, "viscosity": 1.8e-5, "inlet_table": table},
             "particles": [{"count": 1200, "radius": 0.5e-3, "material": "al"}],
             "materials": {"al": {"density": 2700.0}}}
    (path / "scene.json").write_text(json.dumps(scene))
    times, speeds = np.array(table).T
    with open(path / "history.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(("time", "pressure_drop", "bed_height"))
        for t in np.arange(0, times[-1] + 1e-9, 1e-3):
            w.writerow((t, dp_of_u(np.interp(t, times, speeds)), height))


def test_curve_of_an_ergun_bed_gives_back_ergun_and_its_umf(tmp_path):
    """A history that follows Ergun up to the bed weight, then stays at it: the measured
    u_mf is Ergun's, the fixed plateaus match Ergun exactly."""
    volume, area, height = 1200 * np.pi / 6 * 1e-9, 0.008**2, 0.017
    eps = 1 - volume / (area * height)
    weight = (2700.0 - 1.2) * volume * 9.81 / area
    table = [[0.0, 0.0], [0.1, 0.0]]
    for k, u in enumerate((0.1, 0.2, 0.3, 0.4, 0.5, 0.8, 0.9)):
        table += [[0.102 + 0.03 * k, u], [0.13 + 0.03 * k, u]]
    synthetic_run(tmp_path, lambda u: min(ergun_pressure_drop(u, eps, 1e-3, height, **AIR), weight), table)
    c = measure(tmp_path)
    assert c.u == [0.1, 0.2, 0.3, 0.4, 0.5, 0.8, 0.9]
    assert c.weight == pytest.approx(weight, rel=1e-12)
    assert np.allclose(np.array(c.dp)[c.fixed], np.array(c.ergun)[c.fixed], rtol=1e-9)
    assert c.u_mf == pytest.approx(ergun_umf(eps, 1e-3, 2700.0, **AIR), rel=1e-6)
    assert c.voidage[0] == pytest.approx(eps, rel=1e-12)


def test_curve_needs_plateaus_and_a_fluid_history(tmp_path):
    synthetic_run(tmp_path, lambda u: 10 * u, [[0.0, 0.0], [0.1, 0.5]])
    with pytest.raises(ValueError, match="at least 3 plateaus"):
        measure(tmp_path)
    with pytest.raises(ValueError, match="no scene.json"):
        measure(tmp_path / "nothing")
