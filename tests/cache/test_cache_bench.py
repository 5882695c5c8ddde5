"""cache.bench: a small fast run (6 held-out throats, 2000-row throughput batch) writes the JSON
and prints the tables it promises; the held-out FE reference is reused from ``--reference``."""

import pytest
import json

import numpy as np

from cache import bench


@pytest.mark.slow
def test_bench_small_run_writes_json_and_table(tmp_path, capsys):
    out, ref = tmp_path / "b.json", tmp_path / "ref.npz"
    argv = ["--db", str(tmp_path / "none.sqlite"), "--n-fe", "6", "--n-batch", "2000",
            "--repeat", "1", "--rtols", "1e-2", "--reference", str(ref), "--out", str(out),
            "--n-extension", "8"]
    assert bench.main(argv) == 0
    text = capsys.readouterr().out
    data = json.loads(out.read_text())
    assert {"timestamp", "platform", "python", "cpu_count", "loadavg_start", "loadavg_end",
            "solver_version", "seed"} <= set(data)
    assert data["n_heldout"] == 6 and ref.exists()
    # the shipped g1 table covers packing throats, and its estimate bounds the error
    g1 = data["tables"]["g1 (shipped) curvature"]
    assert g1["nodes"] == 25**3 * 5**2 and g1["coverage"] == 1.0
    assert g1["estimate_bounds_error"] == 1.0 and g1["error_all"]["median"] < 3e-3
    methods = {p["method"]: p for p in data["policies"]}
    assert set(methods) == {"shape-factor", "table-only [g1 (shipped)]",
                            "table+fe rtol=0.01 [g1 (shipped)]", "fe-only (FE rtol=1e-3)"}
    assert methods["fe-only (FE rtol=1e-3)"]["fraction_fe_or_sf"] == 1.0
    assert methods["table-only [g1 (shipped)]"]["fraction_fe_or_sf"] == 0.0
    assert methods["fe-only (FE rtol=1e-3)"]["error"]["max"] < 1e-3   # FE 1e-3 vs FE 1e-4
    for key in ("throughput_table_only", "throughput_interp_kernel", "throughput_shape_factor"):
        assert data[key]["n"] == 2000 and data[key]["rows_per_s_cpu_best"] > 0
    # the extension grids on shapes the tables before them cannot serve: they serve them, the
    # estimate is far off
    for name in ("x1", "d1"):
        ext = data["extension"][name]
        assert ext["n"] >= 6 and ext["served"] >= 3 and ext["table"]["median"] < 2e-2
        assert ext["shape_factor"]["median"] > 0.1 and f"extension grid {name}" in text
    # every row of the JSON is in the printed tables
    for name in list(data["tables"]) + list(methods):
        assert name in text
    assert "held-out throats: 6" in text and f"wrote {out}" in text
    # a second run reuses the reference (same held-out Q*, same errors)
    assert bench.main(argv) == 0
    again = json.loads(out.read_text())
    assert np.isclose(again["tables"]["g1 (shipped) curvature"]["error_all"]["median"],
                      g1["error_all"]["median"], rtol=0, atol=0)
