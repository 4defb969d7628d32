"""Section 4 of ``bench_host.py`` (heat against plain DEM by particle count) on the code
before the LIGGGHTS-script rewrite (commit a8d075d: ``SceneDem`` and ``Coupling(...).run()``).
``bench_host.py --baseline TREE`` runs it with PYTHONPATH=TREE; it prints the rows as one
JSON line.

Run: PYTHONPATH=/path/to/old/checkout .venv/bin/python tools/bench_host_baseline.py SIM_TIME REPEAT N [N ...]
"""
from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

from bench_host import heat_by_size

try:        # the old code (a8d075d): its modules are gone from this tree, PYTHONPATH gives them
    from pyhost.dem import SceneDem
    from pyhost.dem_input import place_particles
    from pyhost.loop import Coupling
except ImportError as exc:
    sys.exit(f"bench_host_baseline.py runs the code of commit a8d075d ({exc}): give PYTHONPATH=/path/to/that checkout")


def run_host(scene, out: Path):
    """As bench_host.run_host: wall time of Coupling.run(), not of the DEM's set-up."""
    particles = place_particles(scene)
    dem = SceneDem(scene, particles, out / "dem")
    t = time.perf_counter()
    try:
        summary = Coupling(scene, dem, particles, out, progress_every=1e9).run()
    finally:
        dem.close()
    return time.perf_counter() - t, summary


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as tmp:
        rows = heat_by_size(run_host, [int(n) for n in sys.argv[3:]], float(sys.argv[1]), Path(tmp), int(sys.argv[2]))
    print(json.dumps(rows))
