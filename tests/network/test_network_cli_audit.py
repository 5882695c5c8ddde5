"""The network commands on the audit's degenerate inputs: flat centres, isolated spheres, a huge
or tiny ``--standin``, one velocity for the curve fits, option wording, and the library's
logged warnings printed once each as ``warning:`` lines (exit 2 and nothing written on bad
input)."""

import json
import logging
import subprocess
import sys

import numpy as np
import pytest

from network import _cli, curve, random_packing, read_packing, solve, throatlist
from network.packing import DegeneratePackingError, Packing
from network.paths import __main__ as paths
from network.pores import tessellate

MAINS = {"solve": solve.main, "curve": curve.main, "throats": throatlist.main, "paths": paths.main}
SAMPLE = ["--sample", "0", "0.05", "0", "0.05", "-0.002", "0.002"]


def _write(path, centers, radii, prefix=b""):
    body = "x,y,z,r\n" + "".join(f"{a!r},{b!r},{c!r},{r!r}\n"
                                 for (a, b, c), r in zip(np.asarray(centers).tolist(),
                                                         np.asarray(radii).tolist()))
    path.write_bytes(prefix + body.encode())
    return str(path)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A 386-sphere bed with one sphere apart and a companion JSON without a container, the
    same bed without them (also with a UTF-8 BOM), flat, isolated and five-sphere packings."""
    d = tmp_path_factory.mktemp("audit")
    pk = random_packing(386, solid_fraction=0.592, aspect=(0.04, 0.04, 0.06), rng=5,
                        max_sweeps=300)
    c, r = pk.centers, pk.radii
    grid = np.array([[i * 0.006, j * 0.006, 0.0] for i in range(10) for j in range(10)])
    jitter = np.random.default_rng(1).random((512, 3)) * 1e-3
    lattice = np.array([[i, j, k] for i in range(8) for j in range(8) for k in range(8)]) * 6e-3
    out = {
        "bed": _write(d / "bed.csv", c, r),
        "bom": _write(d / "bom.csv", c, r, prefix=b"\xef\xbb\xbf"),
        "apart": _write(d / "apart.csv", np.vstack([c, [0.2, 0.02, 0.02]]), np.append(r, 0.003)),
        "coplanar": _write(d / "coplanar.csv", grid, np.full(100, 0.003)),
        "collinear": _write(d / "collinear.csv", [[i * 0.006, 0, 0] for i in range(30)],
                            np.full(30, 0.003)),
        "tiny": _write(d / "tiny.csv", lattice + jitter, np.full(512, 3e-6)),
        "five": _write(d / "five.csv", c[:5] * [1, 1, 3], r[:5]),
        "dir": str(d),
    }
    (d / "apart.json").write_text('{"note": "another tool\'s output"}')
    return out


def _one_error(capsys, *words):
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith("error: "), err
    for w in words:
        assert w in err, (w, err)
    return err


@pytest.mark.parametrize("shape", ["coplanar", "collinear"])
@pytest.mark.parametrize("name, extra", [
    ("solve", ["-q"]), ("solve", ["-q"] + SAMPLE), ("curve", ["-q"] + SAMPLE),
    ("throats", ["--all"]), ("throats", SAMPLE), ("paths", []),
    ("paths", ["--kind", "shortest", "--no-branched"]),
])
def test_flat_centres_are_bad_input_in_every_command(files, shape, name, extra, tmp_path,
                                                     capsys):
    out = tmp_path / ("t.csv" if name == "throats" else "o.json")
    opt = ["--out", str(out)] if name == "throats" else ["--json", str(out)]
    assert MAINS[name]([files[shape]] + extra + opt) == 2
    _one_error(capsys, f"the sphere centres are {shape}: no 3-D tessellation")
    assert not out.exists()


def test_tessellating_flat_centres_raises_the_bad_input_error():
    grid = np.array([[i, j, 0.0] for i in range(4) for j in range(4)])
    with pytest.raises(DegeneratePackingError, match="coplanar: no 3-D tessellation") as e:
        tessellate(Packing(grid, np.full(16, 0.3)))
    assert e.value.bad_input


@pytest.mark.parametrize("name, words", [("solve", "give an explicit --sample box"),
                                         ("paths", "--no-branched skips it")])
def test_isolated_spheres_name_the_cause(files, name, words, tmp_path, capsys):
    js = tmp_path / "o.json"
    quiet = ["-q"] if name == "solve" else []
    assert MAINS[name]([files["tiny"], "--json", str(js)] + quiet) == 2
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert out == "" and lines[-1].startswith("error: ") and not js.exists()
    assert "no bed to take a sample from" in lines[-1] and "no two near contact" in lines[-1]
    assert words in lines[-1] and "zero-size array" not in err
    assert all(ln.startswith("warning: ") for ln in lines[:-1])   # the grain-size warning


@pytest.mark.parametrize("box, words", [
    (["10", "10", "10"], "more than the 100000 a stand-in may have"),
    (["0.03", "0.03", "0.03"], "--standin 0.03 0.03 0.03: every side must be >= 0.04 m"),
    (["0.001", "0.001", "0.001"], "--standin 0.001 0.001 0.001: every side must be >= 0.04"),
])
def test_standin_box_is_bounded_before_any_work(box, words, tmp_path, capsys):
    js = tmp_path / "o.json"
    assert paths.main(["--standin", *box, "--json", str(js)]) == 2
    _one_error(capsys, words)
    assert not js.exists()


@pytest.mark.parametrize("velocities", ["0.05", "0.05,0.05,0.05", "0.01:0.01:4"])
def test_curve_with_one_distinct_velocity_says_why_the_fits_are_none(files, velocities,
                                                                      tmp_path, capsys):
    js = tmp_path / "c.json"
    assert curve.main([files["bed"], "-q", "--policy", "shape-factor", "--velocities",
                       velocities, "--json", str(js)]) == 0
    err = capsys.readouterr().err
    said = [ln for ln in err.splitlines() if "distinct velocities" in ln]
    assert len(said) == 1 and said[0].startswith("warning: the fits")
    assert f"need at least {curve.MIN_FIT_VELOCITIES} distinct velocities" in said[0]
    fits = json.loads(js.read_text())
    assert fits["permeability_m2"] is None and fits["d272_a"] is None


@pytest.mark.parametrize("name", ["solve", "curve", "paths"])
def test_viscosity_below_any_gas_is_refused(files, name, tmp_path, capsys):
    js = tmp_path / "o.json"
    assert MAINS[name]([files["bed"], "--viscosity", "1e-30", "--json", str(js)]) == 2
    _one_error(capsys, "--viscosity 1e-30 Pa s is below 1e-07 Pa s", "hydrogen")
    assert not js.exists()


@pytest.mark.parametrize("name, argv, words", [
    ("paths", ["--seed", "-1", "--standin", "0.05", "0.05", "0.05"],
     "--seed must be an integer >= 0, got -1"),
    ("paths", ["{dir}"], "is a folder, not a file"),
    ("solve", ["{dir}"], "is a folder, not a file"),
    ("paths", ["{five}"], "no bed to take a sample from"),
    ("paths", ["{five}", "--kind", "shortest", "--no-branched"], "no air path through the bed"),
])
def test_wording_names_the_option_or_the_cause(files, name, argv, words, capsys):
    assert MAINS[name]([a.format(**files) for a in argv]) == 2
    err = _one_error(capsys, words)
    assert "min_quality" not in err and "expected non-negative integer" not in err


def test_a_csv_with_a_byte_order_mark_reads_as_without(files, tmp_path, capsys):
    a, b = read_packing(files["bom"]), read_packing(files["bed"])
    np.testing.assert_array_equal(a.centers, b.centers)
    assert throatlist.main([files["bom"], "--all", "--out", str(tmp_path / "t.csv")]) == 0


def test_logged_warnings_become_one_warning_line_each(capsys):
    def body(_):
        for _ in range(2):
            logging.getLogger("network.some_module").warning("first  %s", "warning")
        logging.getLogger("network.other").warning("second")
        logging.getLogger("network.other").info("progress, not a warning")
        return 0

    before = list(logging.getLogger().handlers)
    assert _cli.run(body, _cli.CliParser(prog="x"), []) == 0
    assert capsys.readouterr().err == "warning: first warning\nwarning: second\n"
    assert logging.getLogger().handlers == before


@pytest.mark.slow
def test_library_warnings_in_a_real_run_are_prefixed_and_printed_once(files, tmp_path):
    run = subprocess.run([sys.executable, "-m", "network.solve", files["apart"], "--axis",
                          "all", "--stokes", "--policy", "shape-factor"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    lines = run.stderr.splitlines()
    warned = [ln for ln in lines if ln.startswith("warning: ")]
    assert len(warned) == len(set(warned))
    assert sum("companion JSON" in ln for ln in warned) == 1
    assert sum("lie apart" in ln for ln in warned) == 1
    # the progress lines (INFO) carry no warning text of their own
    assert not [ln for ln in lines if not ln.startswith("warning: ")
                and ("lie apart" in ln or "companion JSON" in ln or "wide" in ln)]


def test_paths_warns_once_and_reads_the_region_once(files, capsys):
    assert paths.main([files["apart"], "--kind", "shortest", "--entries", "1"]) == 0
    err = capsys.readouterr().err
    assert err.count("warning: 1 sphere(s) lie apart") == 1
    assert err.count("warning: companion JSON") == 1
