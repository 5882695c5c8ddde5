"""Every reader of the project takes files as spreadsheets write them (one text reader,
network.core.read_text/read_table): a UTF-8 byte-order mark with CRLF line ends, quoted
headers, spaces after the separators, UTF-16 with its mark; bytes that are not UTF-8 (Latin-1)
are refused naming the option, the file, the row and the encoding; a folder or a missing file
names the option. Commands exit 2 with one line and leave the input as it was."""

import hashlib

import numpy as np
import pytest

from cache import lookup as cache_lookup
from cache._csvio import read_throat_csv
from dem.templates import read_template
from network.core import read_packing, read_table, read_text
from network.report import main as report_main
from network.report.system import read_fan

FAN = [["airflow_m3_s", "static_pressure_pa"], ["0", "2000"], ["1.5", "1500"], ["3", "400"]]
BED = [["x", "y", "z", "r"]] + [[f"{i * 0.01}", f"{(i % 3) * 0.01}", f"{(i % 2) * 0.01}",
                                  "0.004"] for i in range(8)]
TEMPLATE = [["x", "y", "z", "r"], ["-1", "0", "0", "1.2"], ["1", "0", "0", "1.2"]]
THROATS = [["r1", "r2", "r3", "l12", "l13", "l23"], ["1", "1", "1", "2.5", "2.5", "2.5"],
           ["1", "1.2", "0.9", "2.4", "2.3", "2.6"]]


def _sheet(rows, style):
    """The text of ``rows`` as a spreadsheet program saves it, as bytes."""
    if style == "plain":
        return "\n".join(",".join(r) for r in rows).encode() + b"\n"
    if style == "excel utf-8":            # BOM, CRLF, header quoted
        head = ",".join(f'"{h}"' for h in rows[0])
        return ("\ufeff" + "\r\n".join([head] + [",".join(r) for r in rows[1:]])
                + "\r\n").encode("utf-8")
    if style == "spaces":                 # a space after every separator
        return "\n".join(", ".join(r) for r in rows).encode() + b"\n"
    if style == "semicolons quoted":
        return "\n".join(";".join(f'"{c}"' for c in r) for r in rows).encode() + b"\n"
    if style == "utf-16":                 # 'Unicode text': UTF-16 LE with its mark, tabs
        return ("\r\n".join("\t".join(r) for r in rows) + "\r\n").encode("utf-16")
    raise AssertionError(style)


STYLES = ["plain", "excel utf-8", "spaces", "semicolons quoted", "utf-16"]


@pytest.mark.parametrize("style", STYLES)
def test_every_reader_reads_what_spreadsheets_write(tmp_path, style):
    fan = tmp_path / "fan.csv"
    fan.write_bytes(_sheet(FAN, style))
    q, p = read_fan(fan)
    assert q.tolist() == [0.0, 1.5, 3.0] and p.tolist() == [2000.0, 1500.0, 400.0]
    bed = tmp_path / "bed.csv"
    bed.write_bytes(_sheet(BED, style))
    pk = read_packing(bed)
    assert pk.n == 8 and np.allclose(pk.radii, 0.004) and pk.centers[3, 0] == pytest.approx(0.03)
    tpl = tmp_path / "kernel.csv"
    tpl.write_bytes(_sheet(TEMPLATE, style))
    t = read_template(tpl, units="mm")
    assert t.n == 2 and t.radii.max() == pytest.approx(1.2e-3)
    thr = tmp_path / "throats.csv"
    thr.write_bytes(_sheet(THROATS, style))
    header, rows, radii, sides = read_throat_csv(thr)
    assert header == THROATS[0] and np.array_equal(sides[0], [2.5, 2.5, 2.5])
    assert np.array_equal(radii[1], [1.0, 1.2, 0.9])


def test_latin1_is_refused_naming_option_file_row_and_encoding(tmp_path):
    f = tmp_path / "fan.csv"
    f.write_bytes("airflow_m3_s,static_pressure_pa\n# 20 \u00b0C\n0,500\n".encode("latin-1"))
    with pytest.raises(ValueError) as e:
        read_text(f, "--fan")
    msg = str(e.value)
    assert msg.startswith(f"--fan {f}: row 2: byte 0xb0 is not UTF-8") and "Latin-1" in msg
    with pytest.raises(ValueError, match="Latin-1"):
        read_fan(f)


def test_a_folder_or_a_missing_file_names_the_option(tmp_path):
    with pytest.raises(IsADirectoryError, match=f"--fan {tmp_path}: is a folder"):
        read_fan(tmp_path)
    with pytest.raises(FileNotFoundError, match="--fan: No such file or directory: "):
        read_fan(tmp_path / "none.csv")
    with pytest.raises(FileNotFoundError, match="--grain: No such file"):
        read_template(tmp_path / "none.csv")
    with pytest.raises(ValueError, match="empty file"):
        (tmp_path / "e.csv").write_text("\n# only a comment\n")
        read_table(tmp_path / "e.csv", "--csv")


def _digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.parametrize("content, words", [
    ("folder", "--fan {}: is a folder"),
    ("latin-1", "is not UTF-8 (Latin-1"),
    ("swapped header", "missing column(s) airflow_m3_s, static_pressure_pa"),
])
def test_report_refuses_a_bad_fan_file_before_any_work(tmp_path, capsys, content, words):
    fan = tmp_path / "fan"
    if content == "folder":
        fan.mkdir()
    else:
        fan = tmp_path / "fan.csv"
        fan.write_bytes("airflow_m3_s,static_pressure_pa\n0,500 \u00b0\n".encode("latin-1")
                        if content == "latin-1" else b"a,b\n0,500\n1,100\n")
        before = _digest(fan)
    rc = report_main(["--grain", "wheat", "--diameter", "6", "--fan", str(fan), "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and err[0].startswith("error: ")
    assert words.format(fan) in err[0]
    if content != "folder":
        assert _digest(fan) == before


def test_cache_lookup_reads_a_utf16_throat_list(tmp_path, capsys):
    src = tmp_path / "throats.csv"
    src.write_bytes(_sheet(THROATS, "utf-16"))
    before = _digest(src)
    out = tmp_path / "q.csv"
    assert cache_lookup.main(["--csv", str(src), "--out", str(out), "--policy", "shape-factor",
                              "--quiet"]) == 0
    header, rows, _, _ = read_throat_csv(out)
    assert "qstar" in header and len(rows) == 2 and _digest(src) == before
    (tmp_path / "bad.csv").write_bytes("r1,r2,r3,l12,l13,l23\n1,1,1,2,2,2 \u00e9\n"
                                       .encode("latin-1"))
    rc = cache_lookup.main(["--csv", str(tmp_path / "bad.csv"), "--out", str(out),
                            "--policy", "shape-factor", "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and f"--csv {tmp_path / 'bad.csv'}: row 2: byte 0xe9 is not UTF-8" in err


@pytest.mark.parametrize("style", STYLES)
def test_network_bin_profiles_read_what_spreadsheets_write(tmp_path, style):
    from network.bin._material import read_profile

    f = tmp_path / "profile.csv"
    f.write_bytes(_sheet([["depth_m", "porosity"], ["0", "0.42"], ["2", "0.39"]], style))
    x, y = read_profile(f)
    assert x.tolist() == [0.0, 2.0] and y.tolist() == [0.42, 0.39]
