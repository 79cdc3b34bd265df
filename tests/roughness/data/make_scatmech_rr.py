"""Write scatmech_rr.csv: SCATMECH's Microroughness_BRDF_Model Mueller BRDFs (reference).

Run with pySCATMECH installed in a separate environment (it is not a dependency of
labbrdf): ``python make_scatmech_rr.py`` writes ``scatmech_rr.csv`` beside this file.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
from pySCATMECH.brdf import BRDF_Model

WAVELENGTH_UM = 0.633
#: SCATMECH's ABC PSD, A / (1 + (B f)^2)^(C/2), A [um^4], B [um], f [1/um]
A_UM4, B_UM, C = 0.01, 20.0, 2.5
MATERIALS = {"aluminium": (1.55, 7.71), "glass": (1.5, 0.0), "silicon": (3.88, 0.02)}
THETA_I = (0.0, 30.0, 60.0)
THETA_S = (0.0, 10.0, 45.0, 80.0)
PHI_S = (0.0, 30.0, 90.0, 150.0, 180.0, 270.0)


def main() -> None:
    out = Path(__file__).with_name("scatmech_rr.csv")
    head = ["material", "n", "k", "wavelength_um", "A_um4", "B_um", "C"]
    head += ["theta_i_deg", "theta_s_deg", "phi_s_deg"]
    head += [f"M{i}{j}" for i in range(4) for j in range(4)]
    with out.open("w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(head)
        for name, (n, k) in MATERIALS.items():
            m = BRDF_Model(
                "Microroughness_BRDF_Model",
                wavelength=WAVELENGTH_UM,
                substrate=complex(n, k),
                psd={None: "ABC_PSD_Function", "A": A_UM4, "B": B_UM, "C": C},
            )
            for ti in THETA_I:
                for ts in THETA_S:
                    for ps in PHI_S:
                        mm = np.array(
                            m.MuellerBRDF(
                                math.radians(ti), math.radians(ts), math.radians(ps), 0, "psps"
                            )
                        )
                        row = [name, n, k, WAVELENGTH_UM, A_UM4, B_UM, C, ti, ts, ps]
                        w.writerow(row + [f"{v:.17g}" for v in mm.reshape(16)])


if __name__ == "__main__":
    main()
