"""``collective``: the mark of rank 0's methods that make collective MPI calls (pyhost.engines.ranks
orders the other ranks' part of each), shared by the engines' bridges."""
from __future__ import annotations

import functools

from pyhost.engines.liggghts import LiggghtsFailed


def collective(method):
    """A method of rank 0 that makes collective calls: an error inside it leaves the
    followers possibly waiting in another call, so the link is marked broken (the run then
    ends through MPI_Abort, pyhost.commands.run)."""
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        try:
            return method(self, *args, **kwargs)
        except LiggghtsFailed:
            raise                 # every rank's LIGGGHTS returned with it (Error::all): still in step
        except BaseException:
            if self.link is not None:
                self.link.broken = True
            raise
    return wrapper
