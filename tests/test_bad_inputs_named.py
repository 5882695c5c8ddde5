"""Bad input to every command is refused before any work with exit 2 and one line that names
it, and no input file changes: templates in the wrong unit or with spheres inside spheres,
outputs that would overwrite an input or each other, beds too small for a sample, spheres that
overlap into one body under separate grain ids, option values in the wrong form."""

import hashlib
from pathlib import Path

import pytest

from dem import pack as dem_pack
from dem.templates import read_template


def _digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _one_error(capsys):
    """The one ``error:`` line on stderr (``warning:`` lines before it aside)."""
    err = [ln for ln in capsys.readouterr().err.strip().splitlines()
           if not ln.startswith("warning: ")]
    assert len(err) == 1 and err[0].startswith("error: "), err
    return err[0]


# ---------------------------------------------------------------- grain templates
def test_a_template_in_metres_read_in_mm_says_so(tmp_path, capsys):
    t = tmp_path / "kernel.csv"
    t.write_text("x,y,z,r\n-0.001,0,0,0.0012\n0.001,0,0,0.0012\n")      # 4.4 mm, in metres
    before = _digest(t)
    with pytest.raises(ValueError, match=r"the grain is 0.0044 mm across read in mm "
                                         r"\(--template-units mm\): a template written in "
                                         r"metres\? give --template-units m"):
        read_template(t, units="mm")
    assert read_template(t, units="m").extent_m.max() == pytest.approx(4.4e-3, rel=2e-3)
    rc = dem_pack.main(["--scene", "box", "--grain", str(t), "--out", str(tmp_path / "o.csv")])
    assert rc == 2 and "give --template-units m" in _one_error(capsys)
    assert _digest(t) == before and not (tmp_path / "o.csv").exists()


@pytest.mark.parametrize("rows, words", [
    ("0,0,0,1\n0,0,0,1\n", "row 3: the sphere lies inside the sphere of row 2 (coincident"),
    ("0,0,0,1\n0.2,0,0,0.5\n1.5,0,0,1\n", "row 3: the sphere lies inside the sphere of row 2"),
    ("0,0,0,0.5\n1,0,0,1\n0.2,0,0,2\n", "row 2: the sphere lies inside the sphere of row 4"),
])
def test_coincident_or_contained_template_spheres_are_refused(tmp_path, capsys, rows, words):
    t = tmp_path / "kernel.csv"
    t.write_text("x,y,z,r\n" + rows)
    with pytest.raises(ValueError, match=words.replace("(", r"\(")):
        read_template(t, units="mm")
    rc = dem_pack.main(["--scene", "box", "--grain", str(t), "--out", str(tmp_path / "o.csv")])
    err = _one_error(capsys)
    assert rc == 2 and words in err and f"--grain {t}" in err


# ---------------------------------------------------------------- an output over an input
GOOD = "x,y,z,r\n" + "".join(f"{i * 0.01},{(i % 3) * 0.01},{(i % 2) * 0.01},0.004\n"
                             for i in range(8))
THROATS = "r1,r2,r3,l12,l13,l23\n1,1,1,2.5,2.5,2.5\n"


def _cases():
    from cache import bench as cache_bench, lookup as cache_lookup, precompute
    from dem import bench as dem_bench, vibrate
    from network import bench as net_bench, curve, solve, throats as net_throats
    from network.paths import __main__ as paths
    from network.report import main as report
    from throats import solve as throats_solve

    return {  # name: (main, files to make, argv, the input it would overwrite, words)
        "network.solve": (solve.main, {"bed.csv": GOOD}, ["bed.csv", "--json", "bed.csv"],
                          "bed.csv", "--json bed.csv: the same file as the packing file"),
        "network.curve": (curve.main, {"bed.csv": GOOD}, ["bed.csv", "--csv", "bed.csv"],
                          "bed.csv", "--csv bed.csv: the same file as the packing file"),
        "network.paths": (paths.main, {"bed.csv": GOOD}, ["bed.csv", "--json", "bed.csv"],
                          "bed.csv", "--json bed.csv: the same file as the packing file"),
        "network.throats": (net_throats.main, {"bed.csv": GOOD}, ["bed.csv", "--out", "bed.csv"],
                            "bed.csv", "--out bed.csv: the same file as the packing file"),
        "network.report --json": (
            report, {"fan.csv": "airflow_m3_s,static_pressure_pa\n0,900\n2,100\n"},
            ["--grain", "wheat", "--diameter", "6", "--fan", "fan.csv", "--json", "fan.csv"],
            "fan.csv", "--json fan.csv: the same file as --fan fan.csv (an input)"),
        "network.report figures": (
            report, {"fig/report_curve.png": "airflow_m3_s,static_pressure_pa\n0,900\n2,100\n"},
            ["--grain", "wheat", "--diameter", "6", "--fan", "fig/report_curve.png",
             "--plot-dir", "fig"],
            "fig/report_curve.png", "--plot-dir fig/report_curve.png: the same file as --fan"),
        "network.bench": (net_bench.main, {"t.sqlite": ""},
                          ["--db", "t.sqlite", "--json", "t.sqlite", "--sizes", "500"],
                          "t.sqlite", "--json t.sqlite: the same file as --db t.sqlite"),
        "dem.vibrate": (vibrate.main, {"out/vib_1mm.csv": GOOD},
                        ["out/vib_1mm.csv", "--amplitude", "0.001", "--scene", "box", "--size",
                         "0.1", "0.1", "--height", "0.1", "--out", "out"],
                        "out/vib_1mm.csv", "--out out/vib_1mm.csv: the same file as the packing"),
        "dem.bench": (dem_bench.main, {"d/study.json": "{}"},
                      ["--study", "d", "--json", "d/study.json"], "d/study.json",
                      "--json d/study.json: the same file as --study d/study.json"),
        "cache.lookup": (cache_lookup.main, {"t.csv": THROATS},
                         ["--csv", "t.csv", "--out", "t.csv", "--policy", "shape-factor"],
                         "t.csv", "--out t.csv: the same file as --csv t.csv"),
        "cache.precompute": (precompute.main, {"t.csv": THROATS},
                             ["--csv", "t.csv", "--db", "t.csv"],
                             "t.csv", "--db t.csv: the same file as --csv t.csv"),
        "cache.bench": (cache_bench.main, {"x.sqlite": ""},
                        ["--db", "x.sqlite", "--out", "x.sqlite"], "x.sqlite",
                        "--out x.sqlite: the same file as --db x.sqlite"),
        "throats.solve": (throats_solve.main, {"t.csv": THROATS},
                          ["--csv", "t.csv", "--out", "t.csv"], "t.csv",
                          "--out t.csv: the same file as --csv t.csv"),
    }


CASES = sorted(_cases())


@pytest.mark.parametrize("name", CASES)
def test_no_command_writes_over_its_input(tmp_path, monkeypatch, capsys, name):
    main, files, argv, victim, words = _cases()[name]
    monkeypatch.chdir(tmp_path)
    for rel, text in files.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text)
    before = _digest(tmp_path / victim)
    try:
        rc = main(argv)
    except SystemExit as e:                  # network.bench ends with SystemExit(code)
        rc = e.code
    err = _one_error(capsys)
    assert rc == 2 and words in err, err
    assert _digest(tmp_path / victim) == before


def test_a_hard_link_of_the_input_is_the_input(tmp_path, monkeypatch, capsys):
    """Two names, one file: os.path.samefile sees what the paths do not."""
    from network import curve

    monkeypatch.chdir(tmp_path)
    (tmp_path / "bed.csv").write_text(GOOD)
    (tmp_path / "link.csv").hardlink_to(tmp_path / "bed.csv")
    rc = curve.main(["bed.csv", "--csv", "link.csv"])
    assert rc == 2 and "--csv link.csv: the same file as the packing file" in _one_error(capsys)
    assert (tmp_path / "bed.csv").read_text() == GOOD



# ---------------------------------------------------------------- exit codes of bad beds
def _lattice(path, n=4):
    """n^3 touching spheres (r 2 mm): too thin for a sample 1.5 diameters in from its faces."""
    rows = [f"{i * 0.0041 + 0.0001 * ((j + k) % 2)},{j * 0.0041},{k * 0.0041},0.002"
            for i in range(n) for j in range(n) for k in range(n)]
    path.write_text("x,y,z,r\n" + "\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize("command", ["solve", "curve", "report", "throats"])
def test_a_packing_too_small_for_a_sample_is_bad_input_everywhere(tmp_path, capsys, command):
    from network import curve, solve, throats
    from network.report import main as report

    bed = _lattice(tmp_path / "small.csv")
    before = _digest(bed)
    argv = {"solve": (solve.main, [str(bed), "-q"]), "curve": (curve.main, [str(bed), "-q"]),
            "report": (report, ["--packing", str(bed), "--grain", "soybean", "--porosity",
                                "0.45", "-q", "--no-figures"]),
            "throats": (throats.main, [str(bed), "--out", str(tmp_path / "t.csv"), "-q"])}
    main, args = argv[command]
    rc = main(args)
    err = _one_error(capsys)
    assert rc == 2 and "too thin for a sample away from the walls" in err
    assert _digest(bed) == before


def test_spheres_overlapping_across_grains_are_bad_input_with_a_sentence(tmp_path, capsys):
    """The soybean grain bed without its grain_id column: every sphere overlaps the other
    spheres of its kernel, now counted as separate grains (porosity 3.38 by the pairwise
    estimate): exit 2 with a sentence saying what to give, from network.solve (an internal
    error, exit 1, without the check) and network.curve (a number, exit 0, without it)."""
    from network import curve, solve

    src = (Path(solve.__file__).parent / "data" / "soybean_grains.csv").read_text()
    bed = tmp_path / "no_ids.csv"
    bed.write_text("\n".join(",".join(ln.split(",")[:4]) for ln in src.splitlines()) + "\n")
    before = _digest(bed)
    for main in (solve.main, curve.main):
        rc = main([str(bed), "-q"])
        err = _one_error(capsys)
        assert rc == 2 and "2970 of 2970 spheres overlap a sphere of another grain" in err
        assert "give each grain's spheres one id in a grain_id column" in err
    assert _digest(bed) == before


# ---------------------------------------------------------------- option forms and bounds
@pytest.mark.parametrize("value, words", [
    ("0.01:0.3:2.5", "n '2.5' is not a whole number of points; give a comma-separated list"),
    ("0.01:0.3", "2 parts; give a comma-separated list (0.01,0.05,0.1) or start:stop:n"),
    ("0.01:0.3:8:2", "4 parts; give"),
    ("a,0.1", "'a' is not a number; give a comma-separated list"),
    ("0.01:0.3:100000", "n must be 1 to 200 points, got 100000"),
    (",", "is empty; give"),
])
def test_velocities_say_which_form_is_expected(capsys, value, words):
    from network import curve
    from network.report import main as report

    for main, args in ((curve.main, ["-q"]), (report, ["--grain", "wheat", "-q"])):
        rc = main(args + ["--velocities", value])
        err = _one_error(capsys)
        assert rc == 2 and words in err and "Traceback" not in err, err


def test_repeated_velocities_are_solved_once():
    from network.curve import parse_velocities

    assert parse_velocities("0.1,0.01,0.1,0.010") == [0.1, 0.01]


@pytest.mark.parametrize("argv, words", [
    (["network.solve", "--threads", "100000"], "--threads must be 1 to 1024, got 100000"),
    (["network.curve", "--workers", "5000"], "--workers must be 1 to 1024, got 5000"),
    (["cache.lookup", "--workers", "99999", "--csv", "t.csv", "--out", "o.csv"],
     "--workers must be 1 to 1024, got 99999"),
    (["dem.pack", "--scene", "box", "--n-particles", "1000000000", "--out", "o.csv"],
     "--n-particles must be 1 to 10000000, got 1000000000"),
    (["dem.vibrate", "p.csv", "--amplitude", "0.001", "--settle-steps", "10000000000"],
     "--settle-steps must be 1 to 1000000000"),
    (["dem.bench", "--repeat", "100000"], "--repeat must be 1 to 1000, got 100000"),
])
def test_counts_are_bounded_before_any_work(tmp_path, monkeypatch, capsys, argv, words):
    import importlib

    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.csv").write_text(THROATS)
    (tmp_path / "p.csv").write_text(GOOD)
    main = importlib.import_module(argv[0]).main
    try:
        rc = main(argv[1:])
    except SystemExit as e:
        rc = e.code
    err = _one_error(capsys)
    assert rc == 2 and words in err, err
