"""pab-opto pgII gonio-photometer ASCII files (the *Mountain* software; format ``pab-pgii``).

Layout (pab-opto's "data format" page and the ``pabopto2bsdf`` manual of Radiance): one
file per incident direction; header lines start with ``#`` and all precede the data::

    #sample_name "name"
    #format: theta phi DSF          or BSDF / BRDF / BTDF
    #incident_angle 82.5 180        or #intheta 82.5 and #inphi 180
    #upphi 0                        (optional)
    #colorimetry: CIE-Y             or CIE-XYZ (then three values per line)
    84.968  125.790  0.009744       theta phi value, TAB or blank separated
    ...

Geometry. Incident and scattered directions share one spherical frame: theta from the
sample's front normal, phi counter-clockwise as seen from the front. The incident angles
name the direction towards the source, so the dataset's ``phi_r`` (source at 0) is
``phi - inphi`` (mod 360), and ``theta_i`` is ``intheta``. A scattered theta above 90 is on
the back side: a transmission point, with ``theta_r = 180 - theta`` from the back normal
(the reflection frame mirrored in the sample plane, as for BTDF ``.bsdf`` files).

Units. ``BSDF``/``BRDF``/``BTDF`` values are the BSDF [sr-1]; ``DSF`` values include the
cosine of the scattered angle (the manual: the two "differ only in their inclusion of a
cosine factor"), so the BSDF is ``DSF / |cos theta|``; DSF points at grazing exit
(``|cos theta| < 1e-6``) have no finite BSDF and are left out (``meta["dropped_points"]``).
Values are photometric (``CIE-Y``) or CIE XYZ triplets (``channel`` X/Y/Z); the file states
no wavelength, so 555 nm is written as a label with ``meta["wavelength_stated"]`` False, as
for photometric ``.bsdf`` files.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..dataset import Measurement
from ._base import AdapterError, Format, decode, parse_number, read_bytes, split_lines
from ._frame import build_frame
from ._numblock import parse_rows
from ._truncation import check_last_row

__all__ = ["FORMATS", "read_pab_mountain"]

INSTRUMENT = "pab-pgii"
#: the wavelength label of photometric data [nm] (the file states none)
DEFAULT_WAVELENGTH_NM = 555.0
_FORMATS = {"DSF": "dsf", "BSDF": "bsdf", "BRDF": "brdf", "BTDF": "btdf"}
_COLORIMETRY = {"CIE-Y": 1, "CIE-XYZ": 3}
_KEY = re.compile(r"#\s*([A-Za-z_]+)\s*:?\s*(.*)")
_SNIFF_FORMAT = re.compile(rb"^#\s*format\s*:\s*theta\s+phi\s+(DSF|BSDF|BRDF|BTDF)\b", re.M)
_SNIFF_ANGLE = re.compile(rb"^#\s*(incident_angle|intheta)\s", re.M)


def _header(path: str | os.PathLike[str], lines: list[str]) -> tuple[dict[str, Any], int]:
    """The ``#`` entries (key -> (value, line)) and the index of the first data line.

    A key given twice keeps its first value (the manual: the reader ignores what it does
    not know; it does not say which of two values wins).
    """
    head: dict[str, Any] = {}
    for i, raw in enumerate(lines):
        s = raw.strip()
        if s and not s.startswith("#"):
            return head, i
        m = _KEY.match(s)
        if m:
            head.setdefault(m.group(1).lower(), (m.group(2).strip(), i + 1))
    return head, len(lines)


def _angles(path: str | os.PathLike[str], head: dict[str, Any]) -> tuple[float, float]:
    """``(intheta, inphi)`` [deg] from ``#incident_angle`` or ``#intheta``/``#inphi``."""
    if "incident_angle" in head:
        text, ln = head["incident_angle"]
        parts = text.split()
        if len(parts) != 2:
            raise AdapterError(path, "#incident_angle: expected theta and phi [deg]", ln)
        return (
            parse_number(parts[0], path, ln, "#incident_angle theta"),
            parse_number(parts[1], path, ln, "#incident_angle phi"),
        )
    if "intheta" not in head:
        raise AdapterError(
            path, "missing the incident angle: '#incident_angle T P' or '#intheta T'"
        )
    theta = parse_number(head["intheta"][0], path, head["intheta"][1], "#intheta")
    phi = 0.0
    if "inphi" in head:
        phi = parse_number(head["inphi"][0], path, head["inphi"][1], "#inphi")
    return theta, phi


def _kind(path: str | os.PathLike[str], head: dict[str, Any]) -> tuple[str, int]:
    """The value kind (``dsf``, ``bsdf``, ``brdf``, ``btdf``) and the values per line."""
    if "format" not in head:
        raise AdapterError(path, "missing '#format: theta phi DSF|BSDF|BRDF|BTDF'")
    text, ln = head["format"]
    words = text.split()
    if (
        len(words) != 3
        or [w.lower() for w in words[:2]] != ["theta", "phi"]
        or (words[2].upper() not in _FORMATS)
    ):
        raise AdapterError(
            path, f"#format: expected 'theta phi DSF|BSDF|BRDF|BTDF', found {text!r}", ln
        )
    color, cln = head.get("colorimetry", ("CIE-Y", None))
    if color.upper() not in _COLORIMETRY:
        raise AdapterError(
            path, f"#colorimetry: expected one of {list(_COLORIMETRY)}, found {color!r}", cln
        )
    return _FORMATS[words[2].upper()], _COLORIMETRY[color.upper()]


def _quantity(path: str | os.PathLike[str], kind: str, back: np.ndarray, ln: int) -> str:
    if back.all():
        q = "btdf"
    elif not back.any():
        q = "brdf"
    else:
        raise AdapterError(
            path,
            "the data mix front (theta < 90) and back (theta > 90) directions: expected "
            "reflection or transmission in one file",
            ln,
        )
    if kind in ("brdf", "btdf") and kind != q:
        raise AdapterError(
            path, f"#format states {kind.upper()} but the directions are {q.upper()}'s", ln
        )
    return q


def read_pab_mountain(path: str | os.PathLike[str]) -> Measurement:
    """Read a pgII gonio-photometer ASCII file (one incident direction) as BRDF or BTDF.

    Returns
    -------
    Measurement
        Quantity ``brdf`` or ``btdf`` [sr-1] (DSF divided by ``|cos theta|``),
        ``theta_i_deg`` = ``#intheta``, ``theta_r_deg`` from the normal of the side the
        light leaves, ``phi_r_deg`` = phi - inphi (source at 0); ``channel`` X/Y/Z for
        CIE-XYZ files. ``meta`` holds the header entries, ``value_kind`` and
        ``dropped_points`` (DSF points at grazing exit).

    Raises
    ------
    AdapterError
        A missing ``#format`` or incident angle, an unknown format or colorimetry, a data
        line with the wrong number of fields or a non-number (its line named), angles out
        of range, front and back directions mixed, no data, or an unterminated last line
        cut inside its number (a shorter one is warned about,
        ``labbrdf.adapters._truncation.check_last_field``).
    """
    text, _ = decode(read_bytes(path), path)
    lines = split_lines(text)
    head, first = _header(path, lines)
    kind, nval = _kind(path, head)
    intheta, inphi = _angles(path, head)
    ln = (head.get("incident_angle") or head["intheta"])[1]
    if not 0.0 <= intheta < 90.0:
        raise AdapterError(
            path, f"incident theta {intheta:g} deg: expected front incidence in [0, 90)", ln
        )
    rows = [(i + 1, s.strip()) for i, s in enumerate(lines[first:], first) if s.strip()]
    if not rows:
        raise AdapterError(path, "no data lines after the header: expected 'theta phi value'")
    bad = next(((n, s) for n, s in rows if s.startswith("#")), None)
    if bad is not None:
        raise AdapterError(path, "expected every '#' header line before the data", bad[0])
    nums = [n for n, _ in rows]
    check_last_row(path, text, lines, nums, None)  # a file cut inside its last number
    data = parse_rows(path, [s for _, s in rows], nums, 2 + nval)
    theta, phi, vals = data[:, 0], data[:, 1], data[:, 2:]
    out = np.flatnonzero((theta < 0) | (theta > 180) | (phi < -360) | (phi > 720))
    if out.size:
        raise AdapterError(
            path, "expected theta in [0, 180] and phi in [-360, 720] deg", nums[int(out[0])]
        )
    quantity = _quantity(path, kind, theta > 90.0, nums[0])
    cos = np.abs(np.cos(np.radians(theta)))
    keep = np.ones(theta.size, dtype=bool)
    if kind == "dsf":
        keep = cos >= 1e-6
        vals = vals[keep] / cos[keep, None]
    else:
        vals = vals[keep]
    theta_r = np.where(theta > 90.0, 180.0 - theta, theta)[keep]
    phi_r = np.mod(phi[keep] - inphi, 360.0)
    frame = _frame(path, quantity, vals, intheta, theta_r, phi_r)
    meta: dict[str, Any] = {
        "format": INSTRUMENT,
        "header": {k: v for k, (v, _) in head.items()},
        "value_kind": kind,
        "incident_deg": [intheta, inphi],
        "dropped_points": int((~keep).sum() * nval),
        "wavelength_stated": False,
        "wavelength_nm": DEFAULT_WAVELENGTH_NM,
    }
    try:
        return Measurement(frame, meta)
    except ValueError as exc:
        raise AdapterError(path, f"invalid data: {exc}") from None


def _frame(
    path: str | os.PathLike[str],
    quantity: str,
    vals: np.ndarray,
    intheta: float,
    theta_r: np.ndarray,
    phi_r: np.ndarray,
) -> pd.DataFrame:
    n, nval = vals.shape
    optional: dict[str, Any] = {}
    if nval == 3:
        codes = np.tile(np.arange(3, dtype=np.int8), n)
        optional["channel"] = pd.Categorical.from_codes(codes, categories=["X", "Y", "Z"])
    return build_frame(
        sample=Path(path).stem,
        instrument=INSTRUMENT,
        source=os.path.basename(os.fspath(path)),
        quantity=quantity,
        value=vals.reshape(-1),
        unit="sr-1",
        wavelength_nm=DEFAULT_WAVELENGTH_NM,
        theta_i_deg=intheta,
        theta_r_deg=np.repeat(theta_r, nval),
        phi_r_deg=np.repeat(phi_r, nval),
        **optional,
    )


def _sniff(head: bytes) -> bool:
    try:
        return bool(_SNIFF_FORMAT.search(head)) and bool(_SNIFF_ANGLE.search(head))
    except Exception:  # pragma: no cover - a sniffer never raises
        return False


FORMATS = (
    Format(
        "pab-pgii",
        "pab-opto pgII gonio-photometer ASCII (Mountain): theta phi BSDF/DSF per incident "
        "direction",
        (),
        _sniff,
        read_pab_mountain,
        ("brdf", "btdf"),
        keywords=(b"#incident_angle", b"#intheta"),
    ),
)
