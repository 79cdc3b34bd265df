"""The exchange files labbrdf writes, one module per program that reads them.

* :mod:`~labbrdf.writers.zemax`: Zemax OpticStudio / Radiant ``.bsdf`` tables of a model, a
  fit or a trace;
* :mod:`~labbrdf.writers.speos`: Ansys Speos ``.anisotropicbsdf`` (text);
* :mod:`~labbrdf.writers.astm`: ASTM E1392-style BRDF tables;
* :mod:`~labbrdf.writers.pgii`: pab-opto pgII gonio-photometer ASCII;
* :mod:`~labbrdf.writers.fred`: the FRED script that defines a fitted ABg or Harvey-Shack
  scatter model.

Each writes through :mod:`labbrdf.outputs` (never over an input or a file it did not
create) and is read back by its reader in :mod:`labbrdf.adapters` in the tests.
"""
