from typing import Any, Dict

import numpy as np
import numpy.typing as npt

from . import batch as batch
from ._gpsrx import (
    Error as Error,
    Receiver as Receiver,
    __version__ as __version__,
    acquire as acquire,
    process_recording as process_recording,
    process_snapshots as process_snapshots,
    read_manifest as read_manifest,
    run as run,
    run_study_case as run_study_case,
    simulate as simulate,
    snapshot as snapshot,
    study_cases as study_cases,
)

def read_truth(path: str) -> Dict[str, npt.NDArray[np.float64]]: ...
def fix_errors_m(fixes: Dict[str, Any], truth: Dict[str, npt.NDArray[np.float64]]) -> npt.NDArray[np.float64]: ...
