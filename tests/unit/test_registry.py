"""One registry API for every kind of model (plugins.registry): heat models, comparison
models, drag laws and Nusselt correlations; a new model is one file."""
import sys

import pytest

from plugins.conduction import CONTACT, GAP
from plugins.convection import CORRELATIONS
from plugins.drag import LAWS
from plugins.heat import MODEL_NAMES, MODELS
from plugins.heat.comparison import COMPARISON
from plugins.registry import Registry


def test_a_new_file_is_a_new_entry_and_helpers_are_not(tmp_path, monkeypatch):
    package = tmp_path / "laws"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "zeta.py").write_text("MODEL = 'z'\n")
    (package / "alpha.py").write_text("MODEL = 'a'\n")
    (package / "_shared.py").write_text("raise AssertionError('a helper is not an entry')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    import laws
    try:
        r = Registry("laws", laws.__path__, "test law")
        assert list(r) == ["alpha", "zeta"] and r["zeta"] == "z" and len(r) == 2 and "alpha" in r
        with pytest.raises(ValueError, match="unknown test law 'beta'; choices: alpha, zeta"):
            r.lookup("beta")
        with pytest.raises(KeyError):
            r["beta"]
    finally:
        sys.modules.pop("laws", None)
        sys.modules.pop("laws.alpha", None)
        sys.modules.pop("laws.zeta", None)


def test_every_kind_of_model_uses_the_one_registry():
    for registry, some in ((MODELS, {"A", "B", "C"}), (COMPARISON, {"hertz", "softened", "zhou"}),
                           (LAWS, {"gidaspow", "ergun", "wenyu"}), (CORRELATIONS, {"gunn", "ranz_marshall"}),
                           (CONTACT, {"mfix", "morris", "lethe"}), (GAP, {"rong_horio", "lethe"})):
        assert isinstance(registry, Registry) and some <= set(registry)
    assert MODEL_NAMES == tuple(MODELS) + tuple(COMPARISON)
