# bench/penetration_2d.py, the paper's 2D comparisons counted: its rod-crossing count on made-up
# positions, and its whole pipeline (every comparison cut short) writing the JSON and the table.
import importlib.util
import json
import os
import subprocess
import sys

import numpy as np

import meltwater as mw
from conftest import REPO

spec = importlib.util.spec_from_file_location("penetration_2d", REPO / "bench" / "penetration_2d.py")
penetration = importlib.util.module_from_spec(spec)
spec.loader.exec_module(penetration)


def test_a_particle_through_the_rods_line_counts_and_one_round_its_end_does_not():
    count = penetration.RodCrossings([0], 0.01)
    nodes = np.array([[x, 0.5] for x in np.linspace(0.2, 0.7, 51)])
    fluid = np.array([[0.3, 0.51], [0.4, 0.49], [0.75, 0.51], [0.5, 0.6]])
    kind = np.array([mw.GEOMETRY] * 51 + [mw.FLUID] * 4)
    body = np.array([0] * 51 + [-1] * 4)
    assert count.count_arrays(np.vstack([nodes, fluid]), kind, body) == 0  # the first call sets the sides
    moved = fluid.copy()
    moved[0, 1] = 0.49  # through the line
    moved[1, 1] = 0.48  # stays below it
    moved[2, 1] = 0.49  # beyond the free end: round it
    moved[3, 1] = 0.40  # never beside it
    assert count.count_arrays(np.vstack([nodes, moved]), kind, body) == 1


def test_a_quick_run_writes_every_comparison(tmp_path):
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    done = subprocess.run([sys.executable, str(REPO / "bench" / "penetration_2d.py"), str(tmp_path), "--quick",
                           "--threads", "1"], capture_output=True, text=True, env=env, timeout=900)
    assert done.returncode == 0, done.stderr + done.stdout
    runs = json.loads((tmp_path / "penetration_2d.json").read_text())["runs"]
    scenes = {scene for _, rows in penetration.COMPARISONS for _, scene in rows}
    assert {r["scene"] for r in runs} == scenes
    assert len(runs) == len(scenes) * len(penetration.STEPS)
    for r in runs:
        assert r["steps"] > 0 and r["max_inside"] >= 0
        if r["step"] == "CFL":  # 0.3 s of every comparison runs at the CFL step
            assert r["completed"], r["error"]
    table = (tmp_path / "penetration_2d.md").read_text()
    for title, _ in penetration.COMPARISONS:
        assert f"### {title}" in table
