"""The Earth around the Sun (examples/sun-earth.toml) with its energy.

Runs the built-in example from Python, records the Earth's path with a
callback, and plots the orbit and the relative energy error of leap-frog
(bounded, no drift). Writes orbit.png (or $MOTE_EXAMPLE_OUT/orbit.png).

    python examples/python/orbit.py
"""

import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import mote

small = os.environ.get("MOTE_EXAMPLE_SMALL") == "1"
out = os.environ.get("MOTE_EXAMPLE_OUT", ".")

sim = mote.Simulation.from_file("example:sun-earth")
path = []
sim.run(until=365.25 if small else 3652.5, callback=lambda s: path.append(s.positions[1].copy()), every=4)
path = np.array(path)
obs = sim.observables
error = (obs["total"] - obs["total"][0]) / abs(obs["total"][0])

fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4.5))
a.plot(path[:, 0], path[:, 1], lw=0.8)
a.plot([0], [0], "o", color="gold", ms=12)
a.set_aspect("equal")
a.set_xlabel("x (AU)")
a.set_ylabel("y (AU)")
a.set_title("Earth's orbit")
b.plot(obs["time"], error)
b.set_xlabel("t (days)")
b.set_ylabel("(E − E₀)/|E₀|")
b.set_title(f"leap-frog, dt = {sim.dt} d: max |ΔE/E| = {np.abs(error).max():.1e}")
fig.tight_layout()
fig.savefig(os.path.join(out, "orbit.png"), dpi=100)
print(f"t = {sim.time} days, {sim.steps} steps, max |ΔE/E| = {np.abs(error).max():.2e}")
