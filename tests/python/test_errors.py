# Errors: the program's exceptions as meltwater.InputError (a ValueError), DeviceError and
# SimulationError (RuntimeErrors), each with the line the CLI prints after its prefix.
import pytest

import meltwater

from conftest import THREADS, cli_error_line


def cli_message(prefix, *args, cwd):
    line, code = cli_error_line(*args, cwd=cwd)
    assert line.startswith(prefix), line
    return line[len(prefix):], code


@pytest.mark.parametrize(
    "override",
    ["nonsense=1", "fluid.spacing=-1", "fluid_blocks.3.min=[0,0,0]", "solver.dt_mode=sometimes", "novalue"],
)
def test_a_bad_override_raises_input_error_with_the_cli_message(override, tmp_path):
    expected, code = cli_message("meltwater: error: ", "run", "--set", override, "--steps", "1",
                                 "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert code == 2
    with pytest.raises(meltwater.InputError) as raised:
        meltwater.Scene(overrides=[override])
    assert str(raised.value) == expected
    assert isinstance(raised.value, ValueError)


def test_a_missing_or_broken_scene_file_raises_the_cli_message(tmp_path):
    broken = tmp_path / "broken.json"
    broken.write_text('{"domain": {"min": [0, 0, 0], "max": [1, 1, 1]}, "fluid_blocks": [ }')
    for path in [tmp_path / "absent.json", broken]:
        expected, _ = cli_message("meltwater: error: ", "run", str(path), "--steps", "1", cwd=tmp_path)
        with pytest.raises(meltwater.InputError) as raised:
            meltwater.Scene(path)
        assert str(raised.value) == expected


def test_a_bad_dict_scene_names_the_key():
    with pytest.raises(meltwater.InputError, match=r"^scene dict: domain.min: required key is missing$"):
        meltwater.Scene({"fluid_blocks": [{"min": [0, 0, 0], "max": [1, 1, 1]}]})
    with pytest.raises(meltwater.InputError, match=r"^scene dict: "):
        meltwater.Scene({"fluid": {"spacing": float("nan")}})


def test_bad_backend_threads_and_run_arguments(coarse_scene, tmp_path):
    expected, _ = cli_message("meltwater: error: ", "run", "--backend", "gpu", "--steps", "1", cwd=tmp_path)
    with pytest.raises(meltwater.InputError) as raised:
        meltwater.Simulation(coarse_scene, backend="gpu")
    assert str(raised.value) == expected
    with pytest.raises(meltwater.InputError, match=r"^threads must be in \[1, 1024\]"):
        meltwater.Simulation(coarse_scene, threads=5000)
    sim = meltwater.Simulation(coarse_scene, backend="openmp", threads=THREADS)
    with pytest.raises(meltwater.InputError, match=r"^steps and until exclude each other; give one$"):
        sim.run(steps=2, until=0.1)
    with pytest.raises(meltwater.InputError, match=r"^steps must be at least 1, got 0$"):
        sim.run(steps=0)
    with pytest.raises(meltwater.InputError, match=r"^until must be in \(0, 1e6\] seconds"):
        sim.run(until=float("inf"))
    assert sim.step_count == 0


def test_cuda_without_a_gpu_raises_device_error_with_the_cli_message(coarse_scene, tmp_path):
    if meltwater.backends()["cuda"]["available"]:
        pytest.skip("a GPU is usable here: test_simulation.py runs on it")
    expected, code = cli_message("meltwater: device error: ", "run", "--backend", "cuda", "--steps", "1",
                                 "--set", "fluid.spacing=0.05", "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert code == 3
    with pytest.raises(meltwater.DeviceError) as raised:
        meltwater.Simulation(coarse_scene, backend="cuda")
    assert str(raised.value) == expected
    assert isinstance(raised.value, RuntimeError)


@pytest.mark.parametrize("guard", ["solver.max_speed=0.05", "solver.max_density_error=0.001"])
def test_a_guard_stops_the_step_with_the_cli_message(guard, tmp_path):
    # Limits the collapsing column passes in its first steps: the guard's message word for word
    # as the CLI's (both run the same steps, bitwise, on OpenMP).
    overrides = ["fluid.spacing=0.05", guard]
    expected, code = cli_message("meltwater: simulation failed: ", "run", "--backend", "openmp", "--threads", "1",
                                 "--steps", "20", "--quiet", *[a for o in overrides for a in ("--set", o)],
                                 "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert code == 4
    sim = meltwater.Simulation(meltwater.Scene(overrides=overrides), backend="openmp", threads=THREADS)
    with pytest.raises(meltwater.SimulationError) as raised:
        sim.run(steps=20)
    assert str(raised.value) == expected
    # Without the guards the same steps run on.
    free = meltwater.Simulation(meltwater.Scene(overrides=overrides), backend="openmp", threads=THREADS,
                                guards=False)
    assert free.run(steps=20)["step"] == 20


def test_a_dict_override_that_is_not_json_names_its_key():
    with pytest.raises(meltwater.InputError, match=r"^--set fluid.spacing: .*JSON"):
        meltwater.Scene(overrides={"fluid.spacing": float("nan")})
