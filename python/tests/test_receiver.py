"""The receiver from Python against the simulator's truth."""

import numpy as np
import pytest

import gpsrx
from conftest import RUN_OPTIONS


def read_ci8(path):
    """The ci8 recording as complex64, as the receiver's source reads it (no scaling)."""
    raw = np.fromfile(path, dtype=np.int8).astype(np.float32)
    return (raw[0::2] + 1j * raw[1::2]).astype(np.complex64)


def test_run_fixes_land_on_the_truth(sim, truth, run_result):
    s = run_result["summary"]
    simulated = sorted(p for p, _, _ in sim["satellites"])
    # Every simulated satellite is at 40 dB-Hz or more: all are tracked, no other.
    assert s["tracked_prns"] == simulated
    assert s["fixes"] >= 80, s  # 10 Hz from about 1 s on
    assert s["first_fix_s"] < 2.0, s
    errors = gpsrx.fix_errors_m(run_result["fixes"], truth)
    # Code tracking noise at 40-46 dB-Hz (~1 m per pseudorange, DLL 2 Hz, d = 1 chip) times
    # PDOP ~2: metres, not tens of metres.
    assert np.median(errors) < 3.0, np.median(errors)
    assert errors.max() < 10.0, errors.max()
    assert set(run_result["fixes"]["quality"]) == {"gnss"}


def test_push_in_chunks_gives_the_fixes_of_run(sim, run_result):
    samples = read_ci8(sim["data_path"])
    # A pushed stream has no metadata: the start time the SigMF core:datetime gives run().
    start = {"week": 2190, "tow_s": 538194.0}
    rx = gpsrx.Receiver(fs_hz=sim["fs_hz"], approx_time=start, **RUN_OPTIONS)
    rng = np.random.default_rng(3)
    fixes = []
    i = 0
    while i < len(samples):
        n = int(rng.integers(1, 400_000))
        out = rx.push(samples[i : i + n])
        fixes.append(out["fixes"])
        i += n
    end = rx.finish()
    fixes.append(end["fixes"])
    pushed = {k: np.concatenate([np.asarray(f[k]) for f in fixes]) for k in ("t_stream_s", "x_m", "y_m", "z_m")}
    ran = run_result["fixes"]
    assert len(pushed["x_m"]) == len(ran["x_m"]) > 0
    # The fixes come at the same times. run() reads the ci8 file as stored, and its channels
    # correlate it with the int16 kernel (carrier rounded to 2^-7 of a sample); pushed complex
    # floats go through the f32 kernel: the same fixes to centimetres (25 cm allowed: the
    # first fixes are single epochs), far below their metre-level noise.
    np.testing.assert_array_equal(pushed["t_stream_s"], ran["t_stream_s"])
    for k in ("x_m", "y_m", "z_m"):
        np.testing.assert_allclose(pushed[k], ran[k], rtol=0, atol=0.25)
    assert end["summary"]["fixes"] == run_result["summary"]["fixes"]
    with pytest.raises(gpsrx.Error, match="the stream has ended"):
        rx.push(samples[:10])


def test_acquire_finds_the_simulated_prns(sim):
    samples = read_ci8(sim["data_path"])[: int(0.02 * sim["fs_hz"])]
    found = gpsrx.acquire(samples, sim["fs_hz"], coherent_ms=1, noncoherent=10)
    assert len(found) == 32
    detected = sorted(r["prn"] for r in found if r["detected"])
    assert detected == sorted(p for p, _, _ in sim["satellites"])
    # The Doppler of each detection within one bin (1/(2 T) = 500 Hz at 1 ms) of the truth.
    truth_sv = np.genfromtxt(sim["truth_sv_path"], delimiter=",", names=True)
    for r in found:
        if r["detected"]:
            rows = truth_sv[(truth_sv["prn"] == r["prn"]) & (truth_sv["t_s"] == 0.0)]
            assert abs(r["doppler_hz"] - rows["doppler_hz"][0]) < 250.0, r


def test_errors_are_python_exceptions_with_the_cli_messages(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        gpsrx.run(tmp_path / "missing.bin", format="ci8", fs_hz=2.048e6)
    with pytest.raises(ValueError, match="sampling rate -1"):
        gpsrx.Receiver(fs_hz=-1.0)
    with pytest.raises(ValueError, match="rate_hzz"):
        gpsrx.Receiver(fs_hz=2.048e6, rate_hzz=1)
    with pytest.raises(ValueError, match="rate 500 Hz: use 1 to 50 Hz"):
        gpsrx.Receiver(fs_hz=2.048e6, rate_hz=500)
    with pytest.raises(ValueError, match="format"):
        gpsrx.run(tmp_path / "x.bin", format="ci9", fs_hz=2.048e6)
    with pytest.raises(FileNotFoundError, match="scenario"):
        gpsrx.simulate(tmp_path / "none.toml", tmp_path)
    with pytest.raises(ValueError, match="PRN 33"):
        gpsrx.acquire(np.zeros(4096, np.complex64), 2.048e6, prns=[33])
    with pytest.raises(ValueError):
        gpsrx.acquire(np.zeros(10, np.complex64), 2.048e6)
