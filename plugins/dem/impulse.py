"""The impulse that gives a contact the restitution another model asks for (the host's
restitution feedback: the DEM's softened law bounces with its own e, the plugin's model with
another). SI units; pure functions."""
from __future__ import annotations

import numpy as np


def restitution_impulse(v_i, v_j, m_i, m_j, normal, e_target, v0):
    """Velocity changes [m/s] that make the normal separation speed e_target * v0, conserving
    momentum. normal points from j to i; v_j, m_j of a wall are 0 and inf. e above 1 is
    clipped to 1 (returned count), so no collision gains energy."""
    e_target = np.asarray(e_target, float)
    clipped = int(np.sum(e_target > 1.0))
    e_target = np.minimum(e_target, 1.0)
    separation = np.einsum("ij,ij->i", v_i - v_j, normal)
    change = e_target * v0 - separation
    wall = np.isinf(m_j)
    share_i = np.where(wall, 1.0, m_j / np.where(wall, 1.0, m_i + m_j))
    share_j = np.where(wall, 0.0, m_i / np.where(wall, 1.0, m_i + m_j))
    return (share_i * change)[:, None] * normal, -(share_j * change)[:, None] * normal, clipped
