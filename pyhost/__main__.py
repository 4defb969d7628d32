import signal
import sys


def _before_start(signum, frame):
    """A signal while the command line is still being read (importing every command takes
    about half a second): a quiet stop, nothing begun, no traceback. The process ends here
    (os._exit): an exception raised by a handler that runs inside a finaliser is ignored, and
    the command went on (test_cli caught it once in a few hundred runs)."""
    import os
    sys.stderr.write(f"interrupted: {signal.Signals(signum).name} received before the command started; "
                     "nothing was run\n")
    sys.stderr.flush()
    os._exit(128 + signum)


for _signal in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
    signal.signal(_signal, _before_start)

from pyhost.cli import main  # noqa: E402  (after the handlers: the import is the slow part)

sys.exit(main())
