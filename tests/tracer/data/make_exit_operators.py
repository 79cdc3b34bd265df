"""Write the exit operators of the version-3 build (see README.md in this folder).

Usage: ``python make_exit_operators.py CHECKOUT OUT.npz`` (CHECKOUT: the repository whose
``labbrdf`` builds them).
"""

import sys

import numpy as np

sys.path.insert(0, sys.argv[1])
from labbrdf.tracer.binning import Grid  # noqa: E402
from labbrdf.tracer.operator import build_exit_operator  # noqa: E402

CASES = [(30.0, 45.0, 0.2), (30.0, 40.0, 0.2), (30.0, 40.0, 0.03)]
KINDS = [
    ("separable", "transmission"),
    ("correlated", "transmission"),
    ("incident", "transmission"),
    ("incident", "reflection"),
    ("incident", "reflection_away"),
]
out = {}
for ts, ps, a in CASES:
    for m, k in KINDS:
        op = build_exit_operator(Grid(ts, ps), 1.5, a, nodes=(2, 2), masking=m, kind=k)
        out[f"{ts:g}_{ps:g}_{a:g}_{m}_{k}"] = op.spectrum
np.savez_compressed(sys.argv[2], **out)
