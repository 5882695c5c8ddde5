"""dem.pack --grain --porosity: the procedure lever, network's sample region, the search.

The search logic is tested on a stand-in for pack_grains whose porosity is a known function of
the lever (a DEM packing of hundreds of grains takes minutes); the lever's physical effect is
measured on real packings in docs/report.md.
"""

from pathlib import Path

import numpy as np
import pytest

import dem._clump_pack as cp
from dem import Container
from dem._clump_pack import network_region, procedure_lever
from dem._grain_search import grain_count, pack_grains_to_porosity
from dem.templates import sphere_template


def test_procedure_lever_ends_and_middle():
    assert procedure_lever(-1.0) == (0.0, 0.0)          # closed box at the fill height
    assert procedure_lever(0.0) == (0.3, 0.0)           # free fall, frictionless
    assert procedure_lever(1.0) == (0.3, 1.0)           # free fall, deposition friction 1
    assert procedure_lever(-0.25) == (0.225, 0.0)
    assert procedure_lever(7.0) == (0.3, 1.0)           # clipped


def test_network_region_is_network_default_region():
    """The same box as network.pores.default_region (1.5 volume-equivalent diameters inside
    the spheres' bounding box), computed without importing network."""
    from network.packing import Packing
    from network.pores import default_region
    rng = np.random.default_rng(3)
    x = rng.uniform(0, 0.05, (400, 3))
    r = np.full(400, 0.002)
    lo, hi = network_region(x, r, np.pi / 6 * 0.004**3)
    reg = default_region(Packing(x, r))
    np.testing.assert_allclose(lo, reg.lo, atol=1e-12)
    np.testing.assert_allclose(hi, reg.hi, atol=1e-12)


def _fake(law, calls):
    """A pack_grains stand-in whose porosity is law(lever) (the lever read back from the
    headroom and friction it is given)."""
    def pack(container, template, *, porosity, deposition_friction, lid_headroom, **kw):
        lam = deposition_friction if deposition_friction > 0 else lid_headroom / 0.3 - 1.0
        calls.append(lam)
        e = law(lam)
        return (None, None, None, None, {"porosity_network_region": e,
                                         "porosity_network_region_error": 1e-3,
                                         "wall_time_s": 1.0})
    return pack


def test_search_reaches_the_target_within_tol(monkeypatch):
    """The range's three beds (levers -1, 0, +1) first, then the search inside them."""
    calls = []
    monkeypatch.setattr(cp, "pack_grains", _fake(lambda lam: 0.38 + 0.02 * (lam + 1) ** 1.5, calls))
    box = Container("box", (0.01, 0.01), 0.01)
    out = pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.405, porosity_tol=0.002)
    s = out[4]["porosity_search"]
    assert abs(out[4]["porosity_network_region"] - 0.405) <= 0.002
    assert s["reachable"] == pytest.approx([0.38, 0.38 + 0.02 * 2**1.5])
    assert calls[:3] == [-1.0, 0.0, 1.0] and len(calls) <= 3 + 6
    assert [b["lever"] for b in s["range_beds"]] == [-1.0, 0.0, 1.0]
    assert [t["lever"] for t in s["tried"]] == pytest.approx(calls[3:], abs=1e-9)


def test_a_range_bed_within_the_tolerance_is_the_answer(monkeypatch):
    """0.401 +- 0.002 and the range's bed at lever 0 has 0.400: that bed, no packing more."""
    calls = []
    monkeypatch.setattr(cp, "pack_grains", _fake(lambda lam: 0.38 + 0.02 * (lam + 1), calls))
    box = Container("box", (0.01, 0.01), 0.01)
    out = pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.401, porosity_tol=0.002)
    assert calls == [-1.0, 0.0, 1.0] and out[4]["procedure_lever"] == 0.0
    assert out[4]["porosity_network_region"] == pytest.approx(0.40)


def test_search_outside_the_reachable_range_names_it(monkeypatch):
    monkeypatch.setattr(cp, "pack_grains", _fake(lambda lam: 0.40 + 0.01 * lam, []))
    box = Container("box", (0.01, 0.01), 0.01)
    with pytest.raises(ValueError, match=r"porosity 0.43 is outside what dem.pack reaches for "
                                         r"sphere in this container: 0\.3900-0\.4100 \(the beds "
                                         r"dem.pack --porosity made in the 0.01 x 0.01 x 0.01 m box"):
        pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.43)


def test_search_gives_up_after_max_packings(monkeypatch):
    """A porosity that jumps across the target (packing noise) is not found: RuntimeError with
    the closest bed, never a bed outside the tolerance; the range's beds are not counted."""
    calls = []
    monkeypatch.setattr(cp, "pack_grains", _fake(lambda lam: 0.39 if lam < 0.3 else 0.42, calls))
    box = Container("box", (0.01, 0.01), 0.01)
    with pytest.raises(RuntimeError, match="no packing at equilibrium within 0.005 of porosity "
                                           "0.405 after 6 packings"):
        pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.405)
    assert len(calls) == 3 + 6


def test_steep_lever_is_searched_to_the_target(monkeypatch):
    """Soybean in the 0.04 m box (253 grains, seed 1), its beds' porosity against the lever as
    packed on one x86-64 host: steep between deposition friction 0.15 and 0.22 (0.3918 ->
    0.4104), not monotone (0.4201 at 0.39, 0.4169 at 1). Plain regula falsi from the two ends
    spends 6 packings there without landing on 0.40 (-1, 1, 0.39, -0.087, 0.152, 0.221); from
    the range's three beds, by regula falsi with bisection after two beds on one side, every
    target in the range lands within 0.005 within the default 6 packings (the range's not
    counted)."""
    pts = [(-1, 0.3616), (-0.087, 0.3799), (0, 0.3727), (0.152, 0.3918), (0.221, 0.4104),
           (0.39, 0.4201), (1, 0.4169)]
    calls = []
    monkeypatch.setattr(cp, "pack_grains", _fake(lambda lam: float(np.interp(lam, *zip(*pts))),
                                                 calls))
    box = Container("box", (0.01, 0.01), 0.01)
    for target in np.arange(0.357, 0.4219, 0.0025):   # the range 0.3616-0.4169 +- 0.005
        calls.clear()
        out = pack_grains_to_porosity(box, sphere_template(0.001), porosity=float(target))
        assert abs(out[4]["porosity_network_region"] - target) <= 0.005
        assert len(calls) - 3 <= 6, (target, calls)


def test_bad_requests():
    box = Container("box", (0.01, 0.01), 0.01)
    with pytest.raises(ValueError, match="porosity must be in"):
        pack_grains_to_porosity(box, sphere_template(0.001), porosity=1.2)
    with pytest.raises(ValueError, match="max packings >= 1"):
        pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.4, max_packings=0)
    with pytest.raises(ValueError, match="deposition friction"):
        cp.pack_grains(box, sphere_template(0.001), deposition_friction=-0.1)


@pytest.mark.slow
def test_grain_bed_not_at_equilibrium_exits_1(tmp_path, capsys):
    """dem.pack --grain marks a bed whose settle stage hit the step limit as it does spheres:
    written with "converged": false, one error line, exit 1 (141 one-sphere grains, 0.8 s)."""
    import json
    from dem.pack import main
    tpl = tmp_path / "one.csv"
    tpl.write_text("x,y,z,r\n0,0,0,1\n")
    out = tmp_path / "bed.csv"
    assert main(["--scene", "box", "--size", "0.01", "0.01", "--height", "0.01", "--grain",
                 str(tpl), "--fill", "grow", "--max-steps", "200", "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: not at equilibrium"), err
    s = json.loads(out.with_suffix(".json").read_text())
    assert s["converged"] is False and s["stages"]["settle"]["steps"] == 200


def test_search_passes_over_a_bed_not_at_equilibrium(monkeypatch):
    """A bed within the tolerance whose settle stage did not converge (here the range's bed at
    lever 0, 0.400 for 0.401 +- 0.002) is not the answer: the search packs others (the same
    lever would give the same bed) until one at equilibrium lands (0.2: 0.404, 0.05: 0.401)."""
    calls = []
    law = _fake(lambda lam: 0.38 + 0.02 * (lam + 1), calls)

    def pack(*a, **kw):
        out = law(*a, **kw)
        out[4]["stages"] = {"settle": {"converged": abs(calls[-1]) > 1e-6}}
        return out
    monkeypatch.setattr(cp, "pack_grains", pack)
    box = Container("box", (0.01, 0.01), 0.01)
    out = pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.401, porosity_tol=0.002)
    assert calls == pytest.approx([-1.0, 0.0, 1.0, 0.2, 0.05])
    assert out[4]["stages"]["settle"]["converged"] and out[4]["procedure_lever"] == 0.05
    assert abs(out[4]["porosity_network_region"] - 0.401) <= 0.002


def test_grain_count_and_range_do_not_depend_on_the_request(monkeypatch, tmp_path):
    """The grain count is the grain's (soybean: from its loose-fill middle 0.40985), whatever the
    request: 0.30, 0.405 and 0.55 pack the same range beds, and the range is quoted the same.
    With an integer seed the beds are packed once and read from the cache after (no packing)."""
    monkeypatch.setenv("GRAINFLOW_REACH_CACHE", str(tmp_path))
    calls, counts = [], []
    law = _fake(lambda lam: 0.38 + 0.02 * (lam + 1), calls)

    def pack(container, template, *, n_grains, porosity, **kw):
        counts.append((n_grains, porosity))
        return law(container, template, porosity=porosity, **kw)
    monkeypatch.setattr(cp, "pack_grains", pack)
    from dem.templates import resolve_template
    box, soy = Container("box", (0.04, 0.04), 0.04), resolve_template("soybean")
    n = int((1 - 0.40985) * 0.04**3 / soy.volume_m3)
    assert grain_count(box, soy)[:2] == (n, 0.40985)
    quoted = []
    for target in (0.30, 0.405, 0.55):
        try:
            out = pack_grains_to_porosity(box, soy, porosity=target, rng=1)
            quoted.append(out[4]["porosity_search"]["reachable_text"])
        except ValueError as e:
            quoted.append(str(e).split("in this container: ")[1])
    assert len(set(quoted)) == 1 and quoted[0].startswith("0.3800-0.4200 (the beds dem.pack "
                                                          "--porosity made in the 0.04 x 0.04 x "
                                                          f"0.04 m box, seed 1, {n} grains at "
                                                          f"levers -1, 0, +1, {tmp_path}")
    assert calls[:3] == [-1.0, 0.0, 1.0] and -1.0 not in calls[3:] and 1.0 not in calls[3:]
    assert set(counts) == {(n, 0.40985)}
    assert len(list(tmp_path.glob("soybean-*.json"))) == 1
    calls.clear()                               # no seed: nothing cached, the range packed again
    with pytest.raises(ValueError, match="0.3800-0.4200"):
        pack_grains_to_porosity(box, soy, porosity=0.55)
    assert calls == [-1.0, 0.0, 1.0]


def test_an_empty_network_region_is_named_not_nan(monkeypatch):
    monkeypatch.setattr(cp, "pack_grains", _fake(lambda lam: float("nan"), []))
    box = Container("box", (0.01, 0.01), 0.01)
    with pytest.raises(ValueError, match=r"network's sample region .* is empty .*porosity nan "
                                         r"at lever -1, nan at lever 0, nan at lever \+1\): give "
                                         r"a larger container"):
        pack_grains_to_porosity(box, sphere_template(0.001), porosity=0.9)


def test_pack_cli_unreachable_porosity_exits_2(tmp_path, monkeypatch, capsys):
    """dem.pack --grain --porosity 0.45 beyond what the range's beds reach in a container
    without a recorded range: exit 2 with the reachable range, nothing written."""
    monkeypatch.setenv("GRAINFLOW_REACH_CACHE", str(tmp_path / "reach"))
    monkeypatch.setattr(cp, "pack_grains", _fake(lambda lam: 0.32 + 0.04 * (lam + 1), []))
    from dem.pack import main
    out = tmp_path / "g.csv"
    assert main(["--scene", "box", "--size", "0.08", "0.08", "--height", "0.05", "--grain",
                 "soybean", "--porosity", "0.45", "--out", str(out), "--quiet"]) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if not ln.startswith("[range]")]
    assert len(err) == 1 and err[0].startswith("error: porosity 0.45 is outside what dem.pack "
                                               "reaches for soybean in this container: "), err
    assert "0.3200-0.4000" in err[0]
    assert [p.name for p in tmp_path.iterdir()] == ["reach"]


@pytest.mark.slow
def test_one_range_per_grain_container_and_seed(tmp_path, monkeypatch, capsys):
    """Real beds: soybean in a 0.04 m box, seed 1 (253 grains, a bed in seconds). --porosity
    0.45 packs the range's three beds and exits 2 quoting it (0.3616-0.4169 on one x86-64
    host); 0.44 exits 2 with the same words from the cache, nothing packed; 0.40 packs inside
    the range only (no range bed again) and its JSON quotes the same range."""
    import json
    import re
    from dem.pack import main
    monkeypatch.setenv("GRAINFLOW_REACH_CACHE", str(tmp_path / "reach"))
    real, levers = cp.pack_grains, []

    def counted(*a, deposition_friction, lid_headroom, **kw):
        levers.append(deposition_friction if deposition_friction > 0 else lid_headroom / 0.3 - 1)
        return real(*a, deposition_friction=deposition_friction, lid_headroom=lid_headroom, **kw)
    monkeypatch.setattr(cp, "pack_grains", counted)
    box = ["--scene", "box", "--size", "0.04", "0.04", "--height", "0.04", "--grain", "soybean",
           "--quiet"]
    quoted = []
    for p in ("0.45", "0.44"):
        assert main(box + ["--porosity", p, "--out", str(tmp_path / "b.csv")]) == 2
        err = [ln for ln in capsys.readouterr().err.splitlines() if not ln.startswith("[")]
        assert len(err) == 1 and err[0].startswith(f"error: porosity {p} is outside what dem.pack "
                                                   "reaches for soybean in this container: "), err
        quoted.append(err[0].split("in this container: ")[1])
        assert levers == ([-1.0, 0.0, 1.0] if p == "0.45" else []), levers
        levers.clear()
    assert quoted[0] == quoted[1]
    lo, hi = map(float, re.match(r"(\d\.\d{4})-(\d\.\d{4}) \(the beds dem.pack --porosity made in "
                                 r"the 0.04 x 0.04 x 0.04 m box, seed 1, 253 grains at levers "
                                 r"-1, 0, \+1, ", quoted[0]).groups())
    assert 0.34 < lo < 0.38 and 0.40 < hi < 0.44 and hi + 0.005 < 0.44
    assert not (tmp_path / "b.csv").exists()
    assert main(box + ["--porosity", "0.40", "--out", str(tmp_path / "b.csv")]) == 0
    s = json.loads((tmp_path / "b.json").read_text())
    ps = s["porosity_search"]
    assert ps["reachable"] == [lo, hi] or ps["reachable"] == pytest.approx([lo, hi], abs=5e-5)
    assert ps["reachable_text"] == quoted[0] and s["n_grains"] == ps["n_grains"] == 253
    assert abs(s["porosity_network_region"] - 0.40) <= 0.005 and s["converged"]
    assert [t["lever"] for t in ps["tried"]] == pytest.approx(levers) and len(levers) <= 6


def test_bundled_box_searches_from_its_record(tmp_path, monkeypatch, capsys):
    """In the bundled soybean box with seed 1 the bundled JSON's record is the range (its beds:
    lever -1 0.3490, +1 0.4114, the same 495 grains the grain's own count gives): nothing is
    packed for the range, the search starts inside it, and the bed's JSON quotes that record."""
    import json
    from dem.pack import main
    monkeypatch.setenv("GRAINFLOW_REACH_CACHE", str(tmp_path / "reach"))
    calls, counts = [], []
    law = _fake(lambda lam: 0.3490 + 0.0312 * (lam + 1), calls)

    def pack(container, template, *, n_grains, **kw):
        counts.append(n_grains)
        out = law(container, template, **kw)
        out[4].update(stages={"settle": {"converged": True, "steps": 1}}, n_grains=n_grains,
                      n_spheres=6 * n_grains, porosity_interior_union=0.4,
                      porosity_interior_error=0.001, deposition_friction=0.0, steps=1)
        return out
    monkeypatch.setattr(cp, "pack_grains", pack)
    monkeypatch.setattr("dem.pack.write_grain_packing",
                        lambda path, *a: Path(path).with_suffix(".json").write_text(
                            json.dumps(a[-1], default=str)))
    out = tmp_path / "b.csv"
    assert main(["--scene", "box", "--size", "0.05", "0.05", "--height", "0.05", "--grain",
                 "soybean", "--porosity", "0.40", "--out", str(out), "--quiet"]) == 0
    ps = json.loads(out.with_suffix(".json").read_text())["porosity_search"]
    assert calls and not {-1.0, 0.0, 1.0} & set(calls) and set(counts) == {495}
    assert ps["reachable"] == pytest.approx([0.349029541015625, 0.411376953125])
    assert ps["reachable_text"].startswith("0.3490-0.4114 (the beds dem.pack --porosity made in "
                                           "the 0.05 x 0.05 x 0.05 m box, seed 1, network/data/"
                                           "soybean_grains.json;")
    assert not (tmp_path / "reach").exists()
