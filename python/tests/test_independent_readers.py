"""Independent programs read what gpsrx writes: sigmf-python the simulator's recordings,
pynmea2 every NMEA sentence of a run."""

import math
import os

import numpy as np
import pynmea2
import sigmf

import gpsrx
from conftest import RUN_OPTIONS


def test_sigmf_python_reads_the_simulators_recording(sim):
    meta_path = os.path.splitext(sim["data_path"])[0] + ".sigmf-meta"
    handle = sigmf.sigmffile.fromfile(meta_path)
    assert handle.get_global_field("core:datatype") == "ci8"
    assert handle.get_global_field("core:sample_rate") == 2.048e6
    capture = handle.get_captures()[0]
    # The scenario's start (week 2190, TOW 538194 s) in UTC: 18 leap seconds earlier.
    assert capture["core:datetime"].startswith("2022-01-01T05:29:36")
    assert capture["core:frequency"] == 1575.42e6
    samples = handle.read_samples(0, 1000)
    raw = np.fromfile(sim["data_path"], dtype=np.int8, count=2000).astype(np.float64)
    # sigmf-python scales int8 by 1/128.
    assert np.allclose(samples.real, raw[0::2] / 128.0)
    assert np.allclose(samples.imag, raw[1::2] / 128.0)
    assert handle.sample_count == os.path.getsize(sim["data_path"]) // 2


def test_pynmea2_parses_every_sentence_and_the_fixes_land_on_the_truth(sim, truth, tmp_path):
    gpsrx.run(sim["data_path"], out=str(tmp_path), **RUN_OPTIONS)
    lines = (tmp_path / "pvt.nmea").read_text().splitlines()
    assert len(lines) > 50
    kinds = set()
    lat0, lon0 = 36.3721, 127.3604
    for line in lines:
        msg = pynmea2.parse(line, check=True)
        kinds.add(msg.sentence_type)
        if msg.sentence_type == "GGA" and int(msg.gps_qual) > 0:
            # Within 20 m of the antenna (1e-4 deg of latitude is 11 m).
            north_m = (msg.latitude - lat0) * 111_320.0
            east_m = (msg.longitude - lon0) * 111_320.0 * math.cos(math.radians(lat0))
            assert math.hypot(north_m, east_m) < 20.0, line
    assert {"GGA", "RMC", "GSA", "GSV", "GST", "ZDA"} <= kinds, kinds


def test_gpxpy_reads_the_track_of_a_run(sim, tmp_path):
    import gpxpy

    result = gpsrx.run(sim["data_path"], out=str(tmp_path), **RUN_OPTIONS)
    with open(tmp_path / "track.gpx") as f:
        gpx = gpxpy.parse(f)
    points = gpx.tracks[0].segments[0].points
    valid = [q for q in result["fixes"]["quality"] if q != "none"]
    assert len(points) == len(valid) > 50
    lat0, lon0 = 36.3721, 127.3604
    for p in points:
        north_m = (p.latitude - lat0) * 111_320.0
        east_m = (p.longitude - lon0) * 111_320.0 * math.cos(math.radians(lat0))
        assert math.hypot(north_m, east_m) < 20.0
        assert p.type_of_gpx_fix == "3d" and p.satellites >= 4
        assert p.time is not None and p.time.year == 2022
