"""Joining the contact events of several MPI ranks (pyhost.engines.events.join_moved), without
engines: an open contact whose atom moves to another rank at a neighbour build ends there and
begins on the new rank at the same step, both flagged; the join keeps one contact going."""
import numpy as np

from pyhost.engines.events import BEGIN, END, EVENT, join_moved
from pyhost.collisions import WALL_BASE, contact_keys


def events(*rows):
    """rows: (kind, step, i, j, moved, duration)."""
    ev = np.zeros(len(rows), EVENT)
    for r, (kind, step, i, j, moved, duration) in enumerate(rows):
        ev[r]["kind"], ev[r]["step"], ev[r]["i"], ev[r]["j"] = kind, step, i, j
        ev[r]["moved"], ev[r]["duration"], ev[r]["wall"] = moved, duration, j >= WALL_BASE
    return ev


def test_a_contact_that_moved_ranks_is_neither_ended_nor_begun():
    # rank 0's batch, then rank 1's: pair (3, 7) began at step 100 on rank 0 and moved to
    # rank 1 at the build of step 140; wall contact of 5 moved at 140 too
    ev = events((BEGIN, 100, 3, 7, False, 0), (END, 140, 3, 7, True, 40), (END, 140, 5, WALL_BASE + 1, True, 12),
                (BEGIN, 140, 3, 7, True, 0), (BEGIN, 140, 5, WALL_BASE + 1, True, 0), (END, 150, 3, 7, False, 10))
    out, joined = join_moved(ev)
    assert [(int(e["kind"]), int(e["step"]), int(e["i"]), int(e["j"])) for e in out] == [(BEGIN, 100, 3, 7), (END, 150, 3, 7)]
    assert sorted(joined) == sorted([(int(contact_keys(np.array([3]), np.array([7]))[0]), 100, 140),
                                     (int(contact_keys(np.array([5]), np.array([WALL_BASE + 1]))[0]), 128, 140)])
    assert not out["moved"].any()


def test_unmatched_moved_rows_are_real_events():
    # a contact that began at a build (flagged: it might have come from another rank), and one
    # that ended as its atom left; a moved END and BEGIN of one pair at different steps are two events
    ev = events((BEGIN, 140, 1, 2, True, 0), (END, 140, 4, 9, True, 6), (END, 160, 6, 8, True, 3),
                (BEGIN, 180, 6, 8, True, 0))
    out, joined = join_moved(ev)
    assert joined == []
    assert len(out) == 4 and list(out["step"]) == [140, 140, 160, 180]
    assert not out["moved"].any()


def test_batches_of_ranks_come_out_in_step_order():
    ev = events((BEGIN, 30, 1, 2, False, 0), (BEGIN, 50, 3, 4, False, 0), (BEGIN, 10, 5, 6, False, 0),
                (BEGIN, 30, 7, 8, False, 0))
    out, _ = join_moved(ev)
    assert list(out["step"]) == [10, 30, 30, 50]
    assert list(out["i"][1:3]) == [1, 7]          # within a step, the ranks' order (stable)
