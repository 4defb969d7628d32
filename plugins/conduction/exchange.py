"""Heat a set of conducting pairs exchanges over an interval, stable at any interval.

Pair p between particles i and j (heat capacities C_i, C_j [J/K]) conducts with G_p [J/K],
its conductance integrated over the interval (H [W/K] times the time it conducts). Alone, the
pair relaxes exactly:

    q = (T_j - T_i) (1 - exp(-G (1/C_i + 1/C_j))) / (1/C_i + 1/C_j)    [J into i, out of j],

which is the exact solution of C_i dT_i/dt = H (T_j - T_i), C_j dT_j/dt = -H (T_j - T_i)
over the interval for any length of it. A particle with n conducting pairs shares its
capacity among them: each pair relaxes as above with C_i / n_i and C_j / n_j. Then:

- energy is conserved to round-off (what i gains, j loses);
- no temperature leaves the range of its neighbours' (each share relaxes towards a value
  between T_i and T_j, and T_i's new value is the mean of its shares);
- an isolated pair (n_i = n_j = 1) is exact at any interval; in a network the scheme is
  first order in the interval (the pairs of a particle see its temperature at the start).
"""
from __future__ import annotations

import numpy as np


def exchange(T, C, i, j, G):
    """Heat into each pair's particle i [J] (n_pairs,), out of its particle j. ``T`` [K] and
    ``C`` [J/K, > 0]: temperatures and heat capacities of the particles; ``i``, ``j``:
    indices into them of each pair (i != j); ``G`` [J/K, >= 0]: each pair's conductance times
    the time it conducts. The new temperatures are T + (np.bincount(i, q) - np.bincount(j, q))
    / C."""
    T, C, G = (np.asarray(a, float) for a in (T, C, G))
    n = np.bincount(i, minlength=len(T)) + np.bincount(j, minlength=len(T))
    inv = n[i] / C[i] + n[j] / C[j]
    return (T[j] - T[i]) * -np.expm1(-G * inv) / inv
