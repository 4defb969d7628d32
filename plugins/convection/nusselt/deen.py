from plugins.convection.nusselt import Correlation
from plugins.convection.nusselt.gunn import gunn_form


def nusselt(re, pr, alpha):
    """Deen, N.G., Peters, E.A.J.F., Padding, J.T. & Kuipers, J.A.M. (2014), Review of direct
    numerical simulation of fluid-particle mass, momentum and heat transfer in dense gas-solid
    flows, Chem. Eng. Sci. 116, 710-724 (as CFDEMcoupling's ``NuDeen``, LaEuScalarTemp.H):

        Nu = (7 - 10 a + 5 a^2)(1 + 0.17 Re^0.2 Pr^(1/3)) + (1.33 - 2.31 a + 1.16 a^2) Re^0.7 Pr^(1/3)

    Gunn's form (``gunn``) with its coefficients refitted to particle-resolved simulations of
    random arrays; a = ``alpha``, Re on the superficial slip velocity. At a = 1 and Re -> 0 it is
    the single sphere's 2. CFDEMcoupling notes the fit for 0 <= Re <= 100; the ranges of
    alpha and Pr below are Gunn's, whose form it keeps."""
    return gunn_form(re, pr, alpha, (7.0, -10.0, 5.0, 0.17, 1.33, -2.31, 1.16))


MODEL = Correlation("deen", nusselt, dict(re=(0.0, 100.0), pr=(0.6, 1e3), alpha=(0.35, 1.0)),
                    "Deen et al., Chem. Eng. Sci. 116 (2014) 710-724")
