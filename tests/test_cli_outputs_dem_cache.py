"""Output paths and option values of throats.solve, cache.lookup and dem.pack/vibrate are
checked before any work (audit items): a folder that takes no file (``/proc``, where
``os.access`` says yes to root), an existing folder given as the file, a missing folder, an
infinite or oversized container, a negative seed. Each is exit 2 with one ``error:`` line
naming the option and value, nothing computed and nothing written (no ``.part``/``.tmp``)."""

import os

import numpy as np
import pytest

import cache.lookup as lookup_cli
import dem.pack as pack_cli
import dem.vibrate as vibrate_cli
import throats.solve as solve_cli
from dem import Container, write_packing
from dem._clump_pack import write_grain_packing
from dem._fill import MAX_SPHERES

GOOD = "r1,r2,r3,l12,l13,l23\n1,1,1,2.2,2.2,2.2\n"
needs_proc = pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux /proc")


def _run(main, argv):
    try:
        return main(argv)
    except SystemExit as exc:          # argparse-style errors of throats.solve / cache.lookup
        return exc.code


def _one_error(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and "Traceback" not in err[0], err
    return err[0]


@pytest.fixture()
def no_work(monkeypatch):
    """Any computation is a test failure: the checks must come first."""
    def boom(*a, **kw):
        raise AssertionError("computed before the output path was checked")
    for mod, name in [(solve_cli, "_compute"), (lookup_cli, "lookup_qstar"),
                      (pack_cli, "pack_bed"), (pack_cli, "pack_grains"),
                      (pack_cli, "pack_grains_to_porosity")]:
        monkeypatch.setattr(mod, name, boom)


@needs_proc
@pytest.mark.parametrize("which", ["throats.solve", "cache.lookup"])
def test_unwritable_out_folder_is_exit_2_before_work(tmp_path, monkeypatch, capsys, no_work,
                                                     which):
    """It was a FileNotFoundError traceback on '/proc/o.csv.part' after the whole solve."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.csv").write_text(GOOD)
    if which == "throats.solve":
        rc = _run(solve_cli.main, ["--csv", "t.csv", "--out", "/proc/o.csv"])
    else:
        rc = _run(lookup_cli.main, ["--policy", "fe-only", "--db", "fresh.sqlite", "--csv",
                                    "t.csv", "--out", "/proc/o.csv", "--quiet"])
    line = _one_error(capsys)
    assert rc == 2 and line.startswith("error: --out /proc/o.csv: folder /proc is not writable (")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]


@pytest.mark.parametrize("opt", ["--db", "--out"])
def test_lookup_refuses_a_missing_folder(tmp_path, monkeypatch, capsys, no_work, opt):
    """--db nodir/x.sqlite created the folder silently (the help says it must exist)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.csv").write_text(GOOD)
    paths = {"--db": "t.sqlite", "--out": "o.csv", opt: f"nodir/x.{opt[2:]}"}
    rc = _run(lookup_cli.main, ["--policy", "fe-only", "--db", paths["--db"], "--csv", "t.csv",
                                "--out", paths["--out"], "--quiet"])
    line = _one_error(capsys)
    assert rc == 2 and line.startswith(f"error: {opt} nodir/x.{opt[2:]}: folder ")
    assert line.endswith("nodir does not exist")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]


def test_lookup_bad_and_short_rows_are_error_lines(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.csv").write_text(GOOD + "1,1,1,2.2,2.2\n")
    rc = lookup_cli.main(["--policy", "shape-factor", "--db", "t.sqlite", "--csv", "t.csv",
                          "--out", "o.csv", "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 1 and err == ["error: t.csv row 3: the row has 5 of 6 values"]


BOX = ["--scene", "box", "--size", "0.05", "0.05", "--height", "0.04", "--quiet"]


@pytest.mark.parametrize("out, words", [
    ("folder", "error: --out folder: is a folder, give a file name"),
    pytest.param("/proc/x.csv", "error: --out /proc/x.csv: folder /proc is not writable (",
                 marks=needs_proc),
    ("bed.json", "error: --out bed.json: the packing would overwrite its own bed.json"),
])
@pytest.mark.parametrize("grain", [[], ["--grain", "soybean"], ["--grain", "soybean",
                                                                 "--porosity", "0.4"]])
def test_pack_checks_out_before_packing(tmp_path, monkeypatch, capsys, no_work, out, words,
                                        grain):
    """It ran the whole simulation first, then failed and left ``<out>.tmp`` behind."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "folder").mkdir()
    assert pack_cli.main([*BOX, *grain, "--out", out]) == 2
    assert _one_error(capsys).startswith(words)
    assert [p.name for p in tmp_path.iterdir()] == ["folder"]
    assert not list((tmp_path / "folder").iterdir())


def test_pack_checks_the_companion_json(tmp_path, monkeypatch, capsys, no_work):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "bed.json").mkdir()
    assert pack_cli.main([*BOX, "--out", "bed.csv"]) == 2
    assert _one_error(capsys) == ("error: --out bed.csv: companion bed.json: is a folder, "
                                  "give a file name")
    assert [p.name for p in tmp_path.iterdir()] == ["bed.json"]


def test_failed_writes_leave_no_tmp(tmp_path):
    """A rename that fails (the target is a folder) removes the temporary file."""
    for name in ("bed.csv", "g.csv"):
        (tmp_path / name).mkdir()
    with pytest.raises(OSError):
        write_packing(tmp_path / "bed.csv", np.zeros((1, 3)), np.ones(1))
    grains = {"centers": np.zeros((1, 3)), "quaternions": np.array([[1.0, 0, 0, 0]]),
              "volume_m3": np.ones(1), "template": ["t"]}
    with pytest.raises(OSError):
        write_grain_packing(tmp_path / "g.csv", np.zeros((1, 3)), np.ones(1), np.zeros(1, int),
                            grains)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bed.csv", "g.csv"]


@pytest.mark.parametrize("size, words", [
    (["inf", "0.04", "--height", "0.03"], "error: --size inf 0.04: lengths must be finite and > 0"),
    (["0.04", "0.04", "--height", "inf"], "error: --height inf: lengths must be finite and > 0"),
    (["nan", "0.04", "--height", "0.03"], "error: --size nan 0.04: lengths must be finite"),
    (["100", "100", "--height", "100"], "error: the container needs 4,117,020,357,668 spheres"),
    (["1", "1", "--height", "1"], "error: the container needs 4,117,020 spheres"),
])
def test_pack_refuses_infinite_or_oversized_containers(tmp_path, monkeypatch, capsys, size,
                                                       words):
    """inf was an OverflowError traceback, 100 m a MemoryError (59.9 TiB), 1 m failed only
    after placing 2.3 million spheres; the limit is named (MAX_SPHERES)."""
    monkeypatch.chdir(tmp_path)
    assert pack_cli.main(["--scene", "box", "--size", *size, "--out", "b.csv", "--quiet"]) == 2
    line = _one_error(capsys)
    assert line.startswith(words), line
    if "needs" in line:
        assert f"more than the limit of {MAX_SPHERES:,} spheres" in line
    assert not list(tmp_path.iterdir())


def test_container_refuses_non_finite_sizes():
    with pytest.raises(ValueError, match=r"finite and positive, got \(inf, 0.04\), 0.03"):
        Container("box", (float("inf"), 0.04), 0.03)


@pytest.mark.parametrize("main", [pack_cli.main, vibrate_cli.main])
def test_negative_seed_names_the_option(tmp_path, monkeypatch, capsys, main):
    monkeypatch.chdir(tmp_path)
    argv = [*BOX, "--out", "b.csv"] if main is pack_cli.main else ["p.csv", "--amplitude", "0.001"]
    assert main([*argv, "--seed", "-1"]) == 2
    assert _one_error(capsys) == "error: --seed must be a non-negative integer, got -1"
    assert not list(tmp_path.iterdir())


def test_vibrate_negative_radius_prints_the_plain_number(tmp_path, capsys):
    src = tmp_path / "p.csv"
    src.write_text("x,y,z,r\n0,0,0.01,0.003\n0,0,0.02,-0.003\n")
    assert vibrate_cli.main([str(src), "--amplitude", "0.001", "--quiet"]) == 2
    assert _one_error(capsys) == f"error: {src}: row 3: radius must be > 0, got -0.003"
