"""docs/scene.md is the generated reference of every scene key: it must match the code."""
import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_scene_reference_is_current():
    spec = importlib.util.spec_from_file_location("scene_doc", ROOT / "tools" / "scene_doc.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert (ROOT / "docs" / "scene.md").read_text() == module.page(), \
        "docs/scene.md is out of date: run .venv/bin/python tools/scene_doc.py"
