import pytest

from plugins.heat import Pair


@pytest.fixture
def paper_pair():
    """The paper's parameter set (sec. 6), particle-particle."""
    return Pair()
