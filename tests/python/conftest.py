# Shared pieces of the Python module's tests (python/CMakeLists.txt runs them under ctest with
# PYTHONPATH=<build>/python and MELTWATER_BINARY=<build>/meltwater).
import os
import pathlib
import subprocess

import pytest

import meltwater

REPO = pathlib.Path(__file__).resolve().parents[2]

# The built-in dam break at 2.5 times its spacing: about 3,000 fluid particles, so that a few
# tenths of a second take seconds on two cores.
COARSE = {"fluid.spacing": 0.05}

# One OpenMP thread: on a machine whose cores are busy (a build beside the tests), a team of
# spinning threads waits on its descheduled members and a step takes 50 times as long.
THREADS = 1


def cli_binary():
    """The `meltwater` program these tests compare messages with, or None."""
    given = os.environ.get("MELTWATER_BINARY")
    path = (pathlib.Path(given) if given else REPO / "build" / "meltwater").resolve()
    return path if path.is_file() else None


def cli_error_line(*args, cwd):
    """What the CLI prints on stderr for `meltwater ARGS`, its last line, and its exit code."""
    binary = cli_binary()
    if binary is None:
        pytest.skip("no meltwater program to compare with (set MELTWATER_BINARY)")
    done = subprocess.run([str(binary), *args], cwd=cwd, capture_output=True, text=True, timeout=120)
    lines = done.stderr.strip().splitlines()
    return (lines[-1] if lines else ""), done.returncode


@pytest.fixture(scope="module")
def coarse_scene():
    return meltwater.Scene(overrides=COARSE)


def fluid_mask(sim):
    return sim.type == meltwater.FLUID
