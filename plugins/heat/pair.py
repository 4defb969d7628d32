"""The colliding pair: material and geometry of the two bodies, and the scales they set.

All inputs and outputs are SI. Body 2 may be a flat wall (``R2 = inf``): then R* = R1 and
m* = m1 (Kosinski et al. 2014, sec. 2). The wall's rho2, c2, k2 still set its thermal
effusivity in eq. (2).

Scales (used to make every contact model dimensionless, see ``plugins.heat.exact``):

- ``delta_y`` indentation at first yield, eq. (6): (3 pi b1 Y / (4 E*))^2 R*   [m]
- ``a_y`` contact radius at first yield, a_y^2 = R* delta_y (eq. 5)             [m]
- ``F_y`` Hertz force at first yield, pi a_y^2 b1 Y                              [N]
- ``v_y`` impact speed at which yield starts: (1/2) m* v_y^2 equals the Hertz work
  (8/15) E* R*^(1/2) delta_y^(5/2) = (2/5) F_y delta_y                           [m/s]
- ``t_y`` = delta_y / v_y                                                        [s]
- ``sigma`` = (rho1 c1 k1)^-1/2 + (rho2 c2 k2)^-1/2, denominator of eq. (2)      [m^2 K s^1/2 / J]
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

PAPER_SET = dict(R1=2e-3, R2=2e-3, rho1=6000.0, rho2=6000.0, Estar=100e9, Y=300e6,
                 b1=1.1, b2=2.8, c1=400.0, c2=400.0, k1=20.0, k2=20.0, dT=100.0)
"""The parameter set of Kosinski et al. (2014), sec. 6."""


@dataclass(frozen=True)
class Pair:
    """Two colliding bodies (or a sphere and a wall). SI units; fields may be numpy arrays.

    R1, R2 radii [m] (R2 = inf for a flat wall); rho1, rho2 densities [kg/m^3];
    Estar effective Young's modulus [Pa]; Y yield stress [Pa]; b1, b2 mean contact pressure
    at first yield and in the fully plastic range, in units of Y [-] (b2 > b1);
    c1, c2 heat capacities [J/(kg K)]; k1, k2 conductivities [W/(m K)];
    dT initial temperature difference T1 - T2 [K] (Q > 0 flows from body 1 to body 2);
    c_log the constant of the logarithm in eq. (8) [-]; None means 3*b1, the value that makes
    the elastic-plastic force meet the fully plastic one at delta_p (the paper prints 3.3,
    which is 3*b1 for b1 = 1.1; any other value makes the force jump at delta_p).
    """

    R1: float = PAPER_SET["R1"]
    R2: float = PAPER_SET["R2"]
    rho1: float = PAPER_SET["rho1"]
    rho2: float = PAPER_SET["rho2"]
    Estar: float = PAPER_SET["Estar"]
    Y: float = PAPER_SET["Y"]
    b1: float = PAPER_SET["b1"]
    b2: float = PAPER_SET["b2"]
    c1: float = PAPER_SET["c1"]
    c2: float = PAPER_SET["c2"]
    k1: float = PAPER_SET["k1"]
    k2: float = PAPER_SET["k2"]
    dT: float = PAPER_SET["dT"]
    c_log: float | None = None
    _derived: dict = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        positive = ("R1", "rho1", "rho2", "Estar", "Y", "b1", "b2", "c1", "c2", "k1", "k2")
        for name in positive + ("R2",):
            value = getattr(self, name)
            if type(value) in (float, int):      # a plain number (most fields): no numpy round trip
                ok = 0 < value < math.inf or (name == "R2" and value == math.inf)
            else:
                value = np.asarray(value, dtype=float)
                ok = np.all(value > 0) and (name == "R2" or np.all(value < np.inf))
            if not ok:
                raise ValueError(f"{name} must be positive and finite{' (or inf)' if name == 'R2' else ''}, "
                                 f"got {getattr(self, name)!r}")
        if not np.all(np.isfinite(np.asarray(self.dT, dtype=float))):
            raise ValueError(f"dT must be finite, got {self.dT!r}")
        if np.any(np.asarray(self.b2) <= np.asarray(self.b1)):
            raise ValueError(f"b2 must exceed b1 (fully plastic pressure above first yield), "
                             f"got b1={self.b1!r}, b2={self.b2!r}")
        if self.c_log is not None and not (math.isfinite(self.c_log) and self.c_log > 0):
            raise ValueError(f"c_log must be positive and finite, got {self.c_log!r}")
        object.__setattr__(self, "_derived", self._scales())

    @classmethod
    def wall(cls, **kwargs) -> "Pair":
        """A sphere (body 1) against a flat wall (body 2): R2 = inf, m* = m1."""
        kwargs["R2"] = math.inf
        return cls(**kwargs)

    def replace(self, **changes) -> "Pair":
        return dataclasses.replace(self, **changes)

    @property
    def log_constant(self):
        """The constant of ln() in eq. (8) actually used [-]."""
        return 3.0 * np.asarray(self.b1, dtype=float) if self.c_log is None else self.c_log

    def _scales(self) -> dict:
        R1, R2 = np.asarray(self.R1, float), np.asarray(self.R2, float)
        m1 = 4.0 / 3.0 * np.pi * R1**3 * self.rho1
        m2 = 4.0 / 3.0 * np.pi * R2**3 * self.rho2
        with np.errstate(invalid="ignore", divide="ignore"):
            Rstar = np.where(np.isinf(R2), R1, R1 * R2 / (R1 + R2))
            mstar = np.where(np.isinf(m2), m1, m1 * m2 / (m1 + m2))
        delta_y = (3.0 * np.pi * self.b1 * self.Y / (4.0 * self.Estar)) ** 2 * Rstar   # eq. (6)
        a_y = np.sqrt(Rstar * delta_y)                                                  # eq. (5)
        F_y = np.pi * a_y**2 * self.b1 * self.Y
        v_y = np.sqrt(4.0 * F_y * delta_y / (5.0 * mstar))
        sigma = (np.asarray(self.rho1) * self.c1 * self.k1) ** -0.5 \
            + (np.asarray(self.rho2) * self.c2 * self.k2) ** -0.5                       # eq. (2)
        d = dict(m1=m1, m2=m2, Rstar=Rstar, mstar=mstar, delta_y=delta_y, a_y=a_y, F_y=F_y,
                 v_y=v_y, t_y=delta_y / v_y, sigma=sigma)
        return {k: (float(v) if np.ndim(v) == 0 else v) for k, v in d.items()}

    def __getattr__(self, name):
        derived = object.__getattribute__(self, "_derived")
        if derived is not None and name in derived:
            return derived[name]
        raise AttributeError(name)

    @property
    def Q_scale(self):
        """Heat unit [J]: 2 sqrt(pi) dT a_y^2 sqrt(t_y) / sigma (eqs. 2-3 made dimensionless)."""
        return 2.0 * math.sqrt(math.pi) * np.asarray(self.dT, float) * self.a_y**2 \
            * np.sqrt(self.t_y) / self.sigma

    def onset_speeds(self) -> tuple:
        """(v_y, v_p) [m/s]: impact speeds at which compression reaches first yield and the
        fully plastic range in Stronge's model (A, C). See ``plugins.heat.compression``."""
        from plugins.heat.compression import Stronge
        law = Stronge(float(np.asarray(self.b1)), float(np.asarray(self.b2)),
                      float(np.asarray(self.log_constant)))
        return self.v_y, self.v_y * law.v_hat_p
