"""Batches of recordings and study grids on a Dask cluster.

:func:`run` submits one task per recording and per snapshot set (``[[snapshots]]``) of a
manifest (TOML or CSV, as ``gpsrx batch`` reads it) and, for each ``[[study]]`` grid, one task
per chunk of cases, to a
``dask.distributed.Client``; results and failures come back as one ``pandas.DataFrame``. A
recording that cannot be processed (missing, truncated, a bad option) is a row with
``status == "error"`` and its ``message``; so is a task whose worker died. Nothing here
schedules work: Dask does, on whatever cluster the client is connected to (a ``LocalCluster``,
Slurm/PBS through dask-jobqueue, Kubernetes through dask-kubernetes).

Each row has ``kind`` (``recording``, ``snapshots`` or ``study``), ``name``, ``status`` (``ok``, ``no_fix``,
``error``) and ``message``, then the columns of its kind (NaN where a column is another
kind's).
"""

import os
import tempfile

from . import _gpsrx

__all__ = [
    "run",
    "run_recordings",
    "run_snapshots",
    "run_study",
    "recording_task",
    "snapshots_task",
    "study_task",
]


def recording_task(spec, out_root):
    """One recording (a spec dict of :func:`gpsrx.read_manifest`) into ``out_root/NAME/``."""
    row = _gpsrx.process_recording(spec, out_root)
    row["kind"] = "recording"
    return row


def snapshots_task(spec, out_root):
    """One snapshot set (a spec dict: the keys of :func:`gpsrx.snapshot`) into ``out_root/NAME/``."""
    row = _gpsrx.process_snapshots(spec, out_root)
    row["kind"] = "snapshots"
    return row


def study_task(study, quick, indices):
    """Cases ``indices`` of a study grid; a case that fails is a row with its error."""
    rows = []
    for i in indices:
        try:
            row = _gpsrx.run_study_case(i, study=study, quick=quick)
            row.update(status="ok", message="")
        except Exception as e:  # one bad case must not lose the others
            row = {"study": study, "case": i, "status": "error", "message": str(e)}
        row["kind"] = "study"
        row["name"] = f"{study}/{i}"
        rows.append(row)
    return rows


def _manifest(manifest):
    if isinstance(manifest, dict):
        return {
            "recordings": manifest.get("recordings", []),
            "snapshots": manifest.get("snapshots", []),
            "studies": manifest.get("studies", []),
        }
    return _gpsrx.read_manifest(os.fspath(manifest))


def _chunks(study):
    cases = study.get("cases")
    if cases is None:
        n = len(_gpsrx.study_cases(study["name"], quick=study.get("quick", False)))
        cases = [0, n]
    start, end = cases
    step = max(1, int(study.get("chunk", 1)))
    return [list(range(i, min(i + step, end))) for i in range(start, end, step)]


def _gather(futures, describe):
    """The results in submission order; a failed task becomes an error row (or rows)."""
    from distributed import wait

    wait(futures)
    rows = []
    for future, what in zip(futures, describe):
        try:
            result = future.result()
        except Exception as e:  # a worker died or the task raised
            failed = [dict(r, status="error", message=f"task failed: {e!r}") for r in what]
            rows.extend(failed)
            continue
        rows.extend(result if isinstance(result, list) else [result])
    return rows


def _submit_recordings(client, recordings, out_root):
    futures = [
        client.submit(recording_task, spec, out_root, key=f"gpsrx-recording-{i}-{spec['name']}", pure=False)
        for i, spec in enumerate(recordings)
    ]
    describe = [[{"kind": "recording", "name": s["name"], "path": s["path"]}] for s in recordings]
    return futures, describe


def _submit_snapshots(client, sets, out_root):
    futures = [
        client.submit(snapshots_task, spec, out_root, key=f"gpsrx-snapshots-{i}-{spec.get('name', '')}", pure=False)
        for i, spec in enumerate(sets)
    ]
    describe = [[{"kind": "snapshots", "name": s.get("name", ""), "path": s["path"]}] for s in sets]
    return futures, describe


def _submit_study(client, study):
    name, quick = study["name"], bool(study.get("quick", False))
    futures, describe = [], []
    for chunk in _chunks(study):
        futures.append(
            client.submit(study_task, name, quick, chunk, key=f"gpsrx-study-{name}-{chunk[0]}", pure=False)
        )
        describe.append([{"kind": "study", "name": f"{name}/{i}", "study": name, "case": i} for i in chunk])
    return futures, describe


def run(manifest, client, out_dir=None):
    """Runs a manifest's recordings, snapshot sets and study grids on ``client``; returns one
    DataFrame.

    ``manifest``: a TOML or CSV file (``gpsrx batch``'s format) or a dict
    ``{"recordings": [spec], "snapshots": [set spec], "studies": [study]}``. ``out_dir``: where each recording's files
    go (``out_dir/NAME/``; default: a temporary directory). It must be reachable by the workers
    under the same path (a shared file system on a cluster).
    """
    import pandas as pd

    m = _manifest(manifest)
    out_root = os.fspath(out_dir) if out_dir is not None else tempfile.mkdtemp(prefix="gpsrx-batch-")
    futures, describe = _submit_recordings(client, m["recordings"], out_root)
    f, d = _submit_snapshots(client, m.get("snapshots", []), out_root)
    futures += f
    describe += d
    for study in m["studies"]:
        f, d = _submit_study(client, study)
        futures += f
        describe += d
    rows = _gather(futures, describe)
    columns = ["kind", "name", "status", "message"]
    frame = pd.DataFrame(rows)
    return frame[columns + [c for c in frame.columns if c not in columns]]


def run_recordings(recordings, client, out_dir=None):
    """:func:`run` for a list of recording specs (dicts with at least ``path``)."""
    specs = []
    for r in recordings:
        spec = {"name": os.path.splitext(os.path.basename(os.fspath(r["path"])))[0]}
        spec.update(r)
        spec["path"] = os.fspath(spec["path"])
        specs.append(spec)
    return run({"recordings": specs, "studies": []}, client, out_dir)


def run_snapshots(sets, client, out_dir=None):
    """:func:`run` for a list of snapshot set specs (dicts with at least ``path``, ``nav`` and
    ``approx_llh``, the keywords of :func:`gpsrx.snapshot`; ``name`` defaults to the file stem)."""
    specs = []
    for s in sets:
        spec = {"name": os.path.splitext(os.path.basename(os.fspath(s["path"])))[0]}
        spec.update(s)
        spec["path"] = os.fspath(spec["path"])
        specs.append(spec)
    return run({"recordings": [], "snapshots": specs, "studies": []}, client, out_dir)


def run_study(client, study="steady-state", cases=None, chunk=1, quick=True):
    """:func:`run` for one study grid: cases ``range(*cases)`` (default all), ``chunk`` per task."""
    spec = {"name": study, "chunk": chunk, "quick": quick}
    if cases is not None:
        spec["cases"] = list(cases)
    return run({"recordings": [], "studies": [spec]}, client)
