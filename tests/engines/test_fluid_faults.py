"""The real collheatFoam stopped mid-run (SIGSTOP): the host does not hang, it names the
stall and the time waited, and leaves no process and no pipe behind."""
import os
import signal
import time

import pytest

from pyhost.engines.fluid_case import box_case
from pyhost.engines.openfoam import FluidError, FluidSolver

pytestmark = pytest.mark.engines


def test_stopped_solver_ends_the_run_within_the_time_out(tmp_path):
    timeout = 3.0                                                     # s
    case = box_case(tmp_path / "fluid", lo=(0, 0, 0), hi=(0.01, 0.01, 0.01), cells=(2, 2, 2), rho=1.2,
                    nu=1.5e-5, boundaries={f: "wall" for f in ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi")})
    fluid = FluidSolver(case, timeout=timeout).start()
    assert fluid.advance(1e-3) == pytest.approx(1e-3)
    pid = fluid.proc.pid
    os.kill(pid, signal.SIGSTOP)
    start = time.monotonic()
    with pytest.raises(FluidError, match=r"did not answer within 3\.\d s while computing: it was stopped"):
        fluid.advance(1e-3)
    assert time.monotonic() - start < timeout + 2.0
    fluid.stop()
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)
    assert not (case / ".link").exists()
