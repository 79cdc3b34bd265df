"""The report's building blocks: the Builder, checks, tables, formatting and atomic output.

A report is built into one JSON-safe ``results`` dict (written as ``results.json``) and a
dict of embedded figures. Every table cell on the page is rendered from ``results`` with
:func:`fmt` and carries a ``data-key`` (a JSON pointer into ``results.json``) and a
``data-fmt`` (the format spec), so that every number on the page can be traced back.

Check statuses: ``pass``, ``fail`` and ``skipped``. Only ``fail`` makes the exit code
non-zero; a section whose inputs or modules are missing renders "not available: <reason>"
and its checks are ``skipped``, never ``pass``.
"""

from __future__ import annotations

import csv
import datetime as _dt
import io
import json
import math
import os
import re
import sys
import time
import traceback
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from .. import progress
from ..jsonsafe import jsonable

__all__ = [
    "STATUSES",
    "Builder",
    "Unavailable",
    "atomic_dir",
    "esc_pointer",
    "fmt",
    "headline",
    "jsonable",
    "not_applicable",
    "num",
    "resolve",
    "slug",
    "tables_csv",
    "tally",
    "wl_label",
    "write_report",
]

#: the three check outcomes
STATUSES = ("pass", "fail", "skipped")
#: a file the page links (``Builder.file``): a plain name, no folder
_FILE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,120}")


class Unavailable(Exception):
    """A section cannot be computed (a module, a file or an optional input is missing)."""


# --------------------------------------------------------------------------- values


def fmt(value: Any, spec: str = "") -> str:
    """The one formatting function for every value shown on the page.

    Parameters
    ----------
    value : Any
        A number, a string, a bool or None (shown as an em dash).
    spec : str
        A Python format spec for numbers (``".4g"``, ``".3f"``); ``"%"`` multiplies a
        fraction by 100 and shows 2 decimals; empty means ``".6g"`` for floats.

    Returns
    -------
    str
    """
    if value is None:
        return "\u2014"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)) and not spec:
        return str(int(value))
    if isinstance(value, (int, float, np.integer, np.floating)):
        v = float(value)
        if not math.isfinite(v):
            return "\u2014"
        if spec == "%":
            return f"{100.0 * v:.2f}"
        if spec.endswith("d"):
            return format(int(round(v)), spec) if v == round(v) else format(v, ".6g")
        return format(v, spec or ".6g")
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(fmt(v, spec) for v in value) + "]"
    return str(value)


def resolve(results: Mapping[str, Any], pointer: str) -> Any:
    """The value at a JSON pointer (``/tables/fits/rows/0/k1``) in ``results``."""
    node: Any = results
    for part in pointer.lstrip("/").split("/"):
        part = part.replace("~1", "/").replace("~0", "~")
        node = node[int(part)] if isinstance(node, list) else node[part]
    return node


def esc_pointer(s: str) -> str:
    """``s`` escaped as one reference token of a JSON pointer (RFC 6901)."""
    return str(s).replace("~", "~0").replace("/", "~1")


def num(x: Any) -> float | None:
    """``x`` as a finite float, or None (not a number, NaN or infinite)."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def slug(s: str) -> str:
    """``s`` as an id fragment: alphanumerics kept, the rest ``_``, at most 40 characters."""
    return "".join(c if c.isalnum() else "_" for c in s)[:40] or "sample"


def wl_label(x: float, *, stated: bool = True) -> str:
    """A wavelength for text: ``"550 nm"``, or "wavelength not stated".

    ``stated=False``: ``x`` is only a label (a file that states no wavelength,
    ``meta["wavelength_stated"]`` False).
    """
    return f"{x:g} nm" if stated else "wavelength not stated"


# --------------------------------------------------------------------------- builder


class Builder:
    """Collects sections, tables, figures and checks into ``results``.

    Parameters
    ----------
    title : str
        Page title.
    progress : bool
        Print one line per step on stderr.
    """

    def __init__(self, title: str, *, progress: bool = False, meta: Mapping | None = None):
        self.results: dict[str, Any] = {
            "title": title,
            "meta": {
                "created_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
                **dict(meta or {}),
            },
            "sections": [],
            "tables": {},
            "figures": {},
            "checks": [],
            "summary": {},
        }
        self.images: dict[str, str] = {}
        self.swatches: dict[str, str] = {}
        #: files written beside the page (``designer/<name>``): name -> content
        self.files: dict[str, bytes] = {}
        self.progress = progress
        self._t0 = time.perf_counter()
        self._current: dict[str, Any] | None = None

    # ---- progress
    def log(self, msg: str) -> None:
        """One progress line on stderr (when enabled)."""
        if self.progress:
            dt = time.perf_counter() - self._t0
            progress.clear()  # a fit's updating line, if one is drawn
            sys.stderr.write(f"[labbrdf report {dt:6.1f} s] {msg}\n")
            sys.stderr.flush()

    # ---- sections
    @contextmanager
    def section(self, sid: str, title: str) -> Iterator[dict[str, Any]]:
        """Open a section; exceptions inside it are recorded, not raised.

        :class:`Unavailable` (and ImportError of a labbrdf module) mark the section "not
        available" and its checks skipped; any other exception becomes a failed check
        naming the error, so that a bug shows on the page and in the exit code.
        """
        sec: dict[str, Any] = {
            "id": sid,
            "title": title,
            "status": "ok",
            "reason": None,
            "text": [],
            "items": [],
        }
        self.results["sections"].append(sec)
        self._current = sec
        self.log(f"section {sid}: {title}")
        try:
            yield sec
        except Unavailable as exc:
            self._unavailable(sec, str(exc))
        except ImportError as exc:
            self._unavailable(sec, f"module missing ({exc})")
        except Exception as exc:  # noqa: BLE001 - shown on the page, fails the run
            tb = traceback.format_exception_only(type(exc), exc)[-1].strip()
            sec["status"] = "error"
            sec["reason"] = tb
            self.check(
                f"{sid}.completed",
                f"section '{title}' ran to the end",
                "fail",
                against="no exception",
                reason=tb,
            )
        finally:
            self._current = None

    def _unavailable(self, sec: dict[str, Any], reason: str) -> None:
        sec["status"] = "not available"
        sec["reason"] = reason
        self._current = sec
        self.check(
            f"{sec['id']}.available",
            f"section '{sec['title']}' computed",
            "skipped",
            against="its inputs and modules",
            reason=f"not available: {reason}",
        )

    def _sec(self) -> dict[str, Any]:
        if self._current is None:
            raise RuntimeError("no open section")
        return self._current

    def text(self, paragraph: str) -> None:
        """A paragraph of plain text (escaped on the page)."""
        self._sec()["items"].append({"kind": "text", "text": paragraph})

    def heading(self, text: str, anchor: str = "") -> None:
        """A subsection heading inside the current section (``anchor``: its HTML id)."""
        self._sec()["items"].append({"kind": "heading", "text": text, "anchor": anchor})

    def note(self, label: str, body: str) -> None:
        """A labelled line, e.g. a "not available" part inside a section that runs."""
        self._sec()["items"].append({"kind": "note", "label": label, "text": body})

    def table(
        self,
        tid: str,
        title: str,
        columns: Sequence[tuple[str, str, str]],
        rows: Sequence[Mapping[str, Any]],
        caption: str = "",
        *,
        details: bool = False,
    ) -> None:
        """Add a table (``details``: folded into a details element on the page).

        Parameters
        ----------
        tid : str
            Unique id (also the CSV file name, ``tables/<tid>.csv``).
        columns : sequence of (key, label, fmt)
            Row key, column header (with units) and the :func:`fmt` spec.
        rows : sequence of mappings
        """
        if tid in self.results["tables"]:
            raise ValueError(f"duplicate table id {tid!r}")
        self.results["tables"][tid] = {
            "title": title,
            "caption": caption,
            "columns": [{"key": k, "label": lab, "fmt": f} for k, lab, f in columns],
            "rows": [jsonable({k: r.get(k) for k, _, _ in columns}) for r in rows],
        }
        self._sec()["items"].append({"kind": "table", "id": tid, "details": details})

    def figure(
        self, fid: str, title: str, caption: str, uri: str | None, *, details: bool = False
    ) -> None:
        """Add an embedded figure (``uri`` is a ``data:image/png;base64,`` URI).

        ``details`` folds it into a details element (closed; its title is the summary).
        """
        if fid in self.results["figures"]:
            raise ValueError(f"duplicate figure id {fid!r}")
        if not uri:
            raise ValueError(f"figure {fid!r} has no image")
        self.results["figures"][fid] = {"title": title, "caption": caption}
        self.images[fid] = uri
        self._sec()["items"].append({"kind": "figure", "id": fid, "details": details})

    def file(self, name: str, label: str, content: bytes) -> None:
        """A file written beside the page as ``designer/<name>`` and linked from it.

        ``content`` is written with the page (:func:`write_report`, inside the report's
        atomic folder).
        """
        if not _FILE_NAME.fullmatch(name) or name in self.files:
            raise ValueError(f"file name {name!r}: expected a new plain file name")
        self.files[name] = bytes(content)
        self._sec()["items"].append({"kind": "file", "name": name, "text": label})

    def swatch(self, sid: str, hex_colour: str) -> None:
        """A colour swatch (hex ``#rrggbb`` computed by the report, never from a file)."""
        if not (len(hex_colour) == 7 and hex_colour[0] == "#"):
            raise ValueError(f"bad colour {hex_colour!r}")
        int(hex_colour[1:], 16)
        self.swatches[sid] = hex_colour
        self._sec()["items"].append({"kind": "swatch", "id": sid, "hex": hex_colour})

    def check(
        self,
        cid: str,
        name: str,
        status: str | bool,
        *,
        against: str = "",
        value: Any = None,
        tolerance: Any = None,
        justification: str = "",
        reason: str = "",
        substantive: bool = True,
    ) -> dict[str, Any]:
        """Record a check: ``status`` is True/False or one of :data:`STATUSES`.

        ``substantive=False`` marks a bookkeeping check (e.g. "every file was read") that
        counts for the exit code but not as a result in the page's headline.
        """
        if isinstance(status, (bool, np.bool_)):
            status = "pass" if status else "fail"
        if status not in STATUSES:
            raise ValueError(f"check status must be one of {STATUSES}, got {status!r}")
        sec = self._current["id"] if self._current is not None else "extra"
        c = jsonable(
            {
                "id": cid,
                "section": sec,
                "name": name,
                "status": status,
                "against": against,
                "value": value,
                "tolerance": tolerance,
                "justification": justification,
                "reason": reason,
                "substantive": bool(substantive),
            }
        )
        self.results["checks"].append(c)
        if self._current is not None:
            self._current["items"].append(
                {"kind": "check", "index": len(self.results["checks"]) - 1}
            )
        self.log(f"  check {cid}: {status.upper()}" + (f" ({reason})" if reason else ""))
        return c

    def skip(self, cid: str, name: str, reason: str, *, against: str = "") -> None:
        """A check that could not run."""
        self.check(cid, name, "skipped", against=against, reason=reason)

    # ---- finish
    def finish(self) -> int:
        """Fill the summary; return the exit code (1 if any check failed).

        ``summary`` is :func:`tally` of the checks plus ``exit_code`` and ``headline``
        (made from that same tally); ``not_applicable`` lists the sections that did not
        apply (:func:`not_applicable`), which the page shows once, together.
        """
        counts = tally(self.results["checks"])
        code = 1 if counts["fail"] else 0
        self.results["summary"] = {
            **counts,
            "exit_code": code,
            "headline": headline(counts),
        }
        self.results["not_applicable"] = not_applicable(self.results)
        self.results["meta"]["elapsed_s"] = round(time.perf_counter() - self._t0, 3)
        return code


def tally(checks: Sequence[Mapping[str, Any]]) -> dict[str, int]:
    """The one count of a report's checks, used by its summary, headline and page.

    Parameters
    ----------
    checks : sequence of mappings
        ``results["checks"]`` (``status`` and, optionally, ``substantive``).

    Returns
    -------
    dict
        ``pass``, ``fail``, ``skipped`` (one per check), ``total``, and ``bookkeeping``:
        the passes that are bookkeeping (``substantive=False``, e.g. "every file was
        read"), included in ``pass``.
    """
    counts = {s: 0 for s in STATUSES}
    for c in checks:
        counts[c["status"]] += 1
    return {
        **counts,
        "total": len(checks),
        "bookkeeping": sum(
            c["status"] == "pass" and not c.get("substantive", True) for c in checks
        ),
    }


def headline(counts: Mapping[str, int] | Sequence[Mapping[str, Any]]) -> str:
    """The page's one-line verdict: what was checked, never "pass" when nothing was.

    Parameters
    ----------
    counts : mapping or sequence of mappings
        A :func:`tally`, or the checks to tally.

    Returns
    -------
    str
        ``"4 checks passed (2 of them bookkeeping), 1 failed, 6 not applicable"``, every
        number that of the tally; ``"nothing checked beyond bookkeeping (...)"`` when only
        bookkeeping checks passed and none failed.
    """
    t = counts if isinstance(counts, Mapping) else tally(counts)
    passed, book, failed, na = t["pass"], t["bookkeeping"], t["fail"], t["skipped"]
    plural = "check" if passed == 1 else "checks"
    book_text = f" ({book} of them bookkeeping)" if book else ""
    if passed - book + failed == 0:
        return (
            f"nothing checked beyond bookkeeping ({passed} bookkeeping {plural}, "
            f"{na} not applicable)"
        )
    return f"{passed} {plural} passed{book_text}, {failed} failed, {na} not applicable"


def not_applicable(results: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The sections that did not apply.

    A section did not apply when it is not available and holds nothing but text and
    skipped checks.

    Returns
    -------
    list of dict
        ``{"section", "title", "reason", "checks"}`` per such section (``checks``: indices
        into ``results["checks"]``), in page order. The page lists them once, with their
        reasons, instead of a section and a check table each.
    """
    out = []
    for sec in results["sections"]:
        if sec["status"] != "not available":
            continue
        idx = [it["index"] for it in sec["items"] if it["kind"] == "check"]
        shown = [it for it in sec["items"] if it["kind"] not in ("check", "text", "heading")]
        if shown or any(results["checks"][i]["status"] != "skipped" for i in idx):
            continue
        out.append(
            {"section": sec["id"], "title": sec["title"], "reason": sec["reason"], "checks": idx}
        )
    return out


# --------------------------------------------------------------------------- output


def _cell(v: Any) -> Any:
    """A CSV cell; text a spreadsheet would run as a formula gets a leading ``'``."""
    from ..outputs import csv_safe_cell

    if v is None:
        return ""
    return csv_safe_cell(json.dumps(v) if isinstance(v, (list, dict)) else v)


def tables_csv(results: Mapping[str, Any]) -> dict[str, str]:
    """Every table of ``results`` as CSV text (full precision), by table id."""
    out: dict[str, str] = {}
    for tid, t in results["tables"].items():
        buf = io.StringIO()
        keys = [c["key"] for c in t["columns"]]
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(keys)
        for r in t["rows"]:
            w.writerow([_cell(r.get(k)) for k in keys])
        out[tid] = buf.getvalue()
    checks = io.StringIO()
    keys = [
        "id",
        "section",
        "name",
        "status",
        "value",
        "tolerance",
        "against",
        "justification",
        "reason",
    ]
    w = csv.writer(checks, lineterminator="\n")
    w.writerow(keys)
    for c in results["checks"]:
        w.writerow([_cell(c.get(k)) for k in keys])
    out["checks"] = checks.getvalue()
    return out


def atomic_dir(
    out: str | os.PathLike[str],
    write: Callable[[Path], None],
    *,
    inputs: Sequence[str | os.PathLike[str]] = (),
) -> Path:
    """Build a report folder with ``write(tmp)`` and move it into place at ``out``.

    See :func:`labbrdf.outputs.replace_dir`: ``out`` must be new, empty or an earlier
    labbrdf report holding only our files, and may not hold an input; otherwise
    :class:`~labbrdf.outputs.OutputError` and nothing is touched. If ``write`` raises, the
    temporary folder is removed and an existing ``out`` is left untouched.
    """
    from ..outputs import replace_dir

    return replace_dir(out, write, inputs=inputs)


def write_report(
    out: str | os.PathLike[str],
    results: Mapping[str, Any],
    html_text: str,
    *,
    inputs: Sequence[str | os.PathLike[str]] = (),
    files: Mapping[str, bytes] | None = None,
) -> Path:
    """Write ``index.html``, ``results.json`` and ``tables/*.csv`` atomically into ``out``.

    ``files`` (:attr:`Builder.files`) are written into ``designer/``. Refused when ``out``
    holds anything but an earlier report, or one of ``inputs``.
    """
    payload = json.dumps(jsonable(results), indent=1, allow_nan=False)
    csvs = tables_csv(results)

    def _write(d: Path) -> None:
        (d / "index.html").write_text(html_text, encoding="utf-8")
        (d / "results.json").write_text(payload, encoding="utf-8")
        (d / "tables").mkdir()
        for tid, text in csvs.items():
            (d / "tables" / f"{tid}.csv").write_text(text, encoding="utf-8")
        if files:
            (d / "designer").mkdir()
            for name, content in files.items():
                (d / "designer" / name).write_bytes(content)

    return atomic_dir(out, _write, inputs=inputs)
