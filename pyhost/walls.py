"""Every kind of wall's geometry in one place: the box faces a box scene names, and LIGGGHTS'
primitive walls (``fix wall/gran ... primitive type T xplane p``, ``zcylinder R c1 c2``, ...)
of users' scripts. The engines, the scene checks, the contact finder of post and the script
readers take their walls from here. Mesh walls are LIGGGHTS' own (their contacts come from
its computes and the event recorder, pyhost.engines).

A wall's contact with a sphere of radius r [m] at x [m]: the overlap delta = r - distance
from the centre to the surface [m] (> 0 in contact) and the unit normal pointing from the
wall to the centre, as LIGGGHTS computes them. SI units; pure functions.
"""
from __future__ import annotations

import numpy as np

FACES = ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi")
"""A box scene's walls: face k lies at box[k] of box = (xmin, xmax, ymin, ymax, zmin, zmax)."""

PRIMITIVES = {"xplane": 1, "yplane": 1, "zplane": 1, "xcylinder": 3, "ycylinder": 3, "zcylinder": 3}
"""LIGGGHTS primitive wall kinds the host reads, and how many numbers follow each: a plane's
position; a cylinder's radius R and its axis' coordinates c1 c2 along the axes that follow its
own cyclically (LIGGGHTS' primitive_wall_definitions.h): y z for xcylinder, z x for ycylinder
(not x z), x y for zcylinder."""


def face_axis(face: str) -> tuple[int, bool]:
    """(axis 0-2, whether it is the high side) of a box face "xlo" ... "zhi"."""
    if face not in FACES:
        raise ValueError(f"unknown box face {face!r}; choices: {', '.join(FACES)}")
    return "xyz".index(face[0]), face.endswith("hi")


def face_primitive(face: str, box) -> tuple[str, tuple[float]]:
    """The LIGGGHTS primitive wall (kind, (position,)) on a box face."""
    return face[0] + "plane", (float(box[FACES.index(face)]),)


def face_gap(x, face: str, box) -> np.ndarray:
    """Distance [m] from each centre x (n, 3) to the face, positive inside the box."""
    axis, hi = face_axis(face)
    x = np.asarray(x, float)
    return box[2 * axis + 1] - x[:, axis] if hi else x[:, axis] - box[2 * axis]


def face_overlap(x, r, face: str, box) -> tuple[np.ndarray, np.ndarray]:
    """(delta [m], normal (n, 3)) of spheres against a box face: one-sided, the normal points
    into the box whichever side the centre is on."""
    axis, hi = face_axis(face)
    normal = np.zeros((len(r), 3))
    normal[:, axis] = -1.0 if hi else 1.0
    return r - face_gap(x, face, box), normal


def primitive_overlap(x, r, primitive) -> tuple[np.ndarray, np.ndarray]:
    """(delta [m], normal (n, 3)) of spheres against a primitive wall (kind, numbers): a plane
    acts on both its sides, a cylinder on its inside and its outside."""
    kind, num = primitive
    if kind not in PRIMITIVES:
        raise ValueError(f"unknown primitive wall {kind!r}; choices: {', '.join(PRIMITIVES)}")
    axis = "xyz".index(kind[0])
    x = np.asarray(x, float)
    normal = np.zeros((len(x), 3))
    if kind.endswith("plane"):
        s = x[:, axis] - num[0]
        normal[:, axis] = np.where(s >= 0, 1.0, -1.0)
        return r - np.abs(s), normal
    other = [(axis + 1) % 3, (axis + 2) % 3]          # c1, c2 as LIGGGHTS reads them
    rad = x[:, other] - np.array(num[1:3])
    dist = np.linalg.norm(rad, axis=1)
    unit = rad / np.where(dist > 0, dist, 1.0)[:, None]
    inside = dist < num[0]
    normal[:, other] = np.where(inside[:, None], -unit, unit)
    return r - np.where(inside, num[0] - dist, dist - num[0]), normal
