#!/usr/bin/env python3
"""The dam break's surge front against Martin & Moyce (1952), from Python.

A notebook in cells (`# %%`): run it whole,

    PYTHONPATH=build/python /usr/bin/python3 examples/dam_break_front.py front.png

or cell by cell in an editor that knows the markers. It runs the built-in dam break with its
column made a wide and 2a high (n^2 = 2, the case of Martin & Moyce's tables), follows the surge
front and the column's residual height step by step, and plots both against the experiment,
measured as docs/validation.md measures them (tests/core/test_dam_break.cpp):

- the front Z = x/a against T = t sqrt(2g/a), x the fluid's leading edge: the farthest fluid
  particle centre plus r0/2;
- the height H/(2a) against tau = t sqrt(g/a), from the highest fluid particle above the column's
  footprint (x < a), plus r0/2.

The tank is the built-in scene's, 1.6 m long: with a = 0.4 m the front reaches Z = 3, the end of
the experiment's table, at T = 2.5, 0.36 s of simulated time.
"""

# %% Set-up: the module (built into build/python), the arguments, matplotlib without a display.
import argparse
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import meltwater

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("png", help="where to save the plot (PNG)")
parser.add_argument("--spacing", type=float, default=0.02,
                    help="fluid.spacing r0, m (default 0.02, the built-in scene's: 32,000 fluid particles)")
parser.add_argument("--backend", default="auto", help="auto, cuda or openmp (default auto)")
parser.add_argument("--threads", type=int, default=0, help="OpenMP threads (default: all cores)")
args = parser.parse_args()

# %% Martin & Moyce (1952), n^2 = 2: their Tables 2 and 6 as docs/validation.md gives them.
T_MM = [0.41, 0.84, 1.19, 1.43, 1.63, 1.83, 1.98, 2.20, 2.32, 2.51]
Z_MM = [1.11, 1.22, 1.44, 1.67, 1.89, 2.11, 2.33, 2.56, 2.78, 3.00]
TAU_MM = [0.56, 0.77, 0.93, 1.08, 1.28, 1.46, 1.66, 1.84]
H_MM = [0.94, 0.89, 0.83, 0.78, 0.72, 0.67, 0.61, 0.56]

# %% The scene: the built-in dam break, its column a = 0.4 m wide and 2a = 0.8 m high.
a = 0.4
try:
    scene = meltwater.Scene(overrides={"fluid_blocks.0.max": [a, 2 * a, 0.8], "fluid.spacing": args.spacing})
    sim = meltwater.Simulation(scene, backend=args.backend, threads=args.threads)
except (meltwater.InputError, meltwater.DeviceError) as e:
    sys.exit(f"dam_break_front.py: {e}")
g = -scene.to_dict()["gravity"][1]
r0 = scene.spacing
T_of_t, tau_of_t = math.sqrt(2 * g / a), math.sqrt(g / a)
print(f"{sim.counts['fluid']:,} fluid particles at r0 = {r0:g} m on {sim.backend} ({sim.device})")

# %% The run: after each step, the front and the height from the particles' positions.
fluid = sim.type == meltwater.FLUID  # the scene's order: a particle keeps its index
t, front, height = [0.0], [1.0], [1.0]  # before the first step: the column's own edge and top
while t[-1] * T_of_t < T_MM[-1] or t[-1] * tau_of_t < TAU_MM[-1]:
    sim.step()
    x = sim.position[fluid]
    t.append(sim.time)
    front.append((x[:, 0].max() + r0 / 2) / a)
    over_column = x[:, 0] < a
    height.append((x[over_column, 1].max() + r0 / 2) / (2 * a))
report = sim.last_report
print(f"{report['step']} steps to t = {sim.time:.3f} s; {report['lost_particles']} particles lost")

# %% The comparison at the experiment's times.
t = np.array(t)
Z = np.interp(T_MM, t * T_of_t, front)
H = np.interp(TAU_MM, t * tau_of_t, height)
print("   T   Z simulated  Martin & Moyce  deviation")
for T_k, z, z_mm in zip(T_MM, Z, Z_MM):
    print(f"{T_k:5.2f}  {z:10.3f}  {z_mm:14.2f}  {100 * (z - z_mm) / z_mm:+8.1f}%")
print(" tau   H simulated  Martin & Moyce  deviation")
for tau_k, h, h_mm in zip(TAU_MM, H, H_MM):
    print(f"{tau_k:5.2f}  {h:10.3f}  {h_mm:14.2f}  {100 * (h - h_mm) / h_mm:+8.1f}%")

# %% The plot.
fig, (ax_front, ax_height) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
ax_front.plot(t * T_of_t, front, label=f"Meltwater, r0 = a/{a / r0:.0f}")
ax_front.plot(T_MM, Z_MM, "o", label="Martin & Moyce (1952)")
ax_front.set(xlabel="T = t sqrt(2g/a)", ylabel="Z = x/a", title="surge front", xlim=(0, T_MM[-1] * 1.05))
ax_height.plot(t * tau_of_t, height, label=f"Meltwater, r0 = a/{a / r0:.0f}")
ax_height.plot(TAU_MM, H_MM, "o", label="Martin & Moyce (1952)")
ax_height.set(xlabel="tau = t sqrt(g/a)", ylabel="H/(2a)", title="residual column height",
              xlim=(0, TAU_MM[-1] * 1.05))
for ax in (ax_front, ax_height):
    ax.grid(alpha=0.3)
    ax.legend()
fig.suptitle(f"Dam break, n² = 2, a = {a} m ({sim.counts['fluid']:,} fluid particles, {sim.backend})")
fig.savefig(args.png, dpi=120)
print(f"plot in {args.png}")
