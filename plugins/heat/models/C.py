from plugins.heat.models import Model

MODEL = Model(
    name="C",
    compression="Stronge",
    recovery="Johnson",
    description="Model A's compression with model B's recovery (eqs. 34-38)",
)
