"""Text files as spreadsheets and other programs write them: the one reader of every CSV the
project takes (packings, fan curves, grain templates, throat lists, profiles).

:func:`read_text` decodes UTF-8 with or without a byte-order mark and UTF-16 with one, and
refuses other bytes with a message naming the option, the file and the row of the first byte
that is not UTF-8 (Latin-1 or Windows-1252 text: save it as UTF-8). :func:`read_table` splits
it into a header and rows: comma, semicolon, tab or spaces, quoted fields, spaces after the
separators, CRLF line ends, blank lines and ``#`` comment lines skipped, rows numbered as a
spreadsheet numbers them (the header is row 1 when it is the file's first line).
"""

from __future__ import annotations

import csv
from pathlib import Path

__all__ = ["read_text", "read_table", "split_fields", "delimiter_of"]

#: byte-order marks read, with their codec
_BOMS = ((b"\xef\xbb\xbf", "utf-8"), (b"\xff\xfe", "utf-16-le"), (b"\xfe\xff", "utf-16-be"))


def _where(path, option) -> str:
    return f"{option} {path}" if option else str(path)


def read_text(path, option: str | None = None, *, what: str = "a text file") -> str:
    """The text of ``path``, decoded; ValueError (or FileNotFoundError / IsADirectoryError)
    naming ``option`` and the file.

    UTF-8 (a byte-order mark dropped) and UTF-16 with a byte-order mark are read; a file with
    NUL bytes and no UTF-16 mark is binary (``what`` says what was expected); any other byte
    that is not UTF-8 is refused with its row.

    >>> import tempfile, os
    >>> p = os.path.join(tempfile.mkdtemp(), "fan.csv")
    >>> _ = open(p, "wb").write("\\ufeffa,b\\r\\n1,2\\r\\n".encode("utf-16"))
    >>> read_text(p, "--fan").splitlines()
    ['a,b', '1,2']
    """
    p = Path(path)
    where = _where(path, option)
    if p.is_dir():
        raise IsADirectoryError(f"{where}: is a folder, give a file")
    if not p.is_file():
        raise FileNotFoundError(f"{option + ': ' if option else ''}No such file or directory: "
                                f"{path}")
    raw = p.read_bytes()
    for bom, codec in _BOMS:
        if raw.startswith(bom):
            try:
                return raw[len(bom):].decode(codec).lstrip("\ufeff")
            except UnicodeDecodeError as e:
                raise ValueError(f"{where}: not readable {codec.upper()} text ({e.reason} at "
                                 f"byte {e.start + len(bom)})") from None
    if b"\0" in raw[:65536]:
        raise ValueError(f"{where}: a binary file, not {what} (UTF-16 text needs its "
                         "byte-order mark)")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        row = raw[:e.start].count(b"\n") + 1
        raise ValueError(f"{where}: row {row}: byte 0x{raw[e.start]:02x} is not UTF-8 (Latin-1 "
                         "or Windows-1252 text?): save the file as UTF-8 (a spreadsheet's "
                         "'CSV UTF-8')") from None


def delimiter_of(line: str):
    """The separator of a header line: ',', ';' or a tab when it holds one, else None (runs
    of spaces)."""
    for d in (",", ";", "\t"):
        if d in line:
            return d
    return None


def split_fields(line: str, delim) -> list[str]:
    """The fields of one line, each stripped of spaces and of the quotes a spreadsheet puts
    around a field (``"x", "y"`` -> ``['x', 'y']``); ``delim`` None splits at spaces."""
    if delim is None:
        return [f.strip('"\'') for f in line.split()]
    if '"' not in line:
        return [f.strip() for f in line.split(delim)]
    return [f.strip() for f in next(csv.reader([line], delimiter=delim, skipinitialspace=True))]


def read_table(path, option: str | None = None, *, what: str = "a table"):
    """(header, rows) of a delimited text file: the header's fields (stripped, unquoted) and
    ``[(row, fields), ...]`` for each data line, ``row`` counted as a spreadsheet counts it;
    blank and ``#`` lines skipped. ValueError naming ``option`` and the file when there is no
    header."""
    lines = read_text(path, option, what=what).splitlines()
    body = [(i, ln) for i, ln in enumerate(lines, 1)
            if ln.strip() and not ln.lstrip().startswith("#")]
    if not body:
        raise ValueError(f"{_where(path, option)}: empty file (no header)")
    delim = delimiter_of(body[0][1])
    header = split_fields(body[0][1], delim)
    return header, [(i, split_fields(ln, delim)) for i, ln in body[1:]]
