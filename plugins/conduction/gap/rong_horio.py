import numpy as np

from plugins.conduction.gap import GapModel
from plugins.conduction.pair import circle_radius


def half_lens(lens_radius, s, overlap, r):
    """Conductance per unit k_g r of a sphere of radius r [m] to a plane through the gas of
    a lens (-): MFiX's EVAL_H_PFP (model/des/des_thermo_cond_mod.f, lines 438-487), the
    integral of 2 pi rho d rho / h(rho) over the sphere's face out to the lens, h the gap
    between sphere and plane, never below s. In units of r: L = lens_radius/r, Kn = s/r,
    o = overlap/r (the sphere's overlap with the plane, negative apart),

        R_out = min(sqrt(L^2 - (1 - o)^2), 1)  (0 where -o >= L - 1),
        o >= 0:  pi ((1-o)^2 - (1-o-Kn)^2)/Kn + 2 pi (sqrt(1 - R_out^2) - (1-o-Kn))
                 + 2 pi (1-o) ln((1 - o - sqrt(1 - R_out^2))/Kn),
        o < 0:   2 pi [R_kn^2/(2 Kn) + sqrt(1 - R_out^2) - sqrt(1 - R_kn^2)
                 + (1-o) ln((1 - o - sqrt(1 - R_out^2))/(1 - o - sqrt(1 - R_kn^2)))],
                 R_kn = sqrt(1 - (1 - o - Kn)^2) (0 where -o >= Kn).

    MFiX stops on o > 2 (an overlap beyond a diameter); here o is clipped at 2."""
    L, kn, o = (np.asarray(a, float) / r for a in (lens_radius, s, overlap))
    o = np.minimum(o, 2.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        r_out = np.where(-o >= L - 1.0, 0.0, np.sqrt(np.clip(L**2 - (1.0 - o) ** 2, 0.0, None)))
        r_out = np.minimum(r_out, 1.0)
        top = np.sqrt(1.0 - r_out**2)
        touching = (np.pi * ((1 - o) ** 2 - (1 - o - kn) ** 2) / kn + 2 * np.pi * (top - (1 - o - kn))
                    + 2 * np.pi * (1 - o) * np.log((1 - o - top) / kn))
        r_kn = np.where(-o >= kn, 0.0, np.sqrt(np.clip(1.0 - (1 - o - kn) ** 2, 0.0, None)))
        apart = 2 * np.pi * (r_kn**2 / (2 * kn) + top - np.sqrt(1 - r_kn**2)
                             + (1 - o) * np.log((1 - o - top) / (1 - o - np.sqrt(1 - r_kn**2))))
    return np.where(o >= 0, touching, apart)


def conductance(pair, gas):
    """H = H_1 H_2 / (H_1 + H_2) [W/K]: MFiX's particle-fluid-particle conduction (Rong &
    Horio 1999 as modified in MFiX), model/des/des_thermo_cond_mod.f lines 154-193. The gas
    lens around the larger particle has radius R_max (1 + lens) (line 154); the pair conducts
    while the gap is below lens R_max (line 158). Each particle conducts through the gas to
    the plane between them, H_1 = k_g R_min h(RLENS_1, S_1, OLAP_1, R_min) and H_2 = k_g R_max
    h(RLENS_2, S_2, OLAP_2, R_max) (``half_lens``, lines 185-186), in series (line 190), with
    (lines 159-171; d the centre distance, delta = R_max + R_min - d, s_min = gas.min_distance)

        RD_OUT = the radius where the lens meets the smaller sphere (``circle_radius``),
        OLAP_1 = R_max^2 (x - x^2/2)/d, x = delta/R_max;   OLAP_2 = delta - OLAP_1,
        S_1 = R_max^2 (y - y^2/2)/(d - s_min) - OLAP_1, y = (delta + s_min)/R_max;  S_2 = s_min - S_1,
        RLENS_1 = (RD_OUT^2 + (R_min - OLAP_1)^2)^(1/2),  RLENS_2 = (RD_OUT^2 + (R_max - OLAP_2)^2)^(1/2).

    Where the smaller sphere lies wholly inside the lens, MFiX's RADIUS returns -1, a length
    (1 cm or 1 m by its units) whose square exceeds every radius squared: both faces then
    conduct whole (R_out capped at 1 in ``half_lens``). RD_OUT = R_max gives the same here,
    whatever the units. Rong, D., Horio,
    M., "DEM simulation of char combustion in a fluidized bed", 2nd Int. Conf. on CFD in the
    Minerals and Process Industries, Melbourne (1999) 65-70; Musser, PhD thesis, WVU (2011).

    Valid for a stagnant gas (conduction only: no convection or radiation in the gap), gaps
    above the gas' mean free path (continuum; s_min bounds the gap), and a gas much less
    conducting than the solid (isothermal particle surfaces). It conducts in contact too, in
    parallel with the contact model's path."""
    R_max, R_min = np.maximum(pair.r_i, pair.r_j), np.minimum(pair.r_i, pair.r_j)
    d = np.asarray(pair.distance, float)
    delta = R_max + R_min - d
    s = gas.min_distance
    near = delta > -R_max * gas.lens
    rd_out = circle_radius(R_max * (1.0 + gas.lens), R_min, d)
    rd_out = np.where(rd_out < 0, R_max, rd_out)
    x = delta / R_max
    olap_1 = R_max**2 * (x - 0.5 * x**2) / d
    olap_2 = delta - olap_1
    y = (delta + s) / R_max
    s_1 = R_max**2 * (y - 0.5 * y**2) / (d - s) - olap_1
    s_2 = s - s_1
    lens_1 = np.sqrt(rd_out**2 + (R_min - olap_1) ** 2)
    lens_2 = np.sqrt(rd_out**2 + (R_max - olap_2) ** 2)
    H_1 = half_lens(lens_1, s_1, olap_1, R_min) * R_min * gas.conductivity
    H_2 = half_lens(lens_2, s_2, olap_2, R_max) * R_max * gas.conductivity
    with np.errstate(invalid="ignore", divide="ignore"):
        H = np.where((H_1 > 0) & (H_2 > 0), H_1 * H_2 / (H_1 + H_2), 0.0)
    return np.where(near, H, 0.0)


def reach(r_max, gas):
    """The largest gap [m] at which it conducts: lens r_max (MFiX line 158)."""
    return gas.lens * r_max


MODEL = GapModel("rong_horio", conductance, reach,
                 "MFiX des_thermo_cond_mod.f lines 154-193, 438-487 (Rong & Horio 1999, modified)")
