#!/usr/bin/env python3
"""The paper's 2D comparisons (Figs. 13, 14 and 15): fluid particles inside the solids, counted.

    PYTHONPATH=build/python /usr/bin/python3 bench/penetration_2d.py [OUT] [--threads N] [--quick]

Runs each shipped scene of a comparison and its baselines (scenes/box_dam_2d*.json: Fig. 14,
the method against Akinci et al. 2012's boundary at r0 and 0.5 r0; scenes/hollow_drop_2d*.json:
Fig. 13, with and without the velocity-position correction; scenes/rod_stream_2d*.json: Fig. 15,
a rod of one line struck by a stream, with and without it) at the CFL step and at fixed steps of
1 ms and 2 ms (the paper gave Akinci's method 0.002 s), and after every step counts the fluid
particles whose centres lie inside a moving object's outline (its closed cavities included;
Simulation.fluid_inside_objects), or for a rod the fluid particles that crossed its line since
the last step: what the paper's figures draw in red. A run that fails (the fluid diverges, the
runaway guard trips) is reported with the time it reached, its counts up to there.

Writes OUT/penetration_2d.json and OUT/penetration_2d.md (default OUT: bench/results/
DATE-cpu-Nthreads-penetration_2d); docs/validation.md, "The paper's 2D comparisons", quotes it.
"""
import argparse
import datetime
import json
import os
import platform
import sys
import time

import meltwater as mw
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, "..", "scenes")

COMPARISONS = [
    ("Fig. 14: dam against a rigid box", [
        ("method (r0, correction)", "box_dam_2d"),
        ("Akinci, boundary at r0", "box_dam_2d_akinci"),
        ("Akinci, boundary at 0.5 r0", "box_dam_2d_akinci_dense"),
    ]),
    ("Fig. 13: four hollow elastic objects dropped", [
        ("method (correction)", "hollow_drop_2d"),
        ("no correction", "hollow_drop_2d_no_correction"),
    ]),
    ("Fig. 15: a rod of one line struck by a stream (crossings of its line)", [
        ("method (correction)", "rod_stream_2d"),
        ("no correction", "rod_stream_2d_no_correction"),
    ]),
]
STEPS = [("CFL", []), ("fixed 0.002 s", ["solver.dt_mode=fixed", "solver.dt=0.002"]),
         ("fixed 0.001 s", ["solver.dt_mode=fixed", "solver.dt=0.001"])]


def cpu_name():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


class RodCrossings:
    """Fluid particles that crossed a rod's line between two steps: each fluid particle beside a
    segment (projecting onto it, within 2 r0 of it) has a side; a particle beside the line at both
    steps on opposite sides went through it. Flowing round the free end is no crossing (the
    projection leaves the segments there)."""

    def __init__(self, rods, r0):
        self.rods = rods
        self.reach = 2 * r0
        self.side = None

    def count(self, sim):
        return self.count_arrays(sim.position[:, :2], sim.type, sim.object) if self.rods else 0

    def count_arrays(self, x, kind, body):
        side = np.zeros(len(x))
        for rod in self.rods:
            nodes = x[(kind == mw.GEOMETRY) & (body == rod)]
            a, d = nodes[:-1], nodes[1:] - nodes[:-1]
            fluid = np.flatnonzero(kind == mw.FLUID)
            lo, hi = nodes.min(axis=0) - self.reach, nodes.max(axis=0) + self.reach
            near = fluid[np.all((x[fluid] >= lo) & (x[fluid] <= hi), axis=1)]
            if len(near) == 0:
                continue
            rel = x[near][:, None, :] - a[None, :, :]
            t = np.einsum("psk,sk->ps", rel, d) / np.einsum("sk,sk->s", d, d)
            across = (d[None, :, 0] * rel[:, :, 1] - d[None, :, 1] * rel[:, :, 0]) / np.linalg.norm(d, axis=1)
            distance = np.where((t >= 0) & (t <= 1), np.abs(across), np.inf)
            nearest = distance.argmin(axis=1)
            rows = np.arange(len(near))
            beside = distance[rows, nearest] < self.reach
            side[near[beside]] = np.sign(across[rows, nearest][beside])
        crossed = 0 if self.side is None else int(np.sum(side * self.side < 0))
        self.side = side
        return crossed


def run_one(scene_name, overrides, threads, end_time):
    path = os.path.join(SCENES, scene_name + ".json")
    scene = mw.Scene(path, overrides=overrides + ["output.formats=[]"] + ([f"run.end_time={end_time}"] if end_time else []))
    sim = mw.Simulation(scene, threads=threads, guards=True)
    end = scene.end_time
    rods = RodCrossings([k for k, o in enumerate(scene.to_dict()["objects"]) if o.get("kind") == "rod"], scene.spacing)
    counts, steps, error = [], 0, ""
    started = time.time()
    try:
        while sim.time < end:
            sim.step()
            steps += 1
            counts.append(sum(c for c in sim.fluid_inside_objects() if c > 0) + rods.count(sim))
    except mw.SimulationError as e:
        error = str(e).splitlines()[0]
    return {
        "scene": scene_name, "overrides": overrides, "reached": sim.time, "end": end, "steps": steps,
        "completed": not error, "error": error, "max_inside": max(counts, default=0),
        "mean_inside": sum(counts) / len(counts) if counts else 0.0,
        "steps_with_inside": sum(1 for c in counts if c > 0), "wall_seconds": time.time() - started,
    }


def table(results):
    lines = []
    for title, rows in COMPARISONS:
        lines += [f"### {title}", "",
                  "| variant | step | reached | steps | most inside at once | mean inside | steps with any |",
                  "|---|---|---|---|---|---|---|"]
        for label, scene in rows:
            for step_label, _ in STEPS:
                r = results[(scene, step_label)]
                reached = f"{r['reached']:.2f} s" + ("" if r["completed"] else " (failed)")
                lines.append(f"| {label} | {step_label} | {reached} | {r['steps']} | {r['max_inside']} | "
                             f"{r['mean_inside']:.3f} | {r['steps_with_inside']} |")
        lines.append("")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?")
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--quick", action="store_true", help="0.3 s of each run (a smoke test)")
    args = parser.parse_args()
    threads = args.threads or os.cpu_count()
    out = args.out or os.path.join(HERE, "results", f"{datetime.date.today()}-cpu-{threads}threads-penetration_2d")
    os.makedirs(out, exist_ok=True)
    results = {}
    for _, rows in COMPARISONS:
        for _, scene in rows:
            for step_label, overrides in STEPS:
                r = run_one(scene, overrides, threads, 0.3 if args.quick else None)
                results[(scene, step_label)] = r
                print(f"{scene:28s} {step_label:14s} reached {r['reached']:.3f} s, most inside {r['max_inside']}, "
                      f"{r['wall_seconds']:.0f} s" + (f"  [{r['error'][:90]}]" if r["error"] else ""), flush=True)
    machine = f"{cpu_name()}, {threads} OpenMP threads"
    with open(os.path.join(out, "penetration_2d.json"), "w") as f:
        json.dump({"machine": machine, "command": " ".join(sys.argv),
                   "runs": [dict(r, step=k[1]) for k, r in results.items()]}, f, indent=2)
    with open(os.path.join(out, "penetration_2d.md"), "w") as f:
        f.write(f"# Fluid inside the solids, the paper's 2D comparisons\n\nMachine: {machine}. Command: "
                f"`bench/penetration_2d.py{' --quick' if args.quick else ''}`. Counted after every step.\n\n")
        f.write(table(results))
    print(f"results in {out}")


if __name__ == "__main__":
    main()
