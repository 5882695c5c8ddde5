"""The container in a packing's companion JSON ("unknown container kinds are errors").

A ``container`` entry of an unknown kind, or with sizes that do not fit its kind, is refused by
every network command with one ``error:`` line naming the file, exit 2, nothing written; a JSON
of the same stem without a ``container`` entry (another tool's output) is ignored. The
``network.throatlist`` export samples the same cylinder as ``network.solve``.
"""

import json

import numpy as np
import pytest

from network import (Packing, random_packing, read_container, write_packing_csv)
from network import curve, report, solve, throatlist
from network.paths import __main__ as paths


@pytest.fixture(scope="module")
def cylinder_bed(tmp_path_factory):
    """A cylindrical bed (spheres inside a vertical cylinder of diameter D) and its D, m."""
    pk = random_packing(1500, rng=8, periodic=True, solid_fraction=0.6, aspect=(1, 1, 1.5))
    mid = 0.5 * (pk.centers.min(0) + pk.centers.max(0))
    big_r = 0.5 * float(np.ptp(pk.centers[:, 0]))
    keep = np.hypot(*(pk.centers[:, :2] - mid[:2]).T) + pk.radii <= big_r
    path = tmp_path_factory.mktemp("cyl") / "bed.csv"
    write_packing_csv(Packing(pk.centers[keep], pk.radii[keep]), path)
    return path, 2 * big_r, mid[:2]


@pytest.mark.slow
@pytest.mark.parametrize("entry, text", [
    ({"kind": "sphere", "size_m": [0.1]}, "container kind 'sphere' is not known; the kinds read are box, cylinder"),
    ({"size_m": [0.1]}, "container kind 'none' is not known"),
    ("cylinder", "container kind None is not known"),
    ({"kind": "box", "size_m": [0.1]}, "a box container needs size_m = [length_x, width_y] (m, > 0), got [0.1]"),
    ({"kind": "cylinder", "size_m": [-0.1]}, "a cylinder container needs size_m = [diameter]"),
    ({"kind": "cylinder", "size_m": ["wide"]}, "container 'size_m' is missing or not numbers"),
    ({"kind": "Cylinder"}, "container 'size_m' is missing"),
])
def test_read_container_refuses_unknown_kinds_and_bad_sizes(tmp_path, entry, text):
    (tmp_path / "bed.json").write_text(json.dumps({"container": entry}))
    with pytest.raises(ValueError) as e:
        read_container(tmp_path / "bed.csv")
    assert str(tmp_path / "bed.json") in str(e.value) and text in str(e.value)


@pytest.mark.slow
def test_read_container_ignores_other_json_and_reads_case_insensitively(tmp_path):
    assert read_container(tmp_path / "bed.csv") is None                   # no JSON at all
    (tmp_path / "bed.json").write_text(json.dumps({"permeability_m2": 4.2e-8}))
    assert read_container(tmp_path / "bed.csv") is None                   # network.solve's output
    (tmp_path / "bed.json").write_text("[1, 2")
    assert read_container(tmp_path / "bed.csv") is None                   # not JSON
    (tmp_path / "bed.json").write_text(json.dumps(
        {"container": {"kind": "Box", "size_m": [0.2, 0.1], "fill_height_m": 0.3}}))
    assert read_container(tmp_path / "bed.csv") == {"kind": "box", "size_m": [0.2, 0.1],
                                                    "source": str(tmp_path / "bed.json")}


COMMANDS = {
    "solve": (solve.main, ["{bed}", "--stokes", "--json", "{tmp}/out.json"]),
    "curve": (curve.main, ["{bed}", "--velocities", "0.01,0.1", "--json", "{tmp}/out.json"]),
    "paths": (paths.main, ["{bed}", "--entries", "2", "--json", "{tmp}/out.json"]),
    "throats": (throatlist.main, ["{bed}", "--out", "{tmp}/out.json"]),
    "report": (report.main, ["--grain", "soybean", "--packing", "{bed}", "--no-band",
                             "--json", "{tmp}/out.json"]),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_command_refuses_an_unknown_container_kind(name, cylinder_bed, tmp_path, capsys):
    src, _, _ = cylinder_bed
    bed = tmp_path / "bed.csv"
    bed.write_bytes(src.read_bytes())
    (tmp_path / "bed.json").write_text(json.dumps({"container": {"kind": "cone", "size_m": [1]}}))
    main, argv = COMMANDS[name]
    assert main([a.format(bed=bed, tmp=tmp_path) for a in argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and "'cone' is not known" in err[0], err
    assert not (tmp_path / "out.json").exists()


@pytest.mark.slow
def test_throats_export_samples_the_cylinder_that_solve_solves(cylinder_bed, tmp_path):
    """With the container, network.throatlist exports the throats of network.solve's cylinder (all
    but a few at the sample faces), not the corners outside it; without it the export takes the
    bounding box (more throats)."""
    src, diameter, mid = cylinder_bed
    bed = tmp_path / "bed.csv"
    bed.write_bytes(src.read_bytes())
    assert throatlist.main([str(bed), "--out", str(tmp_path / "box.csv"), "--quiet"]) == 0
    (tmp_path / "bed.json").write_text(json.dumps(
        {"container": {"kind": "cylinder", "size_m": [diameter], "center_xy": mid.tolist()}}))
    assert throatlist.main([str(bed), "--out", str(tmp_path / "cyl.csv"), "--quiet"]) == 0
    assert solve.main([str(bed), "--stokes", "--quiet", "--axis", "z",
                       "--throats-csv", str(tmp_path / "solved.csv")]) == 0
    ids = {k: set(np.loadtxt(tmp_path / f"{k}.csv", delimiter=",", skiprows=1)[:, 6].astype(int))
           for k in ("box", "cyl")}
    solved = set(np.loadtxt(tmp_path / "solved.csv", delimiter=",", skiprows=1)[:, 0].astype(int))
    # the export's sample selection and the solve's differ in a few throats at the sample's
    # faces (measured: 8 of 5659 with the cylinder, 1 of 6729 with the bounding box)
    assert len(solved - ids["cyl"]) <= 0.005 * len(solved)
    assert len(ids["cyl"]) < 0.9 * len(ids["box"])
    assert len(solved) > 0.8 * len(ids["cyl"])
