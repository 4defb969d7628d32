"""Heat exchanged between particles and the gas of their cells over one coupling interval,
stable at any interval.

Each cell with its particles is a star: particle i (heat capacity C_i = m_i c_i [J/K],
temperature T_i) exchanges with the cell's gas (C_g = rho_g c_g alpha V, T_g) through the
conductance G_i = h_i A_i [W/K]:

    C_i dT_i/dt = G_i (T_g - T_i),        C_g dT_g/dt = sum_i G_i (T_i - T_g).

An explicit step overshoots once G_i dt / C_i > 1 (tiny particles, large h, long interval).
Here each particle relaxes exponentially, exactly, towards the gas temperature T_g' at the
end of the interval, and T_g' is the one that conserves the energy of the cell:

    T_i' = T_g' + (T_i - T_g') exp(-G_i dt / C_i),   a_i = C_i (1 - exp(-G_i dt / C_i)),
    T_g' = (C_g T_g + sum_i a_i T_i) / (C_g + sum_i a_i),   q_i = a_i (T_g' - T_i).

T_g' is a weighted mean of the cell's temperatures and each T_i' lies between T_i and T_g':
no phase passes the other's temperature, for any dt. The gas receives -sum_i q_i, so energy
is conserved to round-off. It is exact when the gas outweighs the particles
(C_g >> sum C_i: a particle in a stream), and for a single particle it tends to the exact
two-body relaxation as dt -> 0 (implicit in T_g, first order); as dt -> infinity every cell
reaches its common equilibrium temperature exactly.
"""
from __future__ import annotations

import numpy as np


def exchange(T_p, C_p, G, cell, T_g, C_g, dt):
    """Heat into each particle over ``dt`` [s], q [J] (n,), and the gas temperature of every
    cell at the end of the interval [K] (ncells,). ``T_p`` [K], ``C_p`` [J/K], ``G`` [W/K]
    and ``cell`` (index into T_g) per particle; ``T_g`` [K] and ``C_g`` [J/K, > 0] per cell.
    The cells' gas gains -sum of q of its particles: ``np.bincount(cell, -q)``."""
    T_p, C_p, G = (np.asarray(a, float) for a in (T_p, C_p, G))
    T_g, C_g = np.asarray(T_g, float), np.asarray(C_g, float)
    a = -C_p * np.expm1(-G * dt / C_p)
    n = len(T_g)
    T_end = (C_g * T_g + np.bincount(cell, a * T_p, n)) / (C_g + np.bincount(cell, a, n))
    q = a * (T_end[cell] - T_p)
    return q, T_end
