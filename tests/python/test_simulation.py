# meltwater.Simulation: the dam break falls, the arrays are what they say, run() stops where asked.
import os

import numpy
import pytest

import meltwater

from conftest import COARSE, THREADS, fluid_mask


@pytest.fixture(scope="module")
def dam_break(coarse_scene):
    """The coarse dam break before its first step, and after 0.15 s."""
    sim = meltwater.Simulation(coarse_scene, backend="openmp", threads=THREADS)
    start = sim.fields()
    report = sim.run(until=0.15)
    return sim, start, report


def test_the_dam_break_collapses_and_keeps_its_fluid(dam_break):
    sim, start, report = dam_break
    fluid0 = start["type"] == meltwater.FLUID
    fluid = fluid_mask(sim)
    assert fluid0.sum() == sim.counts["fluid"] == fluid.sum() > 2000
    assert report["lost_particles"] == 0
    # The column falls and spreads: its mean height drops, its front moves out past the dam at
    # x = 0.6 m, and nothing leaves the tank.
    y0 = start["position"][fluid0, 1].mean()
    y = sim.position[fluid, 1].mean()
    assert y < y0 - 0.01, (y0, y)
    assert sim.position[fluid, 0].max() > 0.7
    low, high = numpy.array([0, 0, 0]), numpy.array([1.6, 1.0, 0.8])
    assert numpy.all(sim.position[fluid] > low - 0.05) and numpy.all(sim.position[fluid] < high + 0.05)
    # Falling fluid moves down; the boundary never moves.
    assert sim.velocity[fluid, 1].mean() < -0.1
    walls = sim.type == meltwater.STATIC_BOUNDARY
    assert numpy.array_equal(sim.position[walls], start["position"][walls])
    assert numpy.all(numpy.isfinite(sim.pressure)) and sim.pressure[fluid].max() > 0
    assert sim.density[fluid].mean() == pytest.approx(1000, rel=0.05)


def test_the_arrays_shapes_types_and_order(dam_break):
    sim, start, _ = dam_break
    n = sim.counts["total"]
    real = numpy.dtype(meltwater.REAL)
    for name in ["position", "velocity"]:
        a = getattr(sim, name)
        assert a.shape == (n, 3) and a.dtype == real
    for name in ["density", "pressure"]:
        assert getattr(sim, name).shape == (n,) and getattr(sim, name).dtype == real
    assert sim.type.dtype == numpy.uint8 and sim.object.dtype == numpy.int32
    assert sim.temperature is None  # no heat conduction in this scene
    assert set(start) == {"position", "velocity", "density", "pressure", "type", "object"}
    # The scene's order: the particles keep their index from step to step.
    assert numpy.array_equal(start["type"], sim.type)


def test_arrays_are_read_only_snapshots(coarse_scene):
    sim = meltwater.Simulation(coarse_scene, backend="openmp", threads=THREADS)
    before = sim.position
    kept = before.copy()
    with pytest.raises(ValueError):
        before[0, 0] = 10.0
    # One download per state: two reads between steps are views of the same snapshot.
    assert sim.position.base is not None
    assert numpy.shares_memory(sim.position, sim.velocity) is False
    sim.run(steps=5)
    # Arrays taken before the steps keep their values; new ones show the new state.
    assert numpy.array_equal(before, kept)
    assert not numpy.array_equal(sim.position, kept)
    changed = sim.position.copy()
    changed[:] = 0  # a copy is the caller's to change
    assert numpy.any(sim.position != 0)


def test_the_report(dam_break):
    sim, _, report = dam_break
    assert report == sim.last_report
    assert report["step"] == sim.step_count > 0
    assert report["time"] == sim.time
    for key in ["dt", "iterations", "density_error_avg", "density_error_max", "max_speed", "kinetic_energy",
                "retries", "diverged", "unconverged", "total_ms"]:
        assert key in report
    assert list(report["stage_ms"]) == sim.stage_names
    assert "pcisph" in sim.stage_names
    assert 0 < report["max_speed"] < 5 and report["density_error_max"] < 0.1


def test_run_until_stops_at_the_step_that_reaches_it(coarse_scene):
    sim = meltwater.Simulation(coarse_scene, backend="openmp", threads=THREADS)
    report = sim.run(until=0.05)
    assert report["time"] >= 0.05 * (1 - 1e-9)
    assert report["time"] - report["dt"] < 0.05
    steps = sim.step_count
    assert sim.run(until=0.05)["step"] == steps  # already there: no step
    assert sim.run(steps=3)["step"] == steps + 3
    one = sim.step()
    assert one["step"] == steps + 4 and one["time"] > report["time"]


def test_threads_zero_means_all_cores_after_a_one_thread_simulation(coarse_scene):
    if "OMP_NUM_THREADS" in os.environ:
        pytest.skip("OMP_NUM_THREADS sets what all cores means")
    assert meltwater.Simulation(coarse_scene, backend="openmp", threads=1).threads == 1
    assert meltwater.Simulation(coarse_scene, backend="openmp", threads=0).threads == len(os.sched_getaffinity(0))


def test_a_scene_with_heat_gives_temperatures():
    sim = meltwater.Simulation(meltwater.Scene(overrides={**COARSE, "heat.enabled": True, "fluid.temperature": 35}),
                               backend="openmp", threads=THREADS)
    sim.run(steps=2)
    t = sim.temperature
    assert t.shape == (sim.counts["total"],)
    assert numpy.allclose(t[fluid_mask(sim)], 35, atol=1e-3)
    assert "heat_content" in sim.last_report and "temperature" in sim.fields()


def test_the_cuda_backend_runs_where_a_gpu_is_usable(coarse_scene):
    if not meltwater.backends()["cuda"]["available"]:
        pytest.skip("no usable GPU: " + meltwater.backends()["cuda"]["description"])
    gpu = meltwater.Simulation(coarse_scene, backend="cuda")
    cpu = meltwater.Simulation(coarse_scene, backend="openmp")
    assert gpu.backend == "cuda"
    gpu.run(steps=10)
    cpu.run(steps=10)
    assert gpu.counts == cpu.counts
    # The backends round differently; after 10 steps they agree far below a spacing.
    assert numpy.abs(gpu.position - cpu.position).max() < 0.01 * coarse_scene.spacing
