"""cases/heated-packed-bed: Beaulieu's heated packed bed as Lethe sets it up. The smoke run
(-test: 400 beads, a few ms of DEM, then the 4000 s frozen stage) in the default suite; the full
case (8849 beads) behind the ``validation`` marker (``pytest -m validation``, about 6-7 min)."""
import csv
import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "cases" / "heated-packed-bed"
sys.path.insert(0, str(CASE))
from compare import compare  # noqa: E402
from conftest import once  # noqa: E402

pytestmark = pytest.mark.engines


def run(out: Path, *flags) -> tuple[dict, float]:
    start = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(CASE), "--out", str(out), *flags],
                       capture_output=True, text=True, cwd=ROOT, timeout=1800)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return json.loads((out / "summary.json").read_text()), time.perf_counter() - start


def test_smoke_run_writes_the_probes_and_closes_the_balance(tmp_path):
    """The smoke run ends its 4000 s frozen stage at 1 s steps with the three probes' columns
    written every 10 s, the plate's heat in the balance (closed to 1e-12)."""
    summary, seconds = run(tmp_path / "out", "--test")
    rows = list(csv.DictReader(open(tmp_path / "out" / "probes.csv")))
    assert list(rows[0]) == ["time", "T_40mm", "T_60mm", "T_73mm"]
    frozen = summary["frozen_stage"]
    assert frozen["steps"] == 4000 and frozen["step"] == 1.0
    assert float(rows[-1]["time"]) == pytest.approx(frozen["start"] + 4000.0, rel=1e-12)
    assert sum(float(r["time"]) > frozen["start"] for r in rows) == 400
    assert summary["heat_conducted_wall"] > 0
    assert abs(summary["energy_balance_error"]) < 1e-12


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    def make(folder):
        summary, seconds = run(folder / "out")
        (folder / "seconds").write_text(repr(seconds))

    folder = once(tmp_path_factory, "heated-packed-bed", make)
    out = folder / "out"
    return out, json.loads((out / "summary.json").read_text()), float((folder / "seconds").read_text())


@pytest.mark.validation
def test_full_case_runs_in_15_minutes_with_its_balance_closed(full):
    out, summary, seconds = full
    print(f"heated packed bed: {seconds:.0f} s, frozen stage {summary['frozen_stage']}")
    assert seconds < 15 * 60
    assert summary["frozen_stage"]["pairs_in_contact"] > 15000 and summary["frozen_stage"]["wall_links"] > 50
    assert abs(summary["energy_balance_error"]) < 1e-9


@pytest.mark.validation
@pytest.mark.xfail(strict=True, reason="measured: 40 mm misses (worst 2.48 K, 1.2 K too cold on "
                                       "average); 60 and 73 mm within (1.10, 0.74 K): README.md; nothing fitted")
def test_full_case_within_1_5_K_of_the_experiment_after_900_s(full):
    """The issue's goal: every experimental point after 900 s within 1.5 K, at 40, 60, 73 mm."""
    out, summary, seconds = full
    result = compare(out)
    print(result)
    assert all(worst <= 1.5 for worst, mean, n in result.values())


@pytest.mark.validation
def test_full_case_holds_what_it_measured(full):
    """What the published values give now (README.md), so that a change that moves the bed away
    from the experiment fails: 60 and 73 mm within the goal's 1.5 K after 900 s, 40 mm within
    3.0 K (measured 2.48 K; the goal itself is the expected failure above)."""
    out, summary, seconds = full
    result = compare(out)
    print(result)
    assert result["T_60mm"][0] <= 1.5 and result["T_73mm"][0] <= 1.5
    assert result["T_40mm"][0] <= 3.0
