import numpy as np

from plugins.convection.nusselt import Correlation


def nusselt(re, pr, alpha):
    """Ranz, W.E. & Marshall, W.R. (1952), Evaporation from drops, Chem. Eng. Prog. 48(3),
    141-146 and 48(4), 173-180, eq. (11) of part I:

        Nu = 2 + 0.6 Re^(1/2) Pr^(1/3)

    A single sphere in an unbounded stream: ``alpha`` is not used (Re is still formed with
    it by the caller, so at alpha = 1 it is the slip Reynolds number). Nu -> 2 (pure
    conduction into still gas) as Re -> 0. Their drops covered 0 <= Re <= 200 and
    Pr (Sc) 0.6-2.7; the commonly quoted range of use is Re < 200 and Pr < 250."""
    return 2.0 + 0.6 * np.sqrt(re) * np.cbrt(pr) + 0.0 * np.asarray(alpha)


MODEL = Correlation("ranz_marshall", nusselt, dict(re=(0.0, 200.0), pr=(0.6, 250.0), alpha=(0.0, 1.0)),
                          "Ranz & Marshall, Chem. Eng. Prog. 48 (1952) 141-146, eq. 11")
