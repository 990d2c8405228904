"""Snapshot sets from Python (``gpsrx.snapshot``, ``gpsrx.batch.run_snapshots``) against the
simulator's truth: three 12 ms snapshots of 1-bit real samples at 4.092 MHz (as SnapperGPS
records them, with an IF of 1.3 MHz) in one SigMF recording with one capture per snapshot,
the device clock 2 s off and the a-priori position 30 km off; and the shared SnapperGPS walk
against its RTK truth (skipped when ../shared/data is absent, unless CI=true)."""

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

import gpsrx

# Daejeon, static; 12 ms per snapshot; the snapshots 20 s apart.
LLH = (36.3721, 127.3604, 80.0)
START_TOW_S = 538194.0
SPACING_S = 20.0
SCENARIO = """
description = "pytest: snapshot {k}"
duration_s = 0.012
seed = {seed}
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = {tow}
[output]
format = "ri1_lsb"
fs_hz = 4.092e6
if_hz = 1.3e6
[receiver]
kind = "static"
llh_deg = [{lat}, {lon}, {h}]
[satellites]
cn0_all_dbhz = 45.0
[atmosphere]
ionosphere = true
troposphere = true
"""
CLOCK_ERROR_S = 2.0
# 30 km north-east (0.19 deg of latitude, 0.24 deg of longitude), at the right height.
APRIORI = [LLH[0] + 0.19, LLH[1] + 0.24, LLH[2]]
NAV = "builtin:brdc0010.22n"


def iso_plus(text, seconds):
    """An ISO 8601 UTC time moved by ``seconds`` (whole seconds here)."""
    from datetime import datetime, timedelta, timezone

    t = datetime.strptime(text.rstrip("Z")[:19], "%Y-%m-%dT%H:%M:%S").replace(tzinfo=timezone.utc)
    frac = text.rstrip("Z")[19:]
    return (t + timedelta(seconds=seconds)).strftime("%Y-%m-%dT%H:%M:%S") + frac + "Z"


@pytest.fixture(scope="module")
def snapshot_set(tmp_path_factory):
    """The three snapshots joined into one SigMF recording, each capture's core:datetime the
    simulated time plus CLOCK_ERROR_S; returns (meta path, truth rows)."""
    d = tmp_path_factory.mktemp("snapshots")
    data = bytearray()
    captures = []
    truths = []
    meta = None
    for k in range(3):
        rep = gpsrx.simulate(
            SCENARIO.format(k=k, seed=40 + k, tow=START_TOW_S + k * SPACING_S, lat=LLH[0], lon=LLH[1], h=LLH[2]),
            str(d / f"sim{k}"),
        )
        raw = Path(rep["data_path"]).read_bytes()
        meta = json.loads(Path(rep["meta_path"]).read_text())
        # 12 ms of 1-bit samples at 4.092 MHz: 49104 samples, 6138 bytes exactly.
        assert len(raw) == 6138
        captures.append(
            {
                "core:sample_start": len(data) * 8,
                "core:datetime": iso_plus(meta["captures"][0]["core:datetime"], CLOCK_ERROR_S),
            }
        )
        data += raw
        truths.append(gpsrx.read_truth(rep["truth_path"]))
    (d / "set.sigmf-data").write_bytes(bytes(data))
    meta["global"].pop("core:dataset", None)
    meta["captures"] = captures
    path = d / "set.sigmf-meta"
    path.write_text(json.dumps(meta))
    return path, truths


def horizontal_error_m(lat_deg, lon_deg, x, y, z, truth):
    """Distance in the horizontal plane at the truth between ECEF (x, y, z) and the truth's
    first position (the receiver is static)."""
    lat, lon = math.radians(truth["lat_deg"][0]), math.radians(truth["lon_deg"][0])
    d = np.array([x - truth["x_m"][0], y - truth["y_m"][0], z - truth["z_m"][0]])
    east = np.array([-math.sin(lon), math.cos(lon), 0.0])
    north = np.array([-math.sin(lat) * math.cos(lon), -math.sin(lat) * math.sin(lon), math.cos(lat)])
    return math.hypot(d @ east, d @ north)


def test_a_sigmf_snapshot_set_is_positioned_against_the_simulator_truth(snapshot_set, tmp_path):
    path, truths = snapshot_set
    result = gpsrx.snapshot(path, NAV, APRIORI, out=tmp_path / "out")
    rows = result["snapshots"]
    assert list(rows["index"]) == [0, 1, 2]
    assert list(rows["quality"]) == ["fix"] * 3, rows["reason"]
    for k in range(3):
        e = horizontal_error_m(rows["lat_deg"][k], rows["lon_deg"][k], rows["x_m"][k], rows["y_m"][k], rows["z_m"][k], truths[k])
        # 1-bit samples at 4 samples a chip, 45 dB-Hz, 6+ satellites: the code phase to a few
        # metres, the fix to tens of metres at most (30 km a-priori error).
        print(f"snapshot {k}: {e:.1f} m, {rows['n_sv'][k]} satellites")
        assert e < 40.0, (k, e)
        assert rows["n_sv"][k] >= 6
        # The device clock was 2 s ahead: the correction finds it. One 12 ms snapshot sees the
        # time only through the satellites' range rates (up to ~800 m/s: 10 ms is 8 m of
        # range), so to tens of ms (measured: 1, 61, 28 ms); 3 snapshots are too few for the
        # sequence's clock (5 needed).
        assert abs(rows["time_correction_s"][k] + CLOCK_ERROR_S) < 0.15, rows["time_correction_s"]
        # The row's GPS time is the simulated time of the first sample, to the same.
        assert rows["week"][k] == 2190
        assert abs(rows["tow_s"][k] - truths[k]["tow_s"][0]) < 0.15
    s = result["summary"]
    assert (s["kind"], s["status"], s["fixes"], s["snapshots"]) == ("snapshots", "ok", 3, 3)
    assert (tmp_path / "out" / "snapshots.csv").is_file()


def test_the_library_error_against_a_truth_matches_the_independent_one(snapshot_set):
    path, truths = snapshot_set
    t = truths[0]
    truth_ecef = [float(t["x_m"][0]), float(t["y_m"][0]), float(t["z_m"][0])]
    rows = gpsrx.snapshot(path, NAV, APRIORI, truth_ecef_m=truth_ecef)["snapshots"]
    mine = horizontal_error_m(rows["lat_deg"][0], rows["lon_deg"][0], rows["x_m"][0], rows["y_m"][0], rows["z_m"][0], t)
    assert abs(rows["h_error_m"][0] - mine) < 0.01, (rows["h_error_m"][0], mine)


def test_snapshot_errors_are_python_exceptions(snapshot_set, tmp_path):
    path, _ = snapshot_set
    with pytest.raises(FileNotFoundError, match="missing.json"):
        gpsrx.snapshot(tmp_path / "missing.json", NAV, APRIORI)
    with pytest.raises(FileNotFoundError, match="nowhere.nav"):
        gpsrx.snapshot(path, tmp_path / "nowhere.nav", APRIORI)
    with pytest.raises(ValueError, match="no navigation data"):
        gpsrx.snapshot(path, None, APRIORI)
    with pytest.raises(ValueError, match="latitude"):
        gpsrx.snapshot(path, NAV, [95.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="WEEK:TOW"):
        gpsrx.snapshot(path, NAV, APRIORI, time="2190")
    with pytest.raises(ValueError, match="height_sigma"):
        gpsrx.snapshot(path, NAV, APRIORI, height_sigma=3.0)


def test_a_snapshot_set_on_dask_equals_the_task_run_here(snapshot_set, tmp_path):
    distributed = pytest.importorskip("distributed")
    pytest.importorskip("pandas")
    import gpsrx.batch

    path, _ = snapshot_set
    sets = [
        {"name": "sim", "path": path, "nav": NAV, "approx_llh": APRIORI},
        {"name": "missing", "path": tmp_path / "missing.json", "nav": NAV, "approx_llh": APRIORI},
    ]
    cluster = distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    )
    with distributed.Client(cluster) as client:
        frame = gpsrx.batch.run_snapshots(sets, client, out_dir=tmp_path / "dask")
    cluster.close()
    assert list(frame["kind"]) == ["snapshots", "snapshots"]
    assert list(frame["status"]) == ["ok", "error"]
    assert "missing.json" in frame["message"][1]
    mine = gpsrx.process_snapshots(dict(sets[0], path=str(path)), tmp_path / "local")
    row = frame.to_dict("records")[0]
    for k in ("fixes", "snapshots", "tracked_prns", "mean_lat_deg", "mean_lon_deg"):
        assert row[k] == mine[k], (k, row[k], mine[k])
    assert (tmp_path / "dask" / "sim" / "snapshots.csv").is_file()


def shared(name):
    p = Path(__file__).resolve().parents[3] / "shared" / "data" / "real" / "snapshots" / name
    if p.is_file():
        return p
    if os.environ.get("CI") == "true":
        pytest.fail(f"shared test data {p} is missing, and CI=true requires it")
    pytest.skip(f"shared test data {p} is absent")


def test_the_snappergps_walk_against_its_rtk_truth():
    walk = shared("snappergps_w00_first60.json")
    nav = shared("snappergps_w00.nav")
    truth = shared("snappergps_w00_first60_truth.json")
    result = gpsrx.snapshot(walk, nav, [52.03, -1.2574, 112.0], truth=truth, truth_h_m=112.4)
    s = result["summary"]
    rows = result["snapshots"]
    assert len(rows["index"]) == 60
    # The regression bounds of scripts/snapshot-check.sh (each snapshot alone).
    assert s["fixes"] >= 54, s
    assert s["h_error_median_m"] <= 17.0 and s["h_error_p95_m"] <= 30.0, s
    # The median from the rows (the library scores the `fix` rows against the RTK truth).
    fixes = np.array([q == "fix" for q in rows["quality"]])
    assert abs(np.median(rows["h_error_m"][fixes]) - s["h_error_median_m"]) < 1e-9
