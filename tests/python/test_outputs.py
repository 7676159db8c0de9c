# Frames and stats.csv written from Python.
import re

import numpy
import pytest

import meltwater

from conftest import THREADS


def test_write_frame_numbers_frames_and_lists_them(coarse_scene, tmp_path):
    sim = meltwater.Simulation(coarse_scene, backend="openmp", threads=THREADS)
    first = sim.write_frame(tmp_path / "frames")
    sim.run(steps=3)
    second = sim.write_frame(str(tmp_path / "frames") + "/")  # the same directory, spelt otherwise
    assert first.endswith("particles_00000.vtu") and second.endswith("particles_00001.vtu")
    pvd = (tmp_path / "frames" / "particles.pvd").read_text()
    # Each frame's moving particles as part 0, the static boundary (written once) as part 1.
    parts = re.findall(r'timestep="([^"]+)" part="(\d)" file="([^"]+)"', pvd)
    assert [f for _, part, f in parts if part == "0"] == ["particles_00000.vtu", "particles_00001.vtu"]
    assert {f for _, part, f in parts if part == "1"} == {"static_boundary.vtu"}
    times = [float(t) for t, part, _ in parts if part == "0"]
    assert times == [0.0, pytest.approx(sim.time)]
    meshio = pytest.importorskip("meshio")
    frame = meshio.read(second)
    assert len(frame.points) == sim.counts["total"] - sim.counts["pending"] - sim.counts["static_boundary"]
    walls = meshio.read(tmp_path / "frames" / "static_boundary.vtu")
    assert len(walls.points) == sim.counts["static_boundary"]
    ids = frame.point_data["id"].ravel()
    assert numpy.allclose(frame.points, sim.position[ids], atol=1e-6)
    assert {"velocity", "density", "pressure", "type", "object", "id"} <= set(frame.point_data)


def test_run_writes_frames_at_the_scene_fps(tmp_path):
    scene = meltwater.Scene(overrides={"fluid.spacing": 0.05, "output.fps": 50})
    sim = meltwater.Simulation(scene, backend="openmp", threads=THREADS)
    sim.run(until=0.1, frames=tmp_path)
    frames = sorted(p.name for p in tmp_path.glob("particles_*.vtu"))
    # The start, then one each 0.02 s to 0.1 s.
    assert frames == ["particles_%05d.vtu" % k for k in range(6)]


def test_write_stats_writes_one_row_a_step(coarse_scene, tmp_path):
    sim = meltwater.Simulation(coarse_scene, backend="openmp", threads=THREADS)
    sim.run(steps=4)
    sim.write_stats(tmp_path / "stats.csv")
    lines = (tmp_path / "stats.csv").read_text().splitlines()
    assert len(lines) == 5 and lines[0].startswith("step,")


def test_an_unwritable_frame_directory_is_input_error(coarse_scene, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    sim = meltwater.Simulation(coarse_scene, backend="openmp", threads=THREADS)
    with pytest.raises(meltwater.InputError):
        sim.write_frame(blocker / "frames")
