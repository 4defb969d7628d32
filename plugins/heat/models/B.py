from plugins.heat.models import Model

MODEL = Model(
    name="B",
    compression="Johnson",
    recovery="Johnson",
    description="Johnson (1985): fully plastic compression from first touch (eqs. 12-15), "
                "Hertz recovery from the maximum force (eqs. 24-30)",
)
