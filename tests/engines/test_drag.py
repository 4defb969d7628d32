"""Drag laws of plugins.drag against their limits (pure functions, kept beside the engine
tests that use them)."""
import numpy as np
import pytest

from plugins import drag

pytestmark = pytest.mark.engines

RHO, NU, D = 1000.0, 1e-6, 1e-3               # kg/m^3, m^2/s, m


def test_unknown_law_names_the_choices():
    with pytest.raises(ValueError, match="unknown drag law 'stokes'; choices: difelice, ergun"):
        drag.LAWS.lookup("stokes")


@pytest.mark.parametrize("name", sorted(drag.LAWS))
def test_every_law_is_vectorised_positive_and_grows_with_slip(name):
    law = drag.LAWS.lookup(name)
    alpha = np.array([0.45, 0.6, 0.85, 0.99])
    slip = np.array([1e-3, 1e-2, 1e-1, 1.0])
    k = law(alpha, slip, D, RHO, NU)
    assert k.shape == (4,) and np.all(k > 0)
    # the drag force K |u - v| grows with the slip at fixed fluid fraction
    f = law(0.7, slip, D, RHO, NU) * slip
    assert np.all(np.diff(f) > 0)


@pytest.mark.parametrize("name, cd", [
    ("difelice", lambda re: (0.63 + 4.8 / np.sqrt(re)) ** 2),               # Dallavalle
    ("gidaspow", lambda re: 24 / re * (1 + 0.15 * re**0.687)),               # Schiller-Naumann
    ("wenyu", lambda re: 24 / re * (1 + 0.15 * re**0.687)),
])
def test_single_sphere_limit(name, cd):
    """At alpha = 1 a law is the drag of one sphere: K = C_d rho pi d^2 |u - v| / 8."""
    slip = np.array([1e-4, 1e-2, 0.3])
    re = slip * D / NU
    k = drag.LAWS.lookup(name)(1.0, slip, D, RHO, NU)
    assert np.allclose(k, cd(re) * RHO * np.pi * D**2 * slip / 8, rtol=1e-12)


def test_gidaspow_dense_branch_is_ergun_per_unit_bed_volume():
    """Below alpha = 0.8: beta = K (1 - alpha) / V_p is Ergun's coefficient."""
    alpha, slip = 0.4, 0.05
    beta = drag.LAWS.lookup("gidaspow")(alpha, slip, D, RHO, NU) * (1 - alpha) / (np.pi * D**3 / 6)
    expected = (150 * (1 - alpha)**2 * RHO * NU / (alpha * D**2)
                + 1.75 * (1 - alpha) * RHO * slip / D)
    assert beta == pytest.approx(expected, rel=1e-12)


def test_koch_hill_limits():
    """Koch-Hill: Stokes' drag 3 pi mu d at alpha = 1 and creeping flow; in a dense bed at low
    Re, Carman-Kozeny's pressure gradient 180 phi^2 mu u_s / (alpha^3 d^2) through model A's
    alpha grad p = n K (u - v)."""
    k = drag.LAWS.lookup("koch_hill")(1.0, 1e-9, D, RHO, NU)
    assert k == pytest.approx(3 * np.pi * RHO * NU * D, rel=1e-5)       # phi floored at 1e-12: 3 sqrt(phi/2)
    alpha, u_s = 0.45, 1e-6                                     # m/s superficial: Re ~ 1e-3
    k = drag.LAWS.lookup("koch_hill")(alpha, u_s / alpha, D, RHO, NU)
    n = (1 - alpha) / (np.pi * D**3 / 6)
    gradient = n * k * (u_s / alpha) / alpha
    assert gradient == pytest.approx(180 * (1 - alpha)**2 * RHO * NU * u_s / (alpha**3 * D**2), rel=1e-3)
