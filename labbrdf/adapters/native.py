"""labbrdf's own dataset files (written by ``labbrdf ingest -o`` or :func:`labbrdf.dataset.write`).

Parquet files carry the metas in their key-value metadata; CSV files start with a
``# labbrdf-meta: {...}`` line. Reading them through :func:`labbrdf.read` lets every command
take instrument exports and saved datasets alike.
"""

from __future__ import annotations

import os

from ..dataset import DatasetError, Measurement, read_csv, read_parquet
from ._base import AdapterError, Format, check_regular_file


def _sniff_parquet(head: bytes) -> bool:
    return head[:4] == b"PAR1"


def _sniff_csv(head: bytes) -> bool:
    return head.startswith(b"# labbrdf-meta: ")


def read_dataset_parquet(path: str | os.PathLike[str]) -> Measurement:
    """Read a labbrdf Parquet dataset."""
    check_regular_file(path)
    try:
        return read_parquet(path)
    except DatasetError as exc:
        raise AdapterError(path, str(exc).removeprefix(f"{path}: ")) from None


def read_dataset_csv(path: str | os.PathLike[str]) -> Measurement:
    """Read a labbrdf CSV dataset (first line ``# labbrdf-meta: ...``)."""
    check_regular_file(path)
    with open(path, "rb") as fh:
        if not _sniff_csv(fh.read(64)):
            raise AdapterError(path, "expected '# labbrdf-meta: {...}' (a labbrdf dataset CSV)", 1)
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
        "labbrdf dataset (CSV with a '# labbrdf-meta:' first line)",
        (".csv",),
        _sniff_csv,
        read_dataset_csv,
        keywords=(b"labbrdf-meta",),
    ),
)
