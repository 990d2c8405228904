"""Batches on a real Dask LocalCluster (2 worker processes on loopback) against single-machine runs."""

import math
import shutil

import pytest

import gpsrx
import gpsrx.batch
from conftest import RUN_OPTIONS, simulate

distributed = pytest.importorskip("distributed")
pd = pytest.importorskip("pandas")

# Columns that depend on the machine, not on the result.
VOLATILE = {"wall_s"}


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
    )
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


@pytest.fixture(scope="module")
def manifest(tmp_path_factory, sim):
    """4 recordings: the shared one, two more seeds (6 s), and a corrupt copy: its data cut to
    0.1 s and its SigMF metadata cut in the middle of the JSON."""
    d = tmp_path_factory.mktemp("batch")
    recs = [("shared", sim)]
    for seed in (8, 9):
        recs.append((f"seed{seed}", simulate(d / f"seed{seed}", duration_s=6.0, seed=seed)))
    (d / "corrupt").mkdir()
    corrupt = d / "corrupt" / "signal.ci8"
    with open(sim["data_path"], "rb") as src:
        corrupt.write_bytes(src.read(int(0.1 * sim["fs_hz"]) * 2 + 1))
    meta = open(sim["meta_path"]).read()
    (d / "corrupt" / "signal.sigmf-meta").write_text(meta[: len(meta) // 2])
    lines = ["name,path,format,fs_hz,nav,approx_llh"]
    llh = '"[36.4, 127.4, 0.0]"'
    for name, rep in recs:
        lines.append(f"{name},{rep['data_path']},,,{RUN_OPTIONS['nav']},{llh}")
    lines.append(f"corrupt,{corrupt},,,{RUN_OPTIONS['nav']},{llh}")
    path = d / "manifest.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


def comparable(row):
    return {k: v for k, v in row.items() if k not in VOLATILE and k != "kind"}


def missing(v):
    """None (JSON null: a NaN of the library) or NaN (pandas' missing value)."""
    return v is None or (isinstance(v, float) and math.isnan(v))


def same(a, b):
    assert a.keys() == b.keys(), (a.keys(), b.keys())
    for k in a:
        x, y = a[k], b[k]
        if missing(x) or missing(y):
            assert missing(x) and missing(y), (k, x, y)
        else:
            assert x == y, (k, x, y)


def test_a_batch_of_recordings_on_dask_equals_the_single_machine_runs(client, manifest, tmp_path):
    frame = gpsrx.batch.run(manifest, client, out_dir=tmp_path / "dask")
    assert list(frame["name"]) == ["shared", "seed8", "seed9", "corrupt"]
    assert list(frame["status"][:3]) == ["ok", "ok", "ok"]
    # The corrupt recording is reported, with the reader's reason, and stops nothing.
    bad = frame.set_index("name").loc["corrupt"]
    assert bad["status"] == "error"
    assert "sigmf-meta" in bad["message"], bad["message"]
    # The same recordings processed here, one after another.
    specs = gpsrx.read_manifest(manifest)["recordings"]
    local = [gpsrx.process_recording(s, tmp_path / "local") for s in specs]
    records = frame.to_dict("records")
    for row, mine in zip(records, local):
        same(comparable({k: row[k] for k in mine}), comparable(mine))
    # Each recording's files were written by its worker.
    assert (tmp_path / "dask" / "shared" / "pvt.csv").stat().st_size > 0


def test_a_missing_recording_is_reported_not_fatal(client, sim, tmp_path):
    recs = [
        dict(path=sim["data_path"], nav=RUN_OPTIONS["nav"], options={"approx_llh": RUN_OPTIONS["approx_llh"]}),
        dict(path=str(tmp_path / "missing.ci8"), format="ci8", fs_hz=2.048e6),
    ]
    frame = gpsrx.batch.run_recordings(recs, client, out_dir=tmp_path)
    assert list(frame["status"]) == ["ok", "error"]
    assert "does not exist" in frame["message"][1]


def test_a_20_case_study_grid_on_dask_equals_the_cases_run_here(client):
    frame = gpsrx.batch.run_study(client, "steady-state", cases=(0, 20), chunk=4)
    assert len(frame) == 20
    assert list(frame["case"]) == list(range(20))
    assert set(frame["status"]) == {"ok"}
    for row in frame.to_dict("records"):
        mine = gpsrx.run_study_case(row["case"], study="steady-state")
        same({k: row[k] for k in mine}, mine)
    # The measured steady-state errors agree with the closed forms (seed 004 Table 1).
    assert frame["agree"].all()


def test_gpsrx_batch_cli_writes_the_same_summary(manifest, tmp_path):
    exe = shutil.which("gpsrx")
    if exe is None:
        pytest.skip("the gpsrx binary is not on PATH")
    import subprocess

    out = tmp_path / "cli"
    p = subprocess.run([exe, "batch", str(manifest), "--out", str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    summary = pd.read_csv(out / "summary.csv")
    assert list(summary["status"]) == ["ok", "ok", "ok", "error"]
    assert "1 failed" in p.stdout
