"""The pairs the conduction models take, and the geometry of two spheres they share. SI units."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Pair(NamedTuple):
    """Pairs of spheres, each field an array (or a number) over the pairs.

    r_i, r_j [m]: radii; distance [m]: between the centres (overlap r_i + r_j - distance);
    k_i, k_j [W/(m K)]: the real materials' conductivities; E_dem [Pa]: the effective modulus
    E* = [(1 - nu_i^2)/E_i + (1 - nu_j^2)/E_j]^-1 of the DEM's (softened) contact, E_real [Pa]
    that of the real materials (used by the models that correct the softened overlap).
    roughness [m], slope [-], microhardness [Pa]: the surfaces' equivalent RMS roughness
    (sigma_i^2 + sigma_j^2)^(1/2), equivalent RMS slope (m_i^2 + m_j^2)^(1/2) and effective
    microhardness 2 H_i H_j / (H_i + H_j), as Lethe combines them (0: smooth; the rough
    contact models only)."""

    r_i: np.ndarray
    r_j: np.ndarray
    distance: np.ndarray
    k_i: np.ndarray
    k_j: np.ndarray
    E_dem: np.ndarray
    E_real: np.ndarray
    roughness: np.ndarray | float = 0.0
    slope: np.ndarray | float = 0.0
    microhardness: np.ndarray | float = 0.0

    @property
    def overlap(self) -> np.ndarray:
        """r_i + r_j - distance [m]: > 0 in contact, minus the gap apart."""
        return np.asarray(self.r_i) + np.asarray(self.r_j) - np.asarray(self.distance)

    @property
    def harmonic_conductivity(self) -> np.ndarray:
        """2 k_i k_j / (k_i + k_j) [W/(m K)]."""
        k_i, k_j = np.asarray(self.k_i, float), np.asarray(self.k_j, float)
        return 2.0 * k_i * k_j / (k_i + k_j)

    @property
    def effective_radius(self) -> np.ndarray:
        """R* = r_i r_j / (r_i + r_j) [m]."""
        r_i, r_j = np.asarray(self.r_i, float), np.asarray(self.r_j, float)
        return r_i * r_j / (r_i + r_j)


class Gas(NamedTuple):
    """The gas between the particles and a gap model's cut-offs.

    conductivity [W/(m K)]; lens [-]: the gas lens around the larger particle reaches
    (1 + lens) times its radius (MFiX's FLPC, 0.2 by default); min_distance [m]: the closest
    the two surfaces come in the gas path (MFiX's DES_MIN_COND_DIST, 1e-6 m by default);
    gas_parameter [m]: Lethe's gas parameter M (the gas' rarefaction length added to the gap)."""

    conductivity: float
    lens: float = 0.2
    min_distance: float = 1e-6
    gas_parameter: float = 0.0


def circle_radius(R1, R2, distance):
    """Radius [m] of the circle where a sphere of radius R1 meets a sphere of radius R2 whose
    centre lies ``distance`` [m] away (law of cosines), -1 where they do not meet (the cosine
    above 1). MFiX's FUNCTION RADIUS (model/des/des_thermo_cond_mod.f, lines 259-287):
    cos(beta) = (R1^2 - R2^2 + d^2) / (2 R1 d), radius = R1 sin(beta)."""
    R1, R2, d = (np.asarray(a, float) for a in (R1, R2, distance))
    cosine = (R1**2 - R2**2 + d**2) / (2.0 * R1 * d)
    return np.where(cosine > 1.0, -1.0, R1 * np.sqrt(np.clip(1.0 - cosine**2, 0.0, None)))
