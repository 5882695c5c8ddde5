"""cache.precompute, cache.lookup and throats.solve as a new user: bad input exits
2 with one ``error:`` line naming the row, value or file, and nothing is written."""

import csv

import pytest

from cache import lookup as lookup_cli, precompute as precompute_cli
from throats import solve as solve_cli

GOOD = "r1,r2,r3,l12,l13,l23\n1,1,1,2.2,2.2,2.2\n"


@pytest.fixture()
def files(tmp_path):
    (tmp_path / "good.csv").write_text(GOOD)
    (tmp_path / "text.csv").write_text(GOOD + "1,1,1,abc,2.2,2.2\n")
    (tmp_path / "flat.csv").write_text(GOOD + "1,1,1,2.2,2.2,2.2\n1,1,1,1,2,3\n")
    (tmp_path / "nan.csv").write_text(GOOD + "1,nan,1,2.2,2.2,2.2\n")
    (tmp_path / "empty.csv").write_text("")
    (tmp_path / "header.csv").write_text("r1,r2,r3,l12,l13,l23\n")
    (tmp_path / "cols.csv").write_text("r1,r2,r3,l12,l13\n1,1,1,2,2\n")
    (tmp_path / "junk.sqlite").write_bytes(b"not a database at all" * 10)
    return tmp_path


PRECOMPUTE = [
    (["--csv", "text.csv"], "text.csv row 3: cannot parse l12='abc'"),
    (["--csv", "flat.csv"], "flat.csv row 4: sides [1.0, 2.0, 3.0] do not form a triangle"),
    (["--csv", "nan.csv"], "nan.csv row 3: non-finite value"),
    (["--csv", "empty.csv"], "empty file"),
    (["--csv", "header.csv"], "no throat rows"),
    (["--csv", "cols.csv"], "missing column(s) ['l23']"),
    (["--csv", "missing.csv"], "No such file or directory: missing.csv"),
    (["--csv", "good.csv", "--rtol", "0"], "--rtol must be in (0, 1), got 0.0"),
    (["--csv", "good.csv", "--workers", "0"], "--workers and --batch-size must be >= 1"),
    (["--csv", "good.csv", "--max-hours", "-1"], "--max-hours must be > 0"),
    (["--csv", "good.csv", "--export", "g.npz"], "--export needs --grid"),
    (["--grid", "tiny", "--orbits"], "--orbits needs --export"),
    (["--csv", "good.csv", "--rtol", "x"], "invalid float value: 'x'"),
]


@pytest.mark.parametrize("argv, text", PRECOMPUTE)
def test_precompute_bad_input_exit_2_nothing_written(files, monkeypatch, capsys, argv, text):
    monkeypatch.chdir(files)
    try:
        rc = precompute_cli.main(["--db", "t.sqlite", "--quiet", *argv])
    except SystemExit as exc:      # argparse's own errors, one line too
        rc = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and err[0].startswith("error: ") and text in err[0], err
    assert not (files / "t.sqlite").exists()


@pytest.mark.parametrize("db, text", [("nofolder/t.sqlite", "folder"), (".", "is a folder"),
                                      ("junk.sqlite", "not an SQLite database")])
def test_precompute_bad_db_exit_2(files, monkeypatch, capsys, db, text):
    monkeypatch.chdir(files)
    assert precompute_cli.main(["--db", db, "--csv", "good.csv", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and text in err[0], err
    assert (files / "junk.sqlite").read_bytes().startswith(b"not a database")


LOOKUP = [
    (["--csv", "good.csv", "--out", "nofolder/o.csv"], "folder"),
    (["--csv", "good.csv", "--out", "o.csv", "--rtol", "-1"], "--rtol must be in (0, 1)"),
    (["--csv", "good.csv", "--out", "o.csv", "--workers", "0"], "--workers must be >= 1"),
    (["--csv", "good.csv", "--out", "o.csv", "--db", "junk.sqlite"], "not an SQLite database"),
    (["--csv", "cols.csv", "--out", "o.csv"], "missing column(s)"),
    (["--csv", "missing.csv", "--out", "o.csv"], "missing.csv"),
    (["--csv", "good.csv", "--out", "o.csv", "--policy", "table"], "invalid choice: 'table'"),
    (["--csv", "good.csv", "--out", "o.csv", "--grid", "G1"],       # was served by the estimate
     "--grid G1: no such grid; the grids are tiny, g2, g1, x1, d1"),
]


@pytest.mark.parametrize("argv, text", LOOKUP)
def test_lookup_bad_input_exit_2_nothing_written(files, monkeypatch, capsys, argv, text):
    monkeypatch.chdir(files)
    try:
        rc = lookup_cli.main(["--quiet", *([] if "--db" in argv else ["--db", "t.sqlite"]),
                              *argv])
    except SystemExit as exc:
        rc = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and err[0].startswith("error: ") and text in err[0], err
    assert not (files / "o.csv").exists() and not (files / "t.sqlite").exists()


def test_lookup_bad_rows_spreadsheet_numbers_exit_1(files, monkeypatch, capsys):
    monkeypatch.chdir(files)
    rc = lookup_cli.main(["--csv", "flat.csv", "--out", "o.csv", "--policy", "shape-factor",
                          "--quiet", "--db", "t.sqlite"])
    err = capsys.readouterr().err
    assert rc == 1 and err.startswith("error: flat.csv row 4: sides [1.0, 2.0, 3.0]")
    rows = list(csv.DictReader(open(files / "o.csv")))
    assert [r["source"] for r in rows] == ["shape-factor", "shape-factor", "failed"]


@pytest.mark.parametrize("argv, text", [
    (["--csv", "good.csv", "--out", "nofolder/o.csv"], "folder"),
    (["--csv", "good.csv", "--out", "."], "is a folder"),
    (["--csv", "cols.csv", "--out", "o.csv"], "missing columns"),
    (["--csv", "good.csv"], "--csv needs --out"),
    (["--radii", "1", "1", "1"], "--radii needs --sides"),
    (["--radii", "1", "1", "1", "--sides", "2", "2", "2", "--rtol", "2"], "--rtol must be in"),
])
def test_throats_solve_bad_input_exit_2(files, monkeypatch, capsys, argv, text):
    monkeypatch.chdir(files)
    try:
        rc = solve_cli.main(argv)
    except SystemExit as exc:
        rc = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and err[0].startswith("error: ") and text in err[0], err
    assert not (files / "o.csv").exists()


@pytest.mark.parametrize("main", [precompute_cli.main, lookup_cli.main, solve_cli.main])
def test_help_gives_every_option_a_text_and_its_default(main, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    parser = {precompute_cli.main: precompute_cli.build_parser,
              lookup_cli.main: lookup_cli.build_parser,
              solve_cli.main: solve_cli._parser}[main]()
    for action in parser._actions:
        if action.option_strings and action.dest != "help":
            assert action.help and action.option_strings[0] in text, action.dest
            if action.default not in (None, False):
                assert "default" in action.help, action.dest
