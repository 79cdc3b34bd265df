"""The fits' defaults that the command line needs before any fit: light, no imports.

The command-line parsers show these (``--method``, ``--seed``) without importing the
fitting core (nlopt, scipy, pandas); :mod:`labbrdf.fitting.core` re-exports them.
"""

from __future__ import annotations

__all__ = ["MAX_SEED", "METHOD"]

#: the default optimiser of every fit (film, batch, report, CLI): the global controlled
#: random search CRS2 with local mutation, then BOBYQA from its best point
METHOD = "GN_CRS2_LM+LN_BOBYQA"

#: the largest seed of a fit: nlopt's ``srand`` takes an unsigned long, 32 bits on some
#: platforms, so seeds are integers in [0, MAX_SEED] everywhere
MAX_SEED = 2**32 - 1
