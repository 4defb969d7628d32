"""The local computes of LIGGGHTS 3.8 whose rows ``dump local`` writes (``compute pair/gran/local``
and ``wall/gran/local``): which column holds what, from the compute's keywords, in the order
LIGGGHTS writes them whatever order they were typed in (measured in ../shared/ENGINES.md and
read from ``compute_pair_gran_local.h`` of LIGGGHTS 3.8). ``pyhost.dumps`` names a local dump's
columns with them; a column that cannot be placed for sure is an error, never a guess.
"""
from __future__ import annotations

import shlex
from dataclasses import dataclass
from itertools import islice

# compute pair/gran/local and wall/gran/local of LIGGGHTS 3.8: keyword -> its columns (name,
# width), pair then wall, in the order LIGGGHTS writes them. "history" has the width of the pair
# style's history (unknown here). heatFlux is written last whatever else is asked for.
LOCAL_GROUPS = {
    "pos": ((("x_i", 3), ("x_j", 3)), (("x_contact", 3), ("x_i", 3))),
    "vel": ((("v_i", 3), ("v_j", 3)), (("v_wall", 3), ("v_i", 3))),
    "id": ((("id_i", 1), ("id_j", 1), ("periodic", 1)), (("mesh", 1), ("triangle", 1), ("id_i", 1))),
    "force": ((("force", 3),),) * 2,
    "force_normal": ((("force_normal", 3),),) * 2,
    "force_tangential": ((("force_tangential", 3),),) * 2,
    "torque": ((("torque", 3),),) * 2,
    "torque_normal": ((("torque_normal", 3),),) * 2,
    "torque_tangential": ((("torque_tangential", 3),),) * 2,
    "history": ((("history", None),),) * 2,
    "contactArea": ((("contact_area", 1),),) * 2,
    "delta": ((("delta", 1),),) * 2,
    "contactPoint": ((("contact_point", 3),),) * 2,
    "heatFlux": ((("heat_flux", 1),),) * 2,
}
LOCAL_DEFAULT = ("pos", "vel", "id", "force", "torque", "history", "contactArea")   # no keyword given
LOCAL_OPTIONS = {"verbose": 0, "extraSurfDistance": 1}      # keywords that add no column: values taken
LOCAL_STYLES = ("pair/gran/local", "wall/gran/local")


@dataclass(frozen=True)
class Compute:
    """A LIGGGHTS ``compute ID group STYLE keywords...`` of a local style."""

    id: str
    style: str
    keywords: tuple = ()

    @property
    def wall(self) -> bool:
        return self.style == "wall/gran/local"

    def columns(self) -> list:
        """(name, component) of each column the compute writes, in LIGGGHTS' order; a name
        of None stands for columns of unknown width (history), after which nothing is known."""
        words = [w for w in self.keywords if w in LOCAL_GROUPS] or list(LOCAL_DEFAULT)
        cols = []
        for kw in [k for k in LOCAL_GROUPS if k in words]:
            for name, width in LOCAL_GROUPS[kw][self.wall]:
                if width is None:
                    return cols + [(None, None)]
                cols += [(name, c) for c in range(width)] if width > 1 else [(name, None)]
        return cols


def parse_compute(text: str, where: str = "") -> Compute:
    """A compute from ``ID STYLE keywords...`` (or a whole ``compute ID group STYLE ...`` line)."""
    words = shlex.split(text.split("#")[0])
    if words and words[0] == "compute":
        words = words[1:2] + words[3:]
    if len(words) < 2 or words[1] not in LOCAL_STYLES:
        raise ValueError(f"{where}compute {text!r}: expected 'ID STYLE keyword...' with STYLE "
                         f"{' or '.join(LOCAL_STYLES)}")
    keywords, rest = [], iter(words[2:])
    for w in rest:
        if w in LOCAL_OPTIONS:
            list(islice(rest, LOCAL_OPTIONS[w]))
        elif w in LOCAL_GROUPS:
            keywords.append(w)
        else:
            raise ValueError(f"{where}compute {words[0]}: keyword {w!r} not understood; known: "
                             f"{', '.join(LOCAL_GROUPS)}")
    return Compute(words[0], words[1], tuple(keywords))
