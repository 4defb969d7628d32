"""Writes docs/scene.md, the reference of every case.toml key, from the scene's own
dataclasses (pyhost/scene.py: each field's rule, default and documentation with units), so
the page cannot drift from the code (tests/unit/test_scene_doc.py checks it).

Run: .venv/bin/python tools/scene_doc.py
"""
from __future__ import annotations

import dataclasses
import sys
import typing
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from plugins.heat import MODEL_NAMES  # noqa: E402
from pyhost import schema as S  # noqa: E402

SECTIONS = (
    ("[dem]", S.Dem, "A user's own LIGGGHTS script. With it, [[particles]] and [domain] are not used: "
                     "the script places the particles, sets the box, the walls and the time step."),
    ("[effects]", S.Effects, "What the host simulates: only these are built."),
    ("[materials.NAME]", S.Material, "A real material, for the contact models (never the DEM's softened values)."),
    ("[materials.NAME].dem", S.DemContact, "The DEM's softened contact of a box scene's material "
                                            "(a script sets its own)."),
    ("[[particles]]", S.Particles, "Box scenes: a group of particles the host places."),
    ("[[walls]]", S.Wall, "A wall's real material and temperature: by plane (box scenes) or by the id of "
                          "the script's fix wall/gran (script scenes). A script wall with no entry is adiabatic for "
                          "collision heat (a fix heat/gran of the script still conducts through it at the temperature "
                          "the script gives it)."),
    ("[domain]", S.Domain, "Box scenes: the box."),
    ("[time]", S.Time, "Time steps, fluid coupling and harvests."),
    ("[fluid]", S.Fluid, "The gas, solved by collheatFoam."),
    ("[conduction]", S.Conduction, "Lasting conduction between particles (effects.contact_conduction, "
                                   "effects.gap_conduction: plugins/conduction): how often it is updated, the gas "
                                   "in the gaps and the gap models' cut-offs. Used only when a model is asked for."),
    ("[frozen]", S.Frozen, "The frozen-bed thermal stage after the script's last run (pyhost/frozen.py): the "
                           "particles stay where the DEM left them and heat moves through the lasting conduction "
                           "network and the walls at a temperature, at thermal steps set for heat alone. Needs "
                           "effects.contact_conduction or effects.gap_conduction; not with a fluid."),
    ("[output]", S.Output, "What a run writes."),
)


def default(f) -> str:
    if f.default is not dataclasses.MISSING:
        return f"`{f.default!r}`"
    if f.default_factory is not dataclasses.MISSING:
        return f"`{f.default_factory()!r}`"
    return "required"


def page() -> str:
    lines = ["# case.toml: every key", "",
             "Generated from `pyhost/scene.py` by `.venv/bin/python tools/scene_doc.py`; SI units. A wrong key, "
             "type or value stops the run before any engine starts, naming the file and the key.", ""]
    for title, cls, text in SECTIONS:
        hints = typing.get_type_hints(cls)
        lines += [f"## {title}", "", text, "", "| key | type | default | meaning |", "|---|---|---|---|"]
        for f in dataclasses.fields(cls):
            kind = hints[f.name]
            parts = [kind] if isinstance(kind, type) else [k for k in typing.get_args(kind) if k is not type(None)]
            name = " or ".join(k.__name__ for k in parts) + ("" if isinstance(kind, type) or len(parts) == len(
                typing.get_args(kind)) else " (optional)")
            rule = f.metadata.get("rule", "")
            if rule == "models":
                rule = "in:none," + ",".join(MODEL_NAMES)
            doc = f.metadata.get("doc", "") + (f" ({rule.replace('in:', 'one of: ').replace(',', ', ')})"
                                               if rule.startswith("in:") else f" ({rule})" if rule else "")
            lines.append(f"| `{f.name}` | {name} | {default(f)} | {doc.strip()} |")
        lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    (ROOT / "docs" / "scene.md").write_text(page())
    print(ROOT / "docs" / "scene.md")
