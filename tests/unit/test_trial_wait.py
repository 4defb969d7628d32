"""The wait for a forked trial of a LIGGGHTS command (pyhost.engines.liggghts): it returns the
copy's status as soon as the copy ends, and ends a copy that wrote an ERROR line but hangs
(stuck in MPI_Finalize). Real child processes, no engine."""
import os
import signal
import time

from pyhost.engines.liggghts import Liggghts


def child(body):
    pid = os.fork()
    if pid == 0:
        try:
            body()
        finally:
            os._exit(0)
    return pid


def test_the_status_of_a_copy_that_ends_comes_back_when_it_ends(tmp_path):
    pid = child(lambda: (time.sleep(0.05), os._exit(3)))
    start = time.monotonic()
    status = Liggghts._wait_trial(pid, tmp_path / "log.trial")
    waited = time.monotonic() - start
    assert os.waitstatus_to_exitcode(status) == 3
    assert 0.04 < waited < 0.5, waited          # woken at the end, not a sleep's length later


def test_a_copy_stuck_after_its_error_line_is_ended(tmp_path):
    trial = tmp_path / "log.trial"

    def stuck():
        trial.write_text("ERROR: Illegal fix command (fix.cpp:42)\n")
        time.sleep(30)

    pid = child(stuck)
    start = time.monotonic()
    status = Liggghts._wait_trial(pid, trial)
    waited = time.monotonic() - start
    assert os.waitstatus_to_exitcode(status) == -signal.SIGKILL
    assert 1.4 < waited < 3.0, waited           # seen after 0.5 s, ended 1 s later
