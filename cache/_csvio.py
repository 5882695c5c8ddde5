"""CSV input/output of throat shapes (columns ``r1,r2,r3,l12,l13,l23``)."""

from __future__ import annotations

import csv
import os

import numpy as np

from network.core import read_table

__all__: list[str] = []

SHAPE_COLUMNS = ("r1", "r2", "r3", "l12", "l13", "l23")


def read_throat_csv(path, parse_errors=None, option="--csv"):
    """Read a throat CSV: ``(header list, rows list of lists, radii (N,3), sides (N,3))``.

    Read as spreadsheets write it (:func:`network.core.read_table`: BOM, CRLF, UTF-16 with a
    mark, quoted fields, spaces after the commas); errors name ``option`` and the file. Cells
    that do not parse as numbers become NaN (the row is then reported as invalid); with a dict
    ``parse_errors``, row index -> "cannot parse l12='abc'" (or, for a row too short to hold a
    shape column, "the row has 5 of 6 values") is filled in.
    """
    try:
        header, table = read_table(path, option, what="a throat list")
    except ValueError as e:
        if "empty file" not in str(e):
            raise
        raise ValueError(f"{option} {path}: empty file, expected a header "
                         f"{','.join(SHAPE_COLUMNS)}") from None
    missing = [c for c in SHAPE_COLUMNS if c not in header]
    if missing:
        raise ValueError(f"{option} {path}: missing column(s) {missing}; header is {header}")
    rows = [fields for _, fields in table]
    cols = [header.index(c) for c in SHAPE_COLUMNS]
    vals = np.full((len(rows), 6), np.nan)
    for j, c in enumerate(cols):
        for i, row in enumerate(rows):
            try:
                vals[i, j] = float(row[c])
            except (ValueError, IndexError):
                if parse_errors is not None and i not in parse_errors:
                    parse_errors[i] = (f"cannot parse {SHAPE_COLUMNS[j]}={row[c]!r}"
                                       if c < len(row) else
                                       f"the row has {len(row)} of {len(header)} values")
    return header, rows, vals[:, :3], vals[:, 3:]


def row_problems(path, ok, messages, parse_errors):
    """``"PATH row N: message"`` for each bad row, N counted as a spreadsheet (header = 1)."""
    return [f"{path} row {i + 2}: {parse_errors.get(i, messages[i])}"
            for i in np.flatnonzero(~np.asarray(ok, bool))]


def write_csv(path, header, rows, extra):
    """Write ``rows`` (lists of str) with extra columns ``extra`` (dict name -> (N,) array)."""
    names = list(extra)
    tmp = f"{path}.part"
    with open(tmp, "w", newline="") as fh:   # complete file or none: renamed when written
        w = csv.writer(fh)
        w.writerow(list(header) + names)
        for i, row in enumerate(rows):
            w.writerow(list(row) + [_fmt(extra[k][i]) for k in names])
    os.replace(tmp, path)


def _fmt(v):
    if isinstance(v, (float, np.floating)):
        return "" if not np.isfinite(v) else repr(float(v))
    return str(v)
