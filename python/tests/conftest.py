"""Shared fixtures: one short simulated recording (10 s, 2.048 MHz, fixed seed) and its truth."""

import pytest

import gpsrx

# A static antenna in Daejeon, 10 s of ci8 at 2.048 MHz with ionosphere and troposphere (as the
# receiver's default corrections model them), 8 satellites above 15 degrees.
SCENARIO = """
description = "pytest: static antenna, Daejeon"
duration_s = {duration_s}
seed = {seed}
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538194.0
[output]
format = "ci8"
fs_hz = 2.048e6
[receiver]
kind = "static"
llh_deg = [36.3721, 127.3604, 80.0]
[atmosphere]
ionosphere = true
troposphere = true
"""

# The navigation data the simulator used, and a position 10 km off the truth: the first fix
# comes from the code phases about a second after the start (coarse time, SigMF core:datetime).
RUN_OPTIONS = {"nav": "builtin:brdc0010.22n", "approx_llh": [36.4, 127.4, 0.0]}


def simulate(out_dir, duration_s=10.0, seed=7):
    return gpsrx.simulate(SCENARIO.format(duration_s=duration_s, seed=seed), str(out_dir))


@pytest.fixture(scope="session")
def sim(tmp_path_factory):
    """The simulator's report of the shared recording."""
    return simulate(tmp_path_factory.mktemp("sim"))


@pytest.fixture(scope="session")
def truth(sim):
    return gpsrx.read_truth(sim["truth_path"])


@pytest.fixture(scope="session")
def run_result(sim):
    """The shared recording run once, as `gpsrx run` would."""
    return gpsrx.run(sim["data_path"], **RUN_OPTIONS)
