"""labbrdf's own dataset files (written by ``labbrdf ingest -o`` or :func:`labbrdf.dataset.write`).

Parquet files carry the metas in their key-value metadata; CSV files keep them in a
sidecar ``<stem>.meta.json`` (older ones in a first line ``# labbrdf-meta: {...}``).
Reading them through :func:`labbrdf.read` lets every command
take instrument exports and saved datasets alike.
"""

from __future__ import annotations

import os

from ..dataset import COLUMNS, DatasetError, Measurement, read_csv, read_parquet
from ._base import AdapterError, Format, check_regular_file


def _sniff_parquet(head: bytes) -> bool:
    return head[:4] == b"PAR1"


_CSV_HEADER = ",".join(COLUMNS).encode()


def _sniff_csv(head: bytes) -> bool:
    """The meta comment line of older files, or the schema's column names in order."""
    if head.startswith(b"# labbrdf-meta: "):
        return True
    first = head.split(b"\n", 1)[0].rstrip(b"\r")
    return first == _CSV_HEADER or first.startswith(_CSV_HEADER + b",")


def read_dataset_parquet(path: str | os.PathLike[str]) -> Measurement:
    """Read a labbrdf Parquet dataset."""
    check_regular_file(path)
    try:
        return read_parquet(path)
    except DatasetError as exc:
        raise AdapterError(path, str(exc).removeprefix(f"{path}: ")) from None


def read_dataset_csv(path: str | os.PathLike[str]) -> Measurement:
    """Read a labbrdf CSV dataset (meta from ``<stem>.meta.json`` or a first comment line)."""
    check_regular_file(path)
    with open(path, "rb") as fh:
        if not _sniff_csv(fh.read(4096)):
            raise AdapterError(
                path,
                "expected the column names of a labbrdf dataset CSV "
                f"({_CSV_HEADER.decode()},...) or a '# labbrdf-meta: {{...}}' line",
                1,
            )
    try:
        return read_csv(path)
    except (DatasetError, UnicodeDecodeError) as exc:
        raise AdapterError(path, str(exc).removeprefix(f"{path}: ")) from None


FORMATS = (
    Format(
        "labbrdf-parquet",
        "labbrdf dataset (Parquet, metas in the file metadata)",
        (".parquet",),
        _sniff_parquet,
        read_dataset_parquet,
    ),
    Format(
        "labbrdf-dataset-csv",
        "labbrdf dataset (CSV with a <stem>.meta.json sidecar, or a '# labbrdf-meta:' line)",
        (".csv",),
        _sniff_csv,
        read_dataset_csv,
        keywords=(b"labbrdf-meta", b"sample,instrument,source,quantity"),
    ),
)
