from plugins.heat.models import Model

MODEL = Model(
    name="A",
    compression="Stronge",
    recovery="Stronge",
    description="Stronge (2000): elastic, elastic-plastic and fully plastic compression "
                "(eqs. 4-11), recovery by geometric similarity (eqs. 16-23)",
)
