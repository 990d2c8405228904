"""Type stubs of the extension module ``gpsrx._gpsrx`` (re-exported by ``gpsrx``)."""

import os
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

Columns = Dict[str, Union[npt.NDArray[np.float64], npt.NDArray[np.int64], List[str]]]
"""A table: equal-length columns (numbers as numpy arrays, NaN where missing; text as lists)."""

PathLike = Union[str, "os.PathLike[str]"]

class Error(Exception):
    """An error of the gpsrx receiver (its message says what to do)."""

class Receiver:
    """The receiver on pushed blocks of complex baseband samples (any chunking, same fixes).

    Options by name as ``gpsrx run`` takes them: ``rate_hz``, ``tropo="none"``,
    ``elevation_mask_deg``, ``approx_llh=[lat_deg, lon_deg, h_m]``, ``prns=[...]``,
    ``tracking="vector"`` (``[tracking] mode``: the navigation filter drives the channels), ...
    """

    def __init__(
        self,
        fs_hz: float,
        nav: Optional[str] = None,
        config: Optional[PathLike] = None,
        **options: Any,
    ) -> None: ...
    @property
    def fs_hz(self) -> float: ...
    def push(self, samples: npt.NDArray[np.complex64]) -> Dict[str, Any]:
        """New products: ``fixes``, ``observables``, ``channels`` (Columns), ``events`` (list of dicts)."""
    def finish(self) -> Dict[str, Any]:
        """The last products as ``push`` gives them, and ``summary`` (dict)."""

def run(
    path: PathLike,
    format: Optional[str] = None,
    fs_hz: Optional[float] = None,
    if_hz: float = 0.0,
    skip_s: float = 0.0,
    duration_s: Optional[float] = None,
    nav: Optional[str] = None,
    config: Optional[PathLike] = None,
    out: Optional[PathLike] = None,
    **options: Any,
) -> Dict[str, Any]:
    """A whole recording: ``fixes``, ``channels``, ``observables`` (Columns), ``events``,
    ``summary`` (dict), ``warnings`` (list of str)."""

def acquire(
    samples: npt.NDArray[np.complex64],
    fs_hz: float,
    prns: Optional[Sequence[int]] = None,
    coherent_ms: int = 1,
    noncoherent: int = 10,
    doppler_max_hz: float = 5000.0,
    doppler_center_hz: float = 0.0,
    pfa: float = 1e-5,
) -> List[Dict[str, Any]]:
    """One dict per PRN searched: ``prn``, ``detected``, ``doppler_hz``, ``code_phase_chips``,
    ``code_phase_samples``, ``cn0_dbhz``, ``metric``, ``threshold``, ``peak_ratio``."""

def simulate(
    scenario: PathLike,
    out_dir: PathLike,
    duration_s: Optional[float] = None,
    seed: Optional[int] = None,
    format: Optional[str] = None,
    fs_hz: Optional[float] = None,
) -> Dict[str, Any]:
    """A scenario file, its TOML text or ``"default"`` simulated into ``out_dir``; the report
    (``data_path``, ``meta_path``, ``truth_path``, ``satellites``, ``fs_hz``, ...)."""

def read_manifest(path: PathLike) -> Dict[str, List[Dict[str, Any]]]:
    """A batch manifest (TOML or CSV): ``{"recordings": [spec], "snapshots": [set spec],
    "studies": [study]}``."""

def process_recording(spec: Dict[str, Any], out_root: PathLike) -> Dict[str, Any]:
    """One recording into ``out_root/NAME/``: its summary row (``status`` ok, no_fix or error)."""

def study_cases(study: str = "steady-state", quick: bool = True) -> List[Dict[str, Any]]:
    """The cases of a study grid, each with its index ``case``."""

def run_study_case(index: int, study: str = "steady-state", quick: bool = True) -> Dict[str, Any]:
    """One case of a study grid: its parameters and results."""

def snapshot(
    path: PathLike,
    nav: Optional[PathLike],
    approx_llh: Sequence[float],
    out: Optional[PathLike] = None,
    **options: Any,
) -> Dict[str, Any]:
    """A snapshot set (SnapperGPS JSON, SigMF with one capture per snapshot, or one raw
    snapshot) positioned as ``gpsrx snapshot`` does: ``snapshots`` (Columns, one row per input
    snapshot: ``index``, ``quality``, ``reason``, ``lat_deg``, ``x_m``, ``time_correction_s``,
    ``h_error_m``, ...) and ``summary`` (dict: ``fixes``, ``h_error_median_m``, ...).

    Options: ``time="WEEK:TOW"``, ``format``, ``map``, ``fs_hz``, ``if_hz``,
    ``height_sigma_m`` (30), ``max_speed_mps`` (50), ``coherent_ms``, ``coherent_look``
    (False), ``smooth_accel_mps2``,
    ``truth`` (SnapperGPS truth JSON), ``truth_h_m``, ``truth_ecef_m``."""

def process_snapshots(spec: Dict[str, Any], out_root: PathLike) -> Dict[str, Any]:
    """One snapshot set into ``out_root/NAME/``: its summary row (``status`` ok, no_fix or error)."""
