"""Write scatmech_rr_stack.csv: SCATMECH's roughness-stack Mueller BRDFs (reference).

Run with pySCATMECH installed in a separate environment (it is not a dependency of
labbrdf): ``python make_scatmech_rr_stack.py`` writes ``scatmech_rr_stack.csv`` beside
this file.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
from pySCATMECH.brdf import BRDF_Model

WAVELENGTH_UM = 0.633
#: SCATMECH's ABC PSD, A / (1 + (B f)^2)^(C/2), A [um^4], B [um], f [1/um]
PSD = {None: "ABC_PSD_Function", "A": 0.01, "B": 20.0, "C": 2.5}
#: name: substrate (n, k), films bottom (next to the substrate) first as ((n, k), um)
STACKS = {
    "si-sio2-tio2": ((3.88, 0.02), (((1.46, 0.0), 0.1), ((2.3, 0.01), 0.05))),
    "al-sio2": ((1.55, 7.71), (((1.46, 0.0), 0.12),)),
}
#: (model, extra parameters, label)
MODELS = (
    ("Correlated_Roughness_Stack_BRDF_Model", {}, "correlated"),
    ("Uncorrelated_Roughness_Stack_BRDF_Model", {}, "uncorrelated"),
    ("Roughness_Stack_BRDF_Model", {"this_layer": 0}, "interface-substrate"),
    ("Roughness_Stack_BRDF_Model", {"this_layer": 1}, "interface-1"),
    ("Roughness_Stack_BRDF_Model", {"this_layer": 2}, "interface-2"),
)
THETA_I = (0.0, 30.0, 60.0)
THETA_S = (10.0, 45.0, 80.0)
PHI_S = (0.0, 90.0, 150.0, 180.0)


def _stack_model(films):
    if len(films) == 1:
        (((n, k), d),) = films
        return {None: "SingleFilm_StackModel", "material": complex(n, k), "thickness": d}
    ((n1, k1), d1), ((n2, k2), d2) = films
    return {
        None: "DoubleFilm_StackModel",
        "material1": complex(n1, k1),
        "thickness1": d1,
        "material2": complex(n2, k2),
        "thickness2": d2,
    }


def _films_text(films) -> str:
    return " ".join(f"{n}+{k}i:{d}" for (n, k), d in films)


def main() -> None:
    out = Path(__file__).with_name("scatmech_rr_stack.csv")
    head = ["stack", "model", "n_sub", "k_sub", "films_bottom_first_n+ki:um", "wavelength_um"]
    head += ["A_um4", "B_um", "C", "theta_i_deg", "theta_s_deg", "phi_s_deg"]
    head += [f"M{i}{j}" for i in range(4) for j in range(4)]
    with out.open("w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(head)
        for name, ((ns, ks), films) in STACKS.items():
            for model, extra, label in MODELS:
                if extra.get("this_layer", 0) > len(films):
                    continue
                m = BRDF_Model(
                    model,
                    wavelength=WAVELENGTH_UM,
                    substrate=complex(ns, ks),
                    psd=PSD,
                    stack=_stack_model(films),
                    **extra,
                )
                for ti in THETA_I:
                    for ts in THETA_S:
                        for ps in PHI_S:
                            mm = np.array(
                                m.MuellerBRDF(
                                    math.radians(ti), math.radians(ts), math.radians(ps), 0, "psps"
                                )
                            )
                            row = [name, label, ns, ks, _films_text(films), WAVELENGTH_UM]
                            row += [PSD["A"], PSD["B"], PSD["C"], ti, ts, ps]
                            w.writerow(row + [f"{v:.17g}" for v in mm.reshape(16)])


if __name__ == "__main__":
    main()
