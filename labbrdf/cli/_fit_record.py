"""One fitted group of a ``labbrdf fit --json`` file, as ``export --from-fit`` reads it."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from ._options import UsageError

__all__ = ["fit_record"]

#: a fit JSON larger than this is refused before it is parsed [bytes]
MAX_FIT_RECORDS_BYTES = 64 * 2**20


def _pick(records: list[Any], path: Path, wavelength: float | None) -> dict[str, Any]:
    """The one record of ``records`` (at ``wavelength`` [nm] where there are several)."""
    fitted = [r for r in records if isinstance(r, dict) and r.get("params")]
    if wavelength is not None and len(fitted) > 1:
        fitted = [
            r
            for r in fitted
            if math.isclose(float((r.get("group") or {}).get("wavelength_nm", math.nan)),
                            wavelength, abs_tol=1e-6)
        ]  # fmt: skip
    if len(fitted) == 1:
        return fitted[0]
    groups = "; ".join(json.dumps(r.get("group")) for r in records if isinstance(r, dict))
    if not fitted:
        raise UsageError(
            f"--from-fit {path}: no fitted group"
            + (f" at --wavelength {wavelength:g}" if wavelength is not None else "")
            + f" (groups: {groups or 'none'})"
        )
    raise UsageError(
        f"--from-fit {path}: {len(fitted)} fitted groups ({groups}); choose one with "
        "--wavelength NM"
    )


def fit_record(path: str | Path, wavelength: float | None) -> dict[str, Any]:
    """``model``, ``options``, parameter ``values`` and ``wavelength_nm`` of one fitted group.

    Parameters
    ----------
    path : path-like
        What ``labbrdf fit --json`` printed (a list of records with ``model``,
        ``options``, ``group``, ``params``), or one such record.
    wavelength : float, optional
        The group's wavelength [nm], needed where the file holds several fitted groups;
        where the fit's data stated none (``wavelength_stated`` false: a ``.bsdf`` whose
        555 nm is a label), the wavelength to record instead.

    Raises
    ------
    UsageError
        The file cannot be read, is not such a list, or holds no (or several) fitted
        groups at ``wavelength``; the message names the file and the groups.
    """
    from ..outputs import InputFileError, read_input_file

    p = Path(path)
    try:
        raw = read_input_file(p, max_bytes=MAX_FIT_RECORDS_BYTES, what="fit JSON")
        doc = json.loads(raw.decode("utf-8"))
    except (InputFileError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise UsageError(f"--from-fit {p}: not a fit JSON ({exc})") from None
    rec = _pick(doc if isinstance(doc, list) else [doc], p, wavelength)
    if not isinstance(rec.get("model"), str) or not isinstance(rec.get("params"), dict):
        raise UsageError(
            f"--from-fit {p}: expected what `labbrdf fit --json` prints (records with "
            "'model', 'options', 'group' and 'params')"
        )
    try:
        values = {k: float(v["value"]) for k, v in rec["params"].items()}
    except (TypeError, KeyError, ValueError):
        raise UsageError(
            f"--from-fit {p}: params: expected {{name: {{'value': number}}}}"
        ) from None
    wl = (rec.get("group") or {}).get("wavelength_nm")
    wl = float(wl) if isinstance(wl, (int, float)) else None
    if rec.get("wavelength_stated") is False:  # the data's wavelength was a label
        wl = wavelength
    elif wavelength is not None and wl is not None and not math.isclose(wl, wavelength):
        raise UsageError(
            f"--from-fit {p}: the fit is at {wl:g} nm, not --wavelength {wavelength:g}"
        )
    return {
        "model": rec["model"],
        "options": dict(rec.get("options") or {}),
        "values": values,
        "wavelength_nm": wl,
    }
