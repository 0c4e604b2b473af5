"""Inverse design with the rod-packing estimator: φ_rcp of lognormal size
distributions against their width, and of binary mixtures against the
fraction of large spheres (size ratio 4), the sweeps a formulator runs.
Writes rcp_sweep.png (or $MOTE_EXAMPLE_OUT/rcp_sweep.png).

    python examples/python/rcp_sweep.py
"""

import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import mote

small = os.environ.get("MOTE_EXAMPLE_SMALL") == "1"
out = os.environ.get("MOTE_EXAMPLE_OUT", ".")
count = 8 if small else 40

sigmas = np.linspace(0.0, 1.0, count)
phi_lognormal = [mote.rcp(sigma=s) if s > 0 else mote.rcp(diameters=[1.0]) for s in sigmas]
fractions = np.linspace(0.0, 1.0, count)
phi_binary = [mote.rcp(diameters=[1.0, 4.0], volumes=[1 - f, f]) if 0 < f < 1 else mote.rcp(diameters=[1.0]) for f in fractions]
best = fractions[int(np.argmax(phi_binary))]

fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
a.plot(sigmas, phi_lognormal, "o-", ms=3)
a.set_xlabel("log-width σ")
a.set_ylabel("φ_rcp")
a.set_title("lognormal")
b.plot(fractions, phi_binary, "o-", ms=3)
b.axvline(best, color="grey", ls="--", lw=0.5)
b.set_xlabel("volume fraction of the large spheres")
b.set_title(f"binary, size ratio 4: best at {best:.2f}")
fig.tight_layout()
fig.savefig(os.path.join(out, "rcp_sweep.png"), dpi=100)
print(f"lognormal σ = 1: φ = {phi_lognormal[-1]:.4f}; binary optimum {max(phi_binary):.4f} at {best:.2f}")
