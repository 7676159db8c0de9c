# Stepping releases the interpreter's lock; Ctrl-C stops a run after a whole step.
import os
import subprocess
import sys
import textwrap
import threading
import time

import pytest

import meltwater

from conftest import THREADS


def test_steps_run_without_the_interpreter_lock(coarse_scene):
    sim = meltwater.Simulation(coarse_scene, backend="openmp", threads=THREADS)
    errors = []

    def run():
        try:
            sim.run(steps=40)
        except Exception as e:  # reported below, in the main thread
            errors.append(e)

    worker = threading.Thread(target=run)
    worker.start()
    # Python runs beside the steps: this loop turns while the worker is inside run(). (Held for
    # the run, the lock would let it turn once or twice.)
    turns = 0
    while worker.is_alive():
        turns += 1
        time.sleep(0.001)
    worker.join()
    assert not errors
    assert turns > 20
    assert sim.step_count == 40


def test_a_second_thread_is_refused_while_one_steps(coarse_scene):
    sim = meltwater.Simulation(coarse_scene, backend="openmp", threads=THREADS)
    worker = threading.Thread(target=lambda: sim.run(steps=100))
    worker.start()
    while worker.is_alive() and "stepping" not in repr(sim):
        pass  # until the worker is inside run()
    with pytest.raises(RuntimeError, match=r"^the simulation is in use by another thread's call$"):
        sim.step()
    with pytest.raises(RuntimeError, match=r"in use"):
        sim.position
    worker.join()
    assert sim.step_count == 100


def test_ctrl_c_stops_a_run_after_a_whole_step():
    script = textwrap.dedent("""
        import os, signal, threading
        import meltwater
        sim = meltwater.Simulation(meltwater.Scene(overrides={"fluid.spacing": 0.05}), backend="openmp", threads=1)
        threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
        try:
            sim.run(until=1000)
        except KeyboardInterrupt:
            steps = sim.step_count
            sim.step()
            print("interrupted", steps > 0, sim.step_count == steps + 1)
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                          env={**os.environ})
    assert done.stdout.strip() == "interrupted True True", done.stderr
