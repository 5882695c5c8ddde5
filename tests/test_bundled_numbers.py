"""What a user sees does not move: the bundled scene's numbers and every command's bad-input exit.

The bundled soybean scene solved by ``python -m network.solve`` (table-only Q* from the shipped
grid alone, as ``conftest.py`` arranges) gives the numbers below; they are pinned to the last
digit the command prints and, in its JSON, to a relative 1e-12, so a refactor that changes a
single rounding step in the pipeline fails here. The values were produced by commit 001063a,
the porosity's by the commit that pairs k with the porosity of its own region (the inset
window's 0.39399, the whole sample's 0.39904 beside it).
"""

from __future__ import annotations

import contextlib
import importlib
import io
import json

import pytest

from network import solve as solve_cli

# JSON values: inertial (default) and --stokes runs of the bundled scene
INERTIAL = {"permeability_m2": 4.2283870706314856e-08, "pressure_drop_pa": 1.5781224133812197,
            "pressure_gradient_pa_per_m": 6.312489653524879,
            "pressure_drop_stokes_pa": 1.4849633903223214,
            "pressure_gradient_stokes_pa_per_m": 5.9398535612892855,
            "permeability_whole_m2": 4.20260849134922e-08, "porosity": 0.3939943067548115,
            "porosity_sample": 0.3990393364127721}
STOKES = {"permeability_m2": 4.2283870706314856e-08, "pressure_drop_pa": 1.4849633903223214,
          "pressure_gradient_pa_per_m": 5.9398535612892855}
# the lines ``python -m network.solve`` prints for them
INERTIAL_LINES = ["  permeability k = 4.2284e-08 m²   k/d32² = 9.6792e-04",
                  "  at v = 0.013 m/s: gradient 6.312 Pa/m, drop over 0.25 m = 1.578 Pa",
                  "    with inertia (Re_p 5.34; Stokes 5.94 Pa/m, 1.485 Pa; 4 Newton iterations)"]
STOKES_LINES = ["  permeability k = 4.2284e-08 m²   k/d32² = 9.6792e-04",
                "  at v = 0.013 m/s: gradient 5.94 Pa/m, drop over 0.25 m = 1.485 Pa"]


@pytest.mark.slow
@pytest.mark.parametrize("extra, want, lines", [([], INERTIAL, INERTIAL_LINES),
                                                 (["--stokes"], STOKES, STOKES_LINES)],
                         ids=["inertial", "stokes"])
def test_bundled_scene_numbers_are_pinned(extra, want, lines, tmp_path, capsys):
    out = tmp_path / "out.json"
    assert solve_cli.main([*extra, "--json", str(out)]) == 0
    printed = capsys.readouterr().out.splitlines()
    for line in lines:
        assert line in printed
    got = json.loads(out.read_text())
    assert got["n_pores"] == 9017 and got["n_throats"] == 17264
    for key, value in want.items():
        assert got[key] == pytest.approx(value, rel=1e-12, abs=0), key


def _main_of(command):
    """``main`` of a command module, or of a command package's ``__main__``."""
    module = importlib.import_module(command)
    if not hasattr(module, "main"):
        module = importlib.import_module(f"{command}.__main__")
    return module.main


BAD_INPUTS = [
    ("network.solve", ["--velocity", "-1"]),
    ("network.solve", ["--axis", "w"]),
    ("network.solve", ["/nonexistent/bed.csv"]),
    ("network.solve", ["--inertial-law", "chain"]),       # removed: names the window law
    ("network.curve", ["--velocities", "0"]),
    ("network.paths", ["--axis", "q"]),
    ("network.report", ["--no-such-option"]),
    ("network.throatlist", ["--out", "/nonexistent/d/t.csv"]),
    ("network.throats", ["--out", "/nonexistent/d/t.csv"]),
    ("network.bench", ["--repeat", "0"]),
    ("cache.precompute", ["--db", "x.sqlite"]),
    ("cache.lookup", ["--csv", "/nonexistent/x.csv", "--out", "o.csv"]),
    ("cache.bench", ["--repeat", "0"]),
    ("throats.solve", ["--radii", "1", "1", "-1", "--sides", "2", "2", "2"]),
    ("throats.bench", ["--no-such-option"]),
    ("dem.pack", ["--scene", "no-such-scene", "--out", "p.csv"]),
    ("dem.vibrate", ["/nonexistent/x.csv", "--amplitude", "0.001", "--out", "v.csv"]),
    ("dem.bench", ["--n", "0"]),
]


@pytest.mark.parametrize("command, argv", BAD_INPUTS,
                         ids=[f"{c}-{' '.join(a)}" for c, a in BAD_INPUTS])
def test_bad_input_exits_2_with_an_error_line(command, argv, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            rc = _main_of(command)(argv)
        except SystemExit as stop:        # argparse's own exit, as ``python -m`` would see it
            rc = stop.code
    assert rc == 2
    assert "error:" in err.getvalue().strip().splitlines()[-1]
    assert list(tmp_path.iterdir()) == []
