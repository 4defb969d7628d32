"""The ``softened`` comparison model against LIGGGHTS' own ``fix heat/gran``: two spheres in
one head-on collision, the heat LIGGGHTS moved against the model's."""
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from plugins.heat import Pair
from plugins.heat.comparison import COMPARISON, DemPair
from plugins.dem.hertz import effective_modulus
from pyhost.engines.liggghts import Liggghts, granular_box

pytestmark = pytest.mark.engines

R, RHO, E_DEM, NU, E_REAL = 1e-3, 2500.0, 5e6, 0.3, 63e9   # m, kg/m^3, Pa, -, Pa (glass)
K, C = 1.0, 800.0                                           # W/m/K, J/kg/K
V, DT, E_REST = 0.5, 1e-7, 0.7                              # m/s each (head-on), s, -
T_HOT, T_COLD = 400.0, 300.0


def liggghts_heat(workdir, area_correction: bool) -> tuple[float, int]:
    """Heat [J] LIGGGHTS moved from the hot sphere to the cold one over the collision, and
    the number of steps in contact. LIGGGHTS runs in a fresh process: its bridge tries
    commands in forked copies, and a fork of a process where an earlier test started MPI can
    hang in MPI."""
    code = ("import json, sys; sys.path.insert(0, sys.argv[1]); import test_softened_heat as t; "
            "print(json.dumps(t.run_liggghts(sys.argv[2], sys.argv[3] == '1')))")
    r = subprocess.run([sys.executable, "-c", code, str(Path(__file__).parent), str(workdir),
                        "1" if area_correction else "0"], capture_output=True, text=True, timeout=600,
                       cwd=Path(__file__).resolve().parents[2])
    assert r.returncode == 0, r.stderr[-3000:]
    t1, t2, v_out, steps = json.loads(r.stdout.strip().splitlines()[-1])
    m = RHO * 4 / 3 * math.pi * R**3
    assert t1 + t2 == pytest.approx(T_HOT + T_COLD, abs=1e-9)
    assert -v_out / V == pytest.approx(E_REST, rel=2e-3)      # the DEM's own restitution
    return (T_HOT - t1) * m * C, steps


def run_liggghts(workdir, area_correction: bool) -> list:
    """The collision in LIGGGHTS: final temperatures [K], rebound speed [m/s], steps."""
    with Liggghts(workdir) as lg:
        lg.commands(granular_box((-0.01,) * 3, (0.01,) * 3, youngs=E_DEM, poisson=NU, restitution=E_REST,
                                 friction=0.5, skin=R / 2, dt=DT))
        lg.commands(f"""
            fix m5 all property/global thermalConductivity peratomtype {K}
            fix m6 all property/global thermalCapacity peratomtype {C}
            fix m7 all property/global youngsModulusOriginal peratomtype {E_REAL}
            create_atoms 1 single {-1.2 * R} 0 0 units box
            create_atoms 1 single {1.2 * R} 0 0 units box
            set atom 1 diameter {2 * R} density {RHO} vx {V}
            set atom 2 diameter {2 * R} density {RHO} vx {-V}
            fix heat all heat/gran initial_temperature {T_COLD} area_correction {'yes' if area_correction else 'no'}
            fix integrate all nve/sphere
        """)
        lg.run(0)
        lg.temperature()[:] = [T_HOT, T_COLD]
        steps = 0
        while lg.atom("v")[0, 0] > 0 or lg.atom("x")[1, 0] - lg.atom("x")[0, 0] < 2 * R:
            lg.run(10)
            steps += 10
            assert steps < 200000
        t1, t2 = lg.temperature()
        return [float(t1), float(t2), float(lg.atom("v")[0, 0]), steps]


@pytest.mark.parametrize("name", ["softened", "softened_corrected"])
def test_softened_model_matches_liggghts_heat_gran(tmp_path, name):
    corrected = name == "softened_corrected"
    Q_lg, steps = liggghts_heat(tmp_path, corrected)
    pair = Pair(R1=R, R2=R, rho1=RHO, rho2=RHO, c1=C, c2=C, k1=K, k2=K, dT=T_HOT - T_COLD)
    dem = DemPair(float(effective_modulus(E_DEM, NU, E_DEM, NU)), E_REST,
                  float(effective_modulus(E_REAL, NU, E_REAL, NU)))
    out = COMPARISON[name].heat(2 * V, pair, dem)
    Q = float(out["Q"])
    # heat/gran conducts with each step's temperatures: the difference decays as
    # d(dT)/dt = -2 h dT / (m c), so over the collision it moves (m c / 2) dT0 (1 - exp(-2 G/(m c)))
    # with G = Q / dT0 the model's conductance-time [J/K].
    mc = RHO * 4 / 3 * math.pi * R**3 * C
    Q_decay = 0.5 * mc * (T_HOT - T_COLD) * (1 - math.exp(-2 * Q / (T_HOT - T_COLD) / mc))
    print(f"{name}: LIGGGHTS {Q_lg:.6e} J, model {Q:.6e} J ({Q_lg / Q - 1:+.2e}), "
          f"model with decaying dT {Q_decay:.6e} J ({Q_lg / Q_decay - 1:+.2e}); "
          f"contact {out['t_coll'] / DT:.0f} steps")
    assert Q_lg == pytest.approx(Q, rel=0.02)
    assert Q_lg == pytest.approx(Q_decay, rel=2e-3)
