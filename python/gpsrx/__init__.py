"""gpsrx: a GPS L1 C/A software receiver on numpy arrays.

- :class:`Receiver` -- the receiver fed with blocks of complex samples (``push``, ``finish``);
- :func:`run` -- a whole recording, as ``gpsrx run`` does, into pandas-ready columns;
- :func:`acquire` -- the FFT acquisition search on a block of samples;
- :func:`simulate` -- the simulator, as ``gpsrx simulate`` does (recording and truth files);
- :func:`snapshot` -- a snapshot set positioned as ``gpsrx snapshot`` does (one row per
  snapshot), :func:`process_snapshots` -- the same as a batch task;
- :func:`study_cases`, :func:`run_study_case` -- a study grid case by case;
- :mod:`gpsrx.batch` -- many recordings, snapshot sets and study grids on a Dask cluster.

Every table is a dict of equal-length columns: ``pandas.DataFrame(result["fixes"])``.
Errors are Python exceptions with the messages of the ``gpsrx`` command: ``FileNotFoundError``
and ``OSError`` for files, ``ValueError`` for bad values and options, :class:`Error` otherwise.
"""

from ._gpsrx import (
    Error,
    Receiver,
    __version__,
    acquire,
    process_recording,
    process_snapshots,
    read_manifest,
    run,
    run_study_case,
    simulate,
    snapshot,
    study_cases,
)
from . import batch  # noqa: E402 (after the extension it uses)

__all__ = [
    "batch",
    "Error",
    "Receiver",
    "__version__",
    "acquire",
    "process_recording",
    "process_snapshots",
    "read_manifest",
    "run",
    "run_study_case",
    "simulate",
    "snapshot",
    "study_cases",
    "read_truth",
    "fix_errors_m",
]


def read_truth(path):
    """The simulator's ``truth.csv`` as a dict of numpy columns (``t_s``, ``x_m``, ...)."""
    import numpy as np

    data = np.genfromtxt(path, delimiter=",", names=True)
    return {name: data[name] for name in data.dtype.names}


def fix_errors_m(fixes, truth):
    """3-D distance of each fix from the truth at the fix's time, metres.

    ``fixes``: the ``fixes`` columns of :func:`run` (``t_stream_s``, ``x_m``, ``y_m``,
    ``z_m``); ``truth``: :func:`read_truth` of the simulator's ``truth.csv``. The truth is
    interpolated linearly at each fix's stream time.
    """
    import numpy as np

    t = np.asarray(fixes["t_stream_s"])
    err = np.zeros_like(t)
    for axis in ("x_m", "y_m", "z_m"):
        true = np.interp(t, truth["t_s"], truth[axis])
        err += (np.asarray(fixes[axis]) - true) ** 2
    return np.sqrt(err)
