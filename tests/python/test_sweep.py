# bench/sweep.py, the speed–accuracy sweep: its Pareto front and purposes on made-up points, and
# its whole pipeline (every case cut short, in child processes) writing the CSV, plot and report,
# --replot redrawing them from the CSV, and --only with --base rerunning one point into them.
import csv
import importlib.util
import math
import os
import subprocess
import sys

import pytest

from conftest import REPO

spec = importlib.util.spec_from_file_location("sweep", REPO / "bench" / "sweep.py")
sweep = importlib.util.module_from_spec(spec)
spec.loader.exec_module(sweep)


def point(name, cost, error, status="ok"):
    return {"setting": name, "ms_per_simulated_s": cost, "error": error, "status": status}


def test_the_front_keeps_only_points_nothing_beats_on_both_cost_and_error():
    points = [point("a", 10, 0.20), point("b", 20, 0.05), point("c", 30, 0.10), point("d", 40, 0.01),
              point("e", 5, 0.5, status="failed")]
    assert [p["setting"] for p in sweep.pareto(points)] == ["a", "b", "d"]
    rules = {name: rule for name, _, rule in sweep.PURPOSES}
    assert sweep.pick(points, rules["preview"])["setting"] == "b"      # the cheapest under 10%
    assert sweep.pick(points, rules["production"])["setting"] == "d"   # the cheapest under 3%
    assert sweep.pick(points, rules["validation"])["setting"] == "d"
    assert sweep.pick([point("x", 1, 0.5)], rules["production"]) is None


def test_a_smoke_sweep_writes_the_csv_the_plot_and_the_report(tmp_path):
    out = tmp_path / "sweep"
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    done = subprocess.run([sys.executable, str(REPO / "bench" / "sweep.py"), "--smoke", "--threads", "1", str(out),
                           "--build", str(pathlib_build())], capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stderr + done.stdout
    rows = list(csv.DictReader(open(out / "sweep.csv")))
    assert [r["case"] for r in rows] == list(sweep.CASES)
    for r in rows:
        assert r["status"] == "ok"
        assert math.isfinite(float(r["error"])) and float(r["error"]) >= 0
        assert float(r["ms_per_simulated_s"]) > 0
        assert int(r["steps"]) > 0
    assert (out / "sweep.png").stat().st_size > 10_000
    report = (out / "report.md").read_text()
    for case in sweep.CASES:
        assert f"## {case}" in report
    assert "| production |" in report
    # --replot redraws the same report from the CSV alone.
    (out / "sweep.png").unlink()
    again = subprocess.run([sys.executable, str(REPO / "bench" / "sweep.py"), "--replot", str(out)],
                           capture_output=True, text=True, env=env, timeout=120)
    assert again.returncode == 0, again.stderr
    assert (out / "report.md").read_text() == report
    assert (out / "sweep.png").stat().st_size > 10_000
    # --only and --base: one point run again, every other taken from the first sweep.
    merged = tmp_path / "merged"
    rerun = subprocess.run([sys.executable, str(REPO / "bench" / "sweep.py"), "--smoke", "--threads", "1",
                            "--cases", "dam_break", "--only", "defaults", "--base", str(out), str(merged),
                            "--build", str(pathlib_build())], capture_output=True, text=True, env=env, timeout=600)
    assert rerun.returncode == 0, rerun.stderr + rerun.stdout
    merged_rows = list(csv.DictReader(open(merged / "sweep.csv")))
    assert sorted(r["case"] for r in merged_rows) == sorted(sweep.CASES)
    assert f"the other {len(rows) - 1} points from {out}" in (merged / "report.md").read_text()


def test_an_unknown_case_is_refused_in_one_line(tmp_path):
    done = subprocess.run([sys.executable, str(REPO / "bench" / "sweep.py"), "--cases", "nonsense", str(tmp_path)],
                          capture_output=True, text=True)
    assert done.returncode == 2
    assert done.stderr.strip().count("\n") == 0 and "unknown case 'nonsense'" in done.stderr


def test_a_missing_base_is_refused_in_one_line_before_any_point_runs(tmp_path):
    done = subprocess.run([sys.executable, str(REPO / "bench" / "sweep.py"), "--base", str(tmp_path / "none"),
                           str(tmp_path / "out")], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert done.stderr.strip().count("\n") == 0 and "--base needs a sweep folder with a sweep.csv" in done.stderr
    assert not (tmp_path / "out").exists()


def pathlib_build():
    """The build whose module this test imports: the folder above PYTHONPATH's python/."""
    import meltwater

    return os.path.dirname(os.path.dirname(os.path.abspath(meltwater.__file__)))
