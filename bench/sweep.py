#!/usr/bin/env python3
"""The speed–accuracy trade: validation cases swept over the solver's settings.

    make sweep                      # or: PYTHONPATH=build/python /usr/bin/python3 bench/sweep.py
    bench/sweep.py --quick          # 56 of the 122 points, none at the finer spacing
    bench/sweep.py --smoke OUT      # one short point a case: checks the pipeline (a ctest)
    bench/sweep.py --replot OUT     # redraws OUT's plot and report from its sweep.csv

Each point is one case run with one setting changed from the method's defaults, in its own
process (a runaway stops that point, not the sweep). For each point: the case's error against
its reference and the cost (wall milliseconds per simulated second, PCISPH iterations per step).
Output, in bench/results/DATE-cpu-Nthreads-sweep/ (or OUT): sweep.csv, sweep.png (error against cost,
one panel per case, the Pareto front drawn) and report.md (the tables, the front, and the
cheapest point per purpose). The cases, their references and how they are measured:
docs/validation.md, "The speed–accuracy trade".

Cases:
- hydrostatic: a column 1 m tall and 10 r0 wide, from rest, 2 s. Error: the pressure gradient's
  deviation from ρ0 g, fitted to the per-layer means of the raw particle pressures (no
  smoothing) of the fluid more than 2 r0 from the side walls, averaged over every step of the
  last 0.5 s, for layers more than 3 r0 below the surface and 2 r0 above the floor. Also
  reported: the same fit over the whole width, the pressure of fluid within r0 of a side wall
  over ρ0 g (H − y), averaged likewise, the load pressure sensors read on a side wall (8 patches
  4 r0 square, 0.1-0.8 m up) and the floor over ρ0 g × depth, and the kinetic energy at the end.
- dam_break: Martin & Moyce (1952), n² = 2, a = 0.2 m, as a slab 4 r0 thick (tests/core/
  test_dam_break.cpp). Error: the largest deviation of the column's residual height H/(2a) from
  their Table 6 at τ = 0.56 … 1.84.
- floating: a rigid box (0.16 × 0.08 × 0.16 m) at ρs/ρf = 0.5 set into a pool at its Archimedes
  draft, 3 s. Error: the draft's deviation from Archimedes', averaged over every step of the last
  1 s. The draft: the pool's level less the bottom face of the box's mesh; the level: where the
  fluid, at the volume its lattice started with (r0³ a particle), fills the pool round the box's
  submerged part (an incompressible pool of that fluid). Also reported: the draft from two other
  levels, the median over r0-wide columns away from the box of each column's highest particle
  plus r0/2 (`draft_by_tops`), and where the interior's pressure, fitted to a line, falls to 0
  (`draft_by_pressure`). floating_0.3 and floating_0.9: the same at those ratios, at the
  defaults and the other spacings only.
- held_box: the floating box's pool with the box held still (every particle pinned) where
  Archimedes puts it at ρs/ρf = 0.5, 2 s: the fluid's lift on it against ρ0 g times the volume below
  the level (by volume, as for floating), averaged over every step of the last 0.5 s. It isolates
  the boundary's response from the box's motion; also reported: the excess lift as a head of
  water, in r0.
- stefan: tests/core/test_stefan.cpp's slab at St 0.3 as a scene (a pinned lattice plate held at
  T_m + 10 K, a pinned slab of solid at T_m, no gravity, α 0.08 m²/s, 8 x 8 lattice columns). Error:
  λ fitted to the steps at which the 4 x 4 central columns' mean melted count passes each whole
  layer (from the third to the tenth) against the one-phase Stefan problem's λ. A front that has
  not passed ten layers by four times the analytic time fails the point.

- lobovsky: Lobovský et al. (2014), H = 0.3 m, a tank 1.61 x 0.6 x 0.15 m with the column 0.6 m
  long at one end, released at once; a pressure sensor (docs/scenes.md) 6 mm square on the far
  wall where their sensor 1 is, 3 mm over the bed, read every step up to t* = t sqrt(g/H) = 3.
  Error: the front's arrival (the first t* at which the sensor reads 0.1 ρ g H) against 2.444, that
  of the experimental run TNL-SPH ships. Also reported: the peak in ρ g H (3.04 in that run), when,
  and the impulse from the arrival to t* 3.

Settings (one at a time from the defaults: fixed 1 ms steps, η 1%, the peak bound 5 η, the cubic
spline at h = 2 r0, the case's r0, one wall layer at r0/2, both corrections): the step (fixed,
CFL numbers, largest steps up to the paper's 0.03 s), η and the peak bound, r0, kernel and h/r0,
the boundary's spacing and layers, the corrections off. Single against double precision needs a
second build: `--double-build DIR` (a `-DMELTWATER_DOUBLE=ON` build with its Python module) adds
the defaults run on it. PCISPH is the project's only pressure solver.
"""

import argparse
import csv
import datetime
import json
import math
import os
import platform
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

# Martin & Moyce (1952), n² = 2, Table 6 (docs/method.md): residual height against τ = t sqrt(g/a).
TAU_MM = [0.56, 0.77, 0.93, 1.08, 1.28, 1.46, 1.66, 1.84]
H_MM = [0.94, 0.89, 0.83, 0.78, 0.72, 0.67, 0.61, 0.56]

# ---- the cases: each builds its scene at spacing r0 and measures its error from a Simulation ----


def hydrostatic_scene(r0):
    width, height = 10 * r0, 1.0
    return {
        "name": "sweep_hydrostatic",
        "domain": {"min": [0, 0, 0], "max": [width, height + 0.2, width]},
        "fluid": {"rest_density": 1000, "spacing": r0, "viscosity": 0},
        "fluid_blocks": [{"min": [0, 0, 0], "max": [width, height, width]}],
        # Wall loads: a 4 r0 patch of one side wall every 0.1 m from 0.1 m to 0.8 m high, and the
        # floor's middle.
        "pressure_sensors": [{"name": f"wall{k}", "center": [width, 0.1 * k, width / 2], "size": 4 * r0}
                             for k in range(1, 9)] + [{"name": "floor", "center": [width / 2, 0, width / 2],
                                                       "size": 4 * r0}],
    }


def hydrostatic_measure(meltwater, sim, r0, settle):
    import numpy as np

    rho_g = 1000 * 9.81
    width = 10 * r0
    report = sim.run(until=max(settle - 0.5, 0.5 * settle))
    # Per-layer mean pressures, averaged over every step of the last half second (or half the run):
    # the column still breathes after the settling, and one instant would catch it mid-swing. Two
    # sets of layers: the interior (more than 2 r0 from the side walls) and the whole width, whose
    # outer ring reads the walls' inflated pressure (docs/validation.md, "Fluid: walls").
    sums = {"interior": {}, "whole": {}}
    counts = {"interior": {}, "whole": {}}
    wall_ratios, surfaces, load_ratios, floor_ratios = [], [], [], []
    while sim.time < settle:
        report = sim.step()
        fluid = sim.type == meltwater.FLUID
        x = sim.position[fluid, 0].astype(float)
        z = sim.position[fluid, 2].astype(float)
        y = sim.position[fluid, 1].astype(float)
        p = sim.pressure[fluid].astype(float)
        surface = float(np.median(np.sort(y)[-int(len(y) * 0.01) - 1:])) + r0 / 2
        surfaces.append(surface)
        layer = np.floor(y / r0).astype(int)
        inner = (np.minimum(x, width - x) > 2 * r0) & (np.minimum(z, width - z) > 2 * r0)
        for name, keep in (("interior", inner), ("whole", np.ones_like(inner))):
            for k in np.unique(layer[keep]):
                sel = keep & (layer == k)
                sums[name][k] = sums[name].get(k, 0.0) + float(p[sel].sum())
                counts[name][k] = counts[name].get(k, 0) + int(sel.sum())
        wall = ((x < r0) | (x > width - r0)) & (surface - y > 3 * r0) & (y > 2 * r0)
        wall_ratios.append(float(np.mean(p[wall] / (rho_g * (surface - y[wall])))))
        # The sensors' readings: the load on the wall, not the pressure of the fluid beside it.
        load_ratios.append([report[f"sensor_wall{k}"] / (rho_g * (surface - 0.1 * k)) for k in range(1, 9)])
        floor_ratios.append(report["sensor_floor"] / (rho_g * surface))
    surface = float(np.mean(surfaces))
    load_ratio = np.mean(load_ratios, axis=0)

    def slope(name):
        depths, means = [], []
        for k in sorted(sums[name]):
            centre = (k + 0.5) * r0
            if surface - centre < 3 * r0 or centre < 2 * r0:
                continue
            depths.append(surface - centre)
            means.append(sums[name][k] / counts[name][k])
        return np.polyfit(depths, means, 1)[0] / rho_g

    interior, whole = slope("interior"), slope("whole")
    return {"error": abs(interior - 1), "gradient_ratio": interior, "whole_width_gradient_ratio": whole,
            "wall_pressure_ratio": float(np.mean(wall_ratios)),
            "wall_load_ratio_min": float(load_ratio.min()), "wall_load_ratio_max": float(load_ratio.max()),
            "floor_load_ratio": float(np.mean(floor_ratios)), "kinetic_energy": report["kinetic_energy"]}


def dam_break_scene(r0):
    a, depth = 0.2, 4 * r0
    return {
        "name": "sweep_dam_break",
        "domain": {"min": [0, 0, 0], "max": [5 * a, 2.5 * a, depth]},
        "fluid": {"rest_density": 1000, "spacing": r0, "viscosity": 0},
        "fluid_blocks": [{"min": [0, 0, 0], "max": [a, 2 * a, depth]}],
    }


def dam_break_measure(meltwater, sim, r0, settle):
    a, g = 0.2, 9.81
    tau_of_t = math.sqrt(g / a)
    tau_end = TAU_MM[-1] if settle is None else settle * tau_of_t
    times, heights = [0.0], [1.0]
    while times[-1] < tau_end:
        sim.step()
        pos = sim.position[sim.type == meltwater.FLUID]
        top = pos[pos[:, 0] < a, 1].max()
        times.append(sim.time * tau_of_t)
        heights.append((float(top) + r0 / 2) / (2 * a))
    worst = 0.0
    for tau, h in zip(TAU_MM, H_MM):
        if tau > times[-1]:
            break
        k = next(i for i, t in enumerate(times) if t >= tau)
        f = (tau - times[k - 1]) / (times[k] - times[k - 1])
        value = heights[k - 1] + f * (heights[k] - heights[k - 1])
        worst = max(worst, abs(value - h) / h)
    return {"error": worst}


# Lobovský et al. (2014), the H = 0.3 m runs: t* = t sqrt(g/H) at which sensor 1 first reads
# 0.1 ρ g H, and its peak, in the one experimental run (their "peak event 5") whose sensor series
# TNL-SPH ships (examples/resources/damBreak2D/damBreak2D_experimentalDataLobovsky2014/pressure/,
# sensor 1 is the file ending _5): 2.444 and 3.04 ρ g H at t* 2.455. Their median peak over 100 runs
# is not checked against the paper here (docs/validation.md).
LOBOVSKY_H, LOBOVSKY_RHO = 0.3, 997.0
LOBOVSKY_ARRIVAL, LOBOVSKY_PEAK = 2.444, 3.04


def lobovsky_scene(r0):
    # A tank 1.61 m long, 0.6 m high and 0.15 m wide; the column 0.6 m long and H high against the
    # x = 0 end, released at once (their gate clears it in about 0.07 s); sensor 1 on the far wall
    # 3 mm over the bed on the centreline, the square of 6 mm centred there.
    return {
        "name": "sweep_lobovsky",
        "domain": {"min": [0, 0, 0], "max": [1.61, 0.6, 0.15]},
        "fluid": {"rest_density": LOBOVSKY_RHO, "spacing": r0, "viscosity": 0.00089},
        "fluid_blocks": [{"min": [0, 0, 0], "max": [0.6, LOBOVSKY_H, 0.15]}],
        "pressure_sensors": [{"name": "s1", "center": [1.61, 0.003, 0.075], "size": 0.006}],
    }


def lobovsky_measure(meltwater, sim, r0, settle):
    rho_g_h = LOBOVSKY_RHO * 9.81 * LOBOVSKY_H
    scale = math.sqrt(9.81 / LOBOVSKY_H)  # t* per second
    end = settle if settle is not None else 3.0 / scale
    times, loads = [], []
    while sim.time < end:
        report = sim.step()
        times.append(sim.time * scale)
        loads.append(report["sensor_s1"] / rho_g_h)
    arrival = next((t for t, p in zip(times, loads) if p > 0.1), None)
    if arrival is None:
        if settle is None:
            raise meltwater.SimulationError(f"the front did not reach the far wall by t* = {times[-1]:.3g}")
        return {"error": 1.0, "arrival": None}
    k = max(range(len(loads)), key=lambda i: loads[i])
    first = times.index(arrival)
    # The impulse of the first impact, from the arrival to t* 3, in ρ g H × t* (Pa s = that × ρ g H / scale).
    impulse = sum(0.5 * (loads[i] + loads[i + 1]) * (times[i + 1] - times[i]) for i in range(first, len(times) - 1))
    return {"error": abs(arrival - LOBOVSKY_ARRIVAL) / LOBOVSKY_ARRIVAL, "arrival": arrival,
            "peak": loads[k], "peak_at": times[k], "impulse": impulse}


# The floating and held box's pool: a square tank POOL wide, water POOL_DEPTH deep, the box BOX_WIDTH
# square and BOX_HEIGHT tall at its centre.
POOL, POOL_DEPTH, BOX_WIDTH, BOX_HEIGHT = 0.4, 0.2, 0.16, 0.08
POOL_AREA, BOX_FOOTPRINT = POOL * POOL, BOX_WIDTH * BOX_WIDTH


def floating_scene(r0, ratio=0.5):
    # The box's centre where its bottom sits at Archimedes' draft below the surface.
    draft = ratio * BOX_HEIGHT
    centre = POOL / 2
    return {
        "name": "sweep_floating",
        "domain": {"min": [0, 0, 0], "max": [POOL, POOL, POOL]},
        "fluid": {"rest_density": 1000, "spacing": r0, "viscosity": 0.01},
        "fluid_blocks": [{"min": [0, 0, 0], "max": [POOL, POOL_DEPTH, POOL]}],
        "objects": [{"name": "box", "mesh": {"procedural": f"box:x={BOX_WIDTH},y={BOX_HEIGHT},z={BOX_WIDTH}"},
                     "transform": {"translation": [centre, POOL_DEPTH - draft + BOX_HEIGHT / 2, centre]},
                     "kind": "rigid", "density": 1000 * ratio}],
    }


def box_levels(meltwater, sim, r0):
    """The floating and held box's pool, this step: the box's bottom face and three measures of the level."""
    import numpy as np

    pos, kind = sim.position, sim.type
    is_fluid = kind == meltwater.FLUID
    fluid = pos[is_fluid]
    # The bottom face: the lowest vertex of the box's mesh, the face itself, wherever the box's
    # particles sit about it.
    bottom = float(pos[(sim.object == 0) & (kind == meltwater.GEOMETRY), 1].min())
    # By volume: the level at which the fluid, at the volume its lattice started with (r0³ a
    # particle), fills the pool round the box's submerged part.
    volume = (len(fluid) * r0**3 - BOX_FOOTPRINT * bottom) / (POOL_AREA - BOX_FOOTPRINT)
    # By the surface particles, away from the box: the median over r0-wide columns of each
    # column's highest particle, plus r0/2 (a splash's droplets do not move it).
    # Away from the box: 0.05 m (the box's splash and meniscus) past its sides.
    clear = BOX_WIDTH / 2 + 0.05
    far_mask = (np.abs(fluid[:, 0] - POOL / 2) > clear) | (np.abs(fluid[:, 2] - POOL / 2) > clear)
    far = fluid[far_mask]
    column = np.floor(far[:, 0] / r0).astype(int) * 100000 + np.floor(far[:, 2] / r0).astype(int)
    order = np.lexsort((far[:, 1], column))
    last = np.r_[column[order][1:] != column[order][:-1], True]
    tops = float(np.median(far[order][last, 1])) + r0 / 2
    # By pressure: where a line fitted to the pressures away from the box, the walls, the floor and
    # the surface falls to 0.
    p = sim.pressure[is_fluid]
    inner = far_mask & (fluid[:, 0] > 2 * r0) & (fluid[:, 0] < POOL - 2 * r0) & (fluid[:, 2] > 2 * r0) & \
        (fluid[:, 2] < POOL - 2 * r0) & (fluid[:, 1] > 3 * r0) & (fluid[:, 1] < bottom - 2 * r0)
    slope, intercept = np.polyfit(fluid[inner, 1], p[inner], 1) if inner.sum() > 10 else (0.0, 0.0)
    pressure = -intercept / slope if slope < 0 else float("nan")
    return bottom, volume, tops, pressure


def floating_measure(meltwater, sim, r0, settle, ratio=0.5):
    import numpy as np

    archimedes = ratio * BOX_HEIGHT
    window = min(1.0, settle / 2)
    sim.run(until=settle - window)
    drafts = []
    while sim.time < settle:
        sim.step()
        bottom, volume, tops, pressure = box_levels(meltwater, sim, r0)
        drafts.append((volume - bottom, tops - bottom, pressure - bottom))
    table = np.array(drafts)
    draft, by_tops = (float(v) for v in table[:, :2].mean(axis=0))
    # No pressure level where the pool has too few interior particles to fit (r0 0.04 m).
    finite = np.isfinite(table[:, 2])
    by_pressure = float(table[finite, 2].mean()) if finite.any() else float("nan")
    return {"error": abs(draft - archimedes) / archimedes, "draft": draft, "archimedes": archimedes,
            "draft_swing": float(np.ptp([d[0] for d in drafts])), "draft_by_tops": by_tops,
            "draft_by_pressure": by_pressure}


def held_box_scene(r0):
    scene = floating_scene(r0, 0.5)
    box = scene["objects"][0]
    box["kind"] = "rigid"  # every IBP pinned: the lattice, and the mesh and SBPs on it, never move
    box["pinned"] = {"box": {"min": [0, 0, 0], "max": [POOL, POOL, POOL]}}
    return scene


def held_box_measure(meltwater, sim, r0, settle):
    import numpy as np

    sim.run(until=settle - min(0.5, settle / 2))
    lifts, depths = [], []
    while sim.time < settle:
        sim.step()
        bottom, volume, _, _ = box_levels(meltwater, sim, r0)
        lifts.append(float(np.asarray(sim.fluid_force_on_solids())[0, 1]))
        depths.append(volume - bottom)
    rho_g = 1000 * 9.81
    lift, depth = float(np.mean(lifts)), float(np.mean(depths))
    archimedes = rho_g * BOX_FOOTPRINT * depth
    return {"error": abs(lift / archimedes - 1), "lift_ratio": lift / archimedes, "depth": depth,
            "excess_head_r0": (lift / (rho_g * BOX_FOOTPRINT) - depth) / r0}


def stefan_scene(r0, stefan=0.3, layers=10):
    # tests/core/test_stefan.cpp's slab as a scene: a pinned lattice plate at 10 °C with 10⁶ times
    # the liquid's heat capacity (a melting point it never reaches makes it a lattice), and a slab
    # of solid at its melting point 0 °C one spacing from it; no gravity.
    capacity, alpha, width, plate = 4.18e6, 0.08, 8 * r0, 4 * r0
    length = (layers + 4) * r0
    lo = [0.1, 0.1, 0.1]
    side = [lo[1], lo[1] + width]
    def box(x0, x1):
        return {"procedural": f"box:x={x1 - x0:.6g},y={width:.6g},z={width:.6g}"}, [(x0 + x1) / 2, lo[1] + width / 2,
                                                                                  lo[2] + width / 2]
    plate_mesh, plate_centre = box(lo[0], lo[0] + plate)
    slab_mesh, slab_centre = box(lo[0] + plate, lo[0] + plate + length)
    return {
        "name": "sweep_stefan",
        "domain": {"min": [0, 0, 0], "max": [lo[0] + plate + length + 0.1, side[1] + 0.1, side[1] + 0.1]},
        "gravity": [0, 0, 0],
        "fluid": {"rest_density": 1000, "spacing": r0, "viscosity": 0, "thermal_diffusivity": alpha,
                  "heat_capacity": capacity, "temperature": 0},
        "heat": {"enabled": True, "max_substeps": 64},
        "objects": [
            {"name": "plate", "mesh": plate_mesh, "transform": {"translation": plate_centre}, "kind": "elastic",
             "density": 1000, "temperature": 10, "heat_capacity": 1e6 * capacity, "melting_point": 1e4,
             "pinned": {"box": {"min": [0, 0, 0], "max": [lo[0] + plate, 1, 1]}}},
            {"name": "slab", "mesh": slab_mesh, "transform": {"translation": slab_centre}, "kind": "elastic",
             "density": 1000, "temperature": 0, "melting_point": 0, "latent_heat": 10 / stefan * capacity / 1000,
             "pinned": {"box": {"min": [lo[0] + plate, 0, 0], "max": [1, 1, 1]}}},
        ],
    }


def stefan_lambda(stefan):
    lo, hi = 0.0, 3.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid * math.exp(mid * mid) * math.erf(mid) < stefan / math.sqrt(math.pi):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def stefan_measure(meltwater, sim, r0, settle, stefan=0.3, layers=10):
    import numpy as np

    alpha, width = 0.08, 8 * r0
    centre = 0.1 + width / 2
    analytic = stefan_lambda(stefan)
    # 10 layers take (10 r0 / 2λ)² / α; four times that is the limit before calling the front stalled.
    limit = settle if settle is not None else 4 * (layers * r0 / (2 * analytic)) ** 2 / alpha
    x0 = sim.position.copy()
    slab = sim.object == 1
    central = slab & (np.abs(x0[:, 1] - centre) < 2 * r0) & (np.abs(x0[:, 2] - centre) < 2 * r0)
    columns = 16
    crossed, st, tt = 0, 0.0, 0.0
    while sim.time < limit and crossed < layers:
        sim.step()
        melted = np.count_nonzero(central & (sim.type == meltwater.FLUID)) / columns
        while crossed < layers and melted >= crossed + 1:
            crossed += 1
            if crossed > 2:
                root = 2 * math.sqrt(alpha * sim.time)
                st += crossed * r0 * root
                tt += root * root
    if settle is None and crossed < layers:
        raise meltwater.SimulationError(f"the front stalled at {crossed} of {layers} layers by t = {sim.time:.3g} s")
    fitted = st / tt if tt > 0 else 0.0
    return {"error": abs(fitted / analytic - 1), "lambda": fitted, "analytic_lambda": analytic, "layers": crossed}


CASES = {
    # name: (scene, measure, base r0, simulated seconds)
    "hydrostatic": (hydrostatic_scene, hydrostatic_measure, 0.02, 2.0),
    "dam_break": (dam_break_scene, dam_break_measure, 0.01, None),
    "floating": (floating_scene, floating_measure, 0.02, 3.0),
    # The same box at other density ratios, over the spacings only (applies()).
    "floating_0.3": (lambda r0: floating_scene(r0, 0.3), lambda *a: floating_measure(*a, ratio=0.3), 0.02, 3.0),
    "floating_0.9": (lambda r0: floating_scene(r0, 0.9), lambda *a: floating_measure(*a, ratio=0.9), 0.02, 3.0),
    "held_box": (held_box_scene, held_box_measure, 0.02, 2.0),
    "stefan": (stefan_scene, stefan_measure, 0.02, None),
    "lobovsky": (lobovsky_scene, lobovsky_measure, 0.01, None),
}

# ---- the settings: a label, its group, and what it changes (scene keys, or r0's factor) ----------


def settings(quick):
    s = [("defaults", "defaults", {})]
    steps = [("fixed 0.5 ms", {"solver.dt": 0.0005}), ("fixed 2 ms", {"solver.dt": 0.002}),
             ("fixed 4 ms", {"solver.dt": 0.004}),
             ("CFL 0.4 under 5 ms", {"solver.dt_mode": "cfl", "solver.cfl_number": 0.4, "solver.dt": 0.005}),
             ("CFL 0.4 under 30 ms", {"solver.dt_mode": "cfl", "solver.cfl_number": 0.4, "solver.dt": 0.03}),
             ("CFL 1 under 30 ms", {"solver.dt_mode": "cfl", "solver.cfl_number": 1.0, "solver.dt": 0.03})]
    eta = [("eta 0.3%", {"solver.eta": 0.003}), ("eta 3%", {"solver.eta": 0.03}),
           ("no peak bound", {"solver.eta_max": 0})]
    spacing = [("r0 x 2", {"r0_factor": 2.0}), ("r0 x 2/3", {"r0_factor": 2 / 3})]
    kernel = [("cubic h 2.25 r0", {"h_factor": 2.25}),
              ("Wendland h 2 r0", {"fluid.kernel": "wendland_c2"}),
              ("Wendland h 3 r0", {"fluid.kernel": "wendland_c2", "h_factor": 3.0})]
    boundary = [("wall spacing r0", {"boundary.spacing_factor": 1.0}), ("2 wall layers", {"boundary.layers": 2}),
                ("walls' correction off", {"boundary.correction": False})]
    coupling = [("objects' correction off", {"coupling.correction": False})]
    # The step rule at other spacings, for the free-surface flows only (applies()): a CFL rule
    # bounds how far a particle travels, not the error.
    cfl = {"solver.dt_mode": "cfl", "solver.cfl_number": 0.4, "solver.dt": 0.005}
    combined = [("r0 x 2, CFL 0.4 under 5 ms", dict(cfl, r0_factor=2.0)),
                ("r0 x 2/3, CFL 0.4 under 5 ms", dict(cfl, r0_factor=2 / 3)),
                ("r0 x 2/3, CFL 1 under 30 ms", dict(cfl, r0_factor=2 / 3, **{"solver.cfl_number": 1.0,
                                                                              "solver.dt": 0.03}))]
    if quick:
        steps = [steps[1], steps[3], steps[5]]
        eta = eta[1:2]
        spacing = spacing[:1]
        kernel = kernel[1:2]
        boundary = boundary[2:]
        combined = combined[:1]
    for group, items in (("step", steps), ("eta", eta), ("spacing", spacing), ("kernel", kernel),
                         ("boundary", boundary), ("coupling", coupling), ("spacing and step", combined)):
        s += [(label, group, change) for label, change in items]
    return s


def applies(case, change):
    if case.startswith("floating_"):
        return not change or set(change) == {"r0_factor"}
    if "r0_factor" in change and len(change) > 1:
        return case in ("dam_break", "lobovsky")
    return not ("coupling.correction" in change and case not in ("floating", "held_box"))


# ---- one point, in its own process ----------------------------------------------------------------


def run_point(spec):
    """Runs one case at one setting; prints one JSON line."""
    import meltwater

    scene_fn, measure, base_r0, seconds = CASES[spec["case"]]
    change = dict(spec["change"])
    r0 = base_r0 * change.pop("r0_factor", 1.0)
    h_factor = change.pop("h_factor", None)
    scene = scene_fn(r0)
    if h_factor:
        change["fluid.support_radius"] = h_factor * r0
    if spec.get("smoke"):
        seconds = 0.4 if spec["case"].startswith("floating") or spec["case"] == "held_box" else {"stefan": 0.2}.get(spec["case"], 0.1)
    out = {"status": "ok"}
    started = time.monotonic()
    try:
        sim = meltwater.Simulation(meltwater.Scene(scene, overrides=change), backend="openmp", threads=spec["threads"])
        result = measure(meltwater, sim, r0, seconds)
        out.update(result)
        out.update(sim_stats(sim))
    except meltwater.SimulationError as e:
        out = {"status": "failed", "message": str(e)}
    out["wall_s"] = time.monotonic() - started
    out["r0"] = r0
    print(json.dumps(out))


def sim_stats(sim):
    """Cost over the whole run, from the per-step statistics the simulation keeps."""
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "stats.csv")
        sim.write_stats(path)
        rows = list(csv.DictReader(open(path)))
    total_ms = sum(float(r["ms_total"]) for r in rows)
    iterations = sum(float(r["iterations"]) for r in rows)
    simulated = float(rows[-1]["time"])
    return {"steps": len(rows), "simulated_s": simulated, "ms_per_simulated_s": total_ms / simulated,
            "iterations_per_step": iterations / len(rows), "halvings": int(sum(float(r["dt_retries"]) for r in rows))}


# ---- the sweep: every point in a child process, then the CSV, the plot and the report ------------


def device_name():
    model = platform.processor() or "CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{os.cpu_count()} cores, {model}"


def run_child(spec, pythonpath, timeout):
    env = dict(os.environ, PYTHONPATH=pythonpath)
    try:
        done = subprocess.run([sys.executable, os.path.abspath(__file__), "--point", json.dumps(spec)], env=env,
                              capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"status": "failed", "message": f"ran past the sweep's {timeout} s limit a point"}
    lines = [l for l in done.stdout.splitlines() if l.startswith("{")]
    if done.returncode != 0 or not lines:
        tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
        return {"status": "failed", "message": f"exit {done.returncode}: {tail}"}
    return json.loads(lines[-1])


def pareto(points):
    """The points no other point beats on both cost and error, cheapest first."""
    ok = sorted((p for p in points if p["status"] == "ok"), key=lambda p: (p["ms_per_simulated_s"], p["error"]))
    front, best = [], math.inf
    for p in ok:
        if p["error"] < best:
            front.append(p)
            best = p["error"]
    return front


PURPOSES = [
    # name, the rule that picks its point among the case's successful runs
    ("preview", "the cheapest point with an error under 10%", lambda p: p["error"] < 0.10),
    ("production", "the cheapest point with an error under 3%", lambda p: p["error"] < 0.03),
    ("validation", "the point with the smallest error", None),
]


def pick(points, rule):
    ok = [p for p in points if p["status"] == "ok"]
    if rule is None:
        return min(ok, key=lambda p: p["error"]) if ok else None
    fitting = [p for p in ok if rule(p)]
    return min(fitting, key=lambda p: p["ms_per_simulated_s"]) if fitting else None


COLUMNS = ["case", "setting", "group", "status", "error", "ms_per_simulated_s", "iterations_per_step", "steps",
           "halvings", "simulated_s", "wall_s", "r0", "pareto", "details", "message"]


def write_outputs(rows, out_dir, device, command, quick):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = [c for c in CASES if any(r["case"] == c for r in rows)]
    for c in cases:
        for p in pareto([r for r in rows if r["case"] == c]):
            p["pareto"] = True
    with open(os.path.join(out_dir, "sweep.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(dict(r, pareto=int(bool(r.get("pareto")))))

    groups = sorted({r["group"] for r in rows})
    colours = dict(zip(groups, plt.rcParams["axes.prop_cycle"].by_key()["color"] * 3))
    ncols = min(2, len(cases))
    nrows = (len(cases) + ncols - 1) // ncols
    fig, axes = plt.subplots(nrows, ncols, figsize=(7.0 * ncols, 5.2 * nrows), squeeze=False)
    for ax in axes.flat[len(cases):]:
        ax.axis("off")
    for ax, c in zip(axes.flat, cases):
        pts = [r for r in rows if r["case"] == c and r["status"] == "ok"]
        for g in groups:
            sel = [r for r in pts if r["group"] == g]
            if sel:
                ax.scatter([r["ms_per_simulated_s"] / 1000 for r in sel], [max(r["error"], 1e-4) * 100 for r in sel],
                           color=colours[g], label=g, s=36, zorder=3)
        for r in pts:
            ax.annotate(r["setting"], (r["ms_per_simulated_s"] / 1000, max(r["error"], 1e-4) * 100), fontsize=7,
                        xytext=(4, 3), textcoords="offset points")
        front = pareto(pts)
        ax.step([r["ms_per_simulated_s"] / 1000 for r in front], [max(r["error"], 1e-4) * 100 for r in front],
                where="post", color="black", lw=1.2, label="Pareto front", zorder=2)
        failed = [r["setting"] for r in rows if r["case"] == c and r["status"] != "ok"]
        if failed:
            ax.text(0.02, 0.02, "failed: " + ", ".join(failed), transform=ax.transAxes, fontsize=7, color="crimson",
                    wrap=True)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("cost: wall seconds per simulated second")
        ax.set_ylabel("error, %")
        ax.set_title(c)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"Meltwater: error against cost ({device}, OpenMP)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "sweep.png"), dpi=110)

    lines = [f"# Speed–accuracy sweep{' (quick)' if quick else ''}", "",
             f"- device: {device}, OpenMP, float unless a row says double",
             f"- command: {command}",
             f"- date: {datetime.date.today().isoformat()}",
             "- cases, measures and settings: `bench/sweep.py`'s docstring and docs/validation.md, "
             "\"The speed–accuracy trade\"; the plot: `sweep.png`; every number: `sweep.csv`",
             "- cost: wall milliseconds per simulated second over the whole run (sum of `ms_total`), on a VM "
             "that drifts 20–50% between runs: compare within this report only", ""]
    for c in cases:
        pts = [r for r in rows if r["case"] == c]
        lines += [f"## {c}", "", "| setting | error | ms per simulated s | iterations/step | steps | halvings | Pareto | details |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- |"]
        for r in sorted(pts, key=lambda r: (r["status"] != "ok", r.get("ms_per_simulated_s") or 0)):
            if r["status"] != "ok":
                lines.append(f"| {r['setting']} | failed | | | | | | {r.get('message', '')[:160]} |")
                continue
            lines.append(f"| {r['setting']} | {100 * r['error']:.2f}% | {r['ms_per_simulated_s']:.0f} | "
                         f"{r['iterations_per_step']:.1f} | {r['steps']} | {r['halvings']} | "
                         f"{'yes' if r.get('pareto') else ''} | {r.get('details', '')} |")
        lines += ["", "| purpose | rule | setting | error | ms per simulated s |", "| --- | --- | --- | --- | --- |"]
        for name, text, rule in PURPOSES:
            p = pick(pts, rule)
            if p:
                error, cost = "%.2f%%" % (100 * p["error"]), "%.0f" % p["ms_per_simulated_s"]
                lines.append(f"| {name} | {text} | {p['setting']} | {error} | {cost} |")
            else:
                lines.append(f"| {name} | {text} | none meets it | | |")
        lines.append("")
    with open(os.path.join(out_dir, "report.md"), "w") as f:
        f.write("\n".join(lines))


def read_rows(path):
    """A sweep.csv's points, their numbers parsed."""
    rows = []
    for r in csv.DictReader(open(path)):
        for k in ("error", "ms_per_simulated_s", "iterations_per_step", "simulated_s", "wall_s", "r0"):
            r[k] = float(r[k]) if r.get(k) else None
        for k in ("steps", "halvings"):
            r[k] = int(float(r[k])) if r.get(k) else None
        r["pareto"] = False
        rows.append(r)
    return rows


def replot(out_dir):
    """Redraws sweep.png and report.md from out_dir/sweep.csv, keeping the report's device and command."""
    path = os.path.join(out_dir or "", "sweep.csv")
    if not out_dir or not os.path.isfile(path):
        print(f"sweep.py: --replot needs a folder with a sweep.csv (got {out_dir!r})", file=sys.stderr)
        return 2
    rows = read_rows(path)
    report = os.path.join(out_dir, "report.md")
    head = open(report).read().splitlines() if os.path.isfile(report) else []
    device = next((l.split(": ", 1)[1].split(", OpenMP")[0] for l in head if l.startswith("- device: ")), device_name())
    command = next((l[len("- command: "):] for l in head if l.startswith("- command: ")), "`bench/sweep.py`")
    write_outputs(rows, out_dir, device, command, "(quick)" in (head[0] if head else ""))
    print(f"sweep.py: redrew {out_dir}/sweep.png and report.md from {len(rows)} points")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", help="output folder (default bench/results/DATE-cpu-Nthreads-sweep)")
    parser.add_argument("--build", default=os.path.join(ROOT, "build"), help="the build with the Python module")
    parser.add_argument("--double-build", help="a -DMELTWATER_DOUBLE=ON build: adds the defaults in double")
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated cases (default: all)")
    parser.add_argument("--quick", action="store_true", help="fewer settings, no finer spacing")
    parser.add_argument("--smoke", action="store_true", help="the defaults only, each case cut short")
    parser.add_argument("--threads", type=int, default=0, help="OpenMP threads (default: all cores)")
    parser.add_argument("--timeout", type=int, default=900, help="seconds a point may take (default 900)")
    parser.add_argument("--replot", action="store_true", help="redraw OUT's plot and report from its sweep.csv")
    parser.add_argument("--only", help="only the settings whose label contains this text (e.g. CFL)")
    parser.add_argument("--base", help="a sweep folder whose other points complete this run's (rerun the points a "
                                       "change touches)")
    parser.add_argument("--point", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.point:
        run_point(json.loads(args.point))
        return 0
    if args.replot:
        return replot(args.out)
    cases = [c for c in args.cases.split(",") if c]
    unknown = [c for c in cases if c not in CASES]
    if unknown:
        print(f"sweep.py: unknown case {unknown[0]!r} (cases: {', '.join(CASES)})", file=sys.stderr)
        return 2
    if args.base and not os.path.isfile(os.path.join(args.base, "sweep.csv")):
        # Checked before any point runs: the base is read only once the run's points are done.
        print(f"sweep.py: --base needs a sweep folder with a sweep.csv (got {args.base!r})", file=sys.stderr)
        return 2
    pythonpath = os.path.join(os.path.abspath(args.build), "python")
    if not any(n.startswith("meltwater") for n in (os.listdir(pythonpath) if os.path.isdir(pythonpath) else [])):
        print(f"sweep.py: no Python module in {pythonpath}: build it (cmake --build {args.build} --target "
              "meltwater_python) or name the build with --build", file=sys.stderr)
        return 2
    device = device_name()
    if args.out:
        out_dir = args.out
    else:
        threads = args.threads or os.cpu_count()
        out_dir = os.path.join(HERE, "results", f"{datetime.date.today().isoformat()}-cpu-{threads}threads-sweep")
    os.makedirs(out_dir, exist_ok=True)
    points = [("defaults", "defaults", {})] if args.smoke else settings(args.quick)
    plan = [(c, label, group, change) for c in cases for label, group, change in points if applies(c, change)]
    if args.only:
        plan = [p for p in plan if args.only in p[1]]
    if args.double_build:
        plan += [(c, "defaults, double", "precision", {"__build": args.double_build}) for c in cases]
    rows = []
    started = time.monotonic()
    for n, (case, label, group, change) in enumerate(plan, 1):
        build = change.get("__build")
        change = {k: v for k, v in change.items() if k != "__build"}
        path = os.path.join(os.path.abspath(build), "python") if build else pythonpath
        spec = {"case": case, "change": change, "threads": args.threads, "smoke": args.smoke}
        result = run_child(spec, path, args.timeout)
        row = {"case": case, "setting": label, "group": group}
        row.update(result)
        extra = {k: v for k, v in result.items() if k not in COLUMNS and k not in ("status",)}
        row["details"] = ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in extra.items())
        rows.append(row)
        shown = f"error {100 * result['error']:.2f}%, {result['ms_per_simulated_s']:.0f} ms/simulated s" \
            if result["status"] == "ok" else f"failed: {result.get('message', '')[:120]}"
        print(f"[{n}/{len(plan)}, {time.monotonic() - started:.0f} s] {case}, {label}: {shown}", flush=True)
    command = "bench/sweep.py " + " ".join(a for a in sys.argv[1:])
    if args.base:
        rerun = {(r["case"], r["setting"]) for r in rows}
        kept = [r for r in read_rows(os.path.join(args.base, "sweep.csv")) if (r["case"], r["setting"]) not in rerun]
        rows = kept + rows
        command += f" (the other {len(kept)} points from {args.base})"
    write_outputs(rows, out_dir, device, f"`{command.strip()}`", args.quick)
    print(f"sweep.py: {len(rows)} points; results in {out_dir} (sweep.csv, sweep.png, report.md)")
    failed = sum(r["status"] != "ok" for r in rows)
    return 1 if args.smoke and failed else 0


if __name__ == "__main__":
    sys.exit(main())
