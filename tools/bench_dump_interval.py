"""What the contact-dump interval costs offline: collision count and heat against the online run.

The user-style case cases/silo-heat (STL tube and shaken plate, two materials at 400 K and
300 K, polydisperse, insertion) in its -test length: once through the host (``pyhost run``,
contact events recorded at every step: the reference), then as plain ``liggghts``
runs of the same script whose contact dumps are written every K steps, each post-processed
(``pyhost post --model A``). Prints a table: K, interval, collisions and heat, and their
errors against the online run. Wall collisions differ by design: the host counts one per
particle and wall fix, post one per particle and mesh (the tube and the plate are two meshes
of one fix).

Run: .venv/bin/python tools/bench_dump_interval.py [--every 5 25 100 500 1000]
"""
from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

CASE = Path(__file__).resolve().parents[1] / "cases" / "silo-heat"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--every", type=int, nargs="+", default=[5, 25, 100, 500, 1000])
    args = p.parse_args()
    from pyhost.scene import load_scene

    scene = load_scene(CASE / "case.toml")
    variables = [a for k, v in {**scene.dem.variables, **scene.dem.test_variables}.items() for a in ("-var", k, str(v))]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        shutil.copytree(CASE, tmp / "online", ignore=shutil.ignore_patterns("output", "post"))
        (tmp / "online" / "post").mkdir()
        subprocess.run([sys.executable, "-m", "pyhost", "run", str(tmp / "online"), "--test", "--out",
                        str(tmp / "online" / "output")], check=True, capture_output=True)
        ref = json.loads((tmp / "online" / "output" / "summary.json").read_text())
        print(f"online (contact events at every step): {ref['particle_particle']} particle-particle and "
              f"{ref['particle_wall']} wall collisions, {ref['heat_moved']:.5g} J between particles")
        print(f"{'K':>6} {'interval s':>10} {'pp':>6} {'pp err %':>9} {'wall':>6} {'heat J':>11} {'heat err %':>10}")
        for k in args.every:
            run = tmp / f"every{k}"
            shutil.copytree(CASE, run, ignore=shutil.ignore_patterns("output", "post"))
            (run / "post").mkdir()
            script = run / "in.liggghts"
            script.write_text(re.sub(r"^(dump\s+c\w+\s+all\s+local\s+)\d+", rf"\g<1>{k}",
                                     script.read_text(), flags=re.M))
            subprocess.run(["liggghts", "-in", "in.liggghts", "-log", "log.liggghts", "-screen", "/dev/null",
                            *variables], cwd=run, check=True)
            subprocess.run([sys.executable, "-m", "pyhost", "post", str(run / "post" / "particles_*.dump"),
                            "--scene", str(CASE / "case.toml"), "--contacts", str(run / "post" / "pairs_*.dump"),
                            str(run / "post" / "walls_*.dump"), "--script", str(script), "--model", "A",
                            "--out", str(run / "out")], check=True, capture_output=True)
            s = json.loads((run / "out" / "summary.json").read_text())
            pp, wall, heat = s["collisions"]["particle_particle"], s["collisions"]["particle_wall"], s["heat_J"]["A"]
            print(f"{k:6d} {s['dump_interval_s']:10.3g} {pp:6d} {100 * (pp / ref['particle_particle'] - 1):9.2f} "
                  f"{wall:6d} {heat:11.5g} {100 * (heat / ref['heat_moved'] - 1):10.2f}"
                  + ("   (warned: interval > shortest collision)" if any("dump interval" in w for w in s["warnings"])
                     else ""))


if __name__ == "__main__":
    main()
