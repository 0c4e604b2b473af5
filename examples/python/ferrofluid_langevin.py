"""Magnetisation curve of a ferrofluid against the Langevin function.

The scene of examples/ferrofluid.toml (Brownian dynamics, LJ units, k_BT = 1,
μ₀ = 4π, m = √3) at Langevin parameters α = μ₀mH/k_BT from 0.25 to 8: once
with the dipoles' interactions switched off, where the magnetisation along
the field is exactly M/M_s = L(α) = coth α − 1/α, and once with dipole–dipole
forces and WCA repulsion (λ = 3), which lift it above L(α). Writes
ferrofluid_langevin.png (or $MOTE_EXAMPLE_OUT/...).

    python examples/python/ferrofluid_langevin.py
"""

import os
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import mote

small = os.environ.get("MOTE_EXAMPLE_SMALL") == "1"
out = os.environ.get("MOTE_EXAMPLE_OUT", ".")
here = os.path.dirname(os.path.abspath(__file__))
with open(os.path.join(here, "..", "ferrofluid.toml")) as f:
    base = f.read()
m = np.sqrt(3.0)
alphas = [0.5, 2.0, 8.0] if small else [0.25, 0.5, 1.0, 2.0, 4.0, 8.0]
until = 2.0 if small else 10.0


def magnetisation(alpha, interacting):
    text = re.sub(r"h = \[0.0, 0.0, [0-9.e-]+\]", f"h = [0.0, 0.0, {float(alpha / (4 * np.pi * m))!r}]", base)
    text = text.replace("until = 10.0", f"until = {until}")
    if small:
        text = text.replace("n = [10, 10, 10]", "n = [5, 5, 5]")
    if not interacting:
        text = re.sub(r"\[dipolar\].*?\n\n", "", text, flags=re.S)
    sim = mote.Simulation.from_toml(text, seed=3)
    sim.run()
    obs = sim.observables
    late = obs["time"] > 0.5 * until
    return obs["magnetisation"][late, 2].mean() / (len(sim) * m)


def langevin(a):
    return 1.0 / np.tanh(a) - 1.0 / a


ideal = [magnetisation(a, False) for a in alphas]
dense = [magnetisation(a, True) for a in alphas]
grid = np.linspace(0.05, max(alphas), 200)
plt.figure(figsize=(6.5, 4.5))
plt.plot(grid, langevin(grid), "k-", lw=1, label="Langevin L(α)")
plt.plot(alphas, ideal, "o", label="mote, no interactions")
plt.plot(alphas, dense, "s", label="mote, λ = 3 (dipolar + WCA)")
plt.xlabel("α = μ₀ m H / k_BT")
plt.ylabel("M / M_s")
plt.legend()
plt.tight_layout()
plt.savefig(os.path.join(out, "ferrofluid_langevin.png"), dpi=100)
for a, i, d in zip(alphas, ideal, dense):
    print(f"α = {a:5.2f}: L = {langevin(a):.3f}, ideal {i:.3f}, interacting {d:.3f}")
