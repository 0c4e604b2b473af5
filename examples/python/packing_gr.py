"""A jammed packing of equal spheres and its pair correlation g(r).

Grows N spheres to jamming (Lubachevsky–Stillinger, mote.pack), then
histograms the pair distances in the periodic box: the contact peak at
r = d and the split second peak at √3 d and 2d of random close packing.
Writes packing_gr.png (or $MOTE_EXAMPLE_OUT/packing_gr.png).

    python examples/python/packing_gr.py
"""

import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import mote

small = os.environ.get("MOTE_EXAMPLE_SMALL") == "1"
out = os.environ.get("MOTE_EXAMPLE_OUT", ".")
n = 200 if small else 2000

p = mote.pack(n, seed=1, max_pressure=1e6 if small else 1e12)
x, r, box = p["positions"], p["radii"], p["box"]
d = 2 * r.mean()
# All pair distances under the minimum image (O(N²), fine for a few thousand).
delta = x[:, None, :] - x[None, :, :]
delta -= box * np.round(delta / box)
dist = np.sqrt((delta**2).sum(-1))[np.triu_indices(n, 1)] / d
rmax = 0.5 * box.min() / d
hist, edges = np.histogram(dist, bins=200, range=(0.5, rmax))
centres = 0.5 * (edges[1:] + edges[:-1])
shell = 4 / 3 * np.pi * (edges[1:] ** 3 - edges[:-1] ** 3) * d**3
density = n / np.prod(box)
g = hist / (0.5 * n * density * shell)

plt.figure(figsize=(7, 4))
plt.plot(centres, g, lw=1)
for mark in (1.0, np.sqrt(3), 2.0):
    plt.axvline(mark, color="grey", lw=0.5, ls="--")
plt.xlabel("r / d")
plt.ylabel("g(r)")
plt.title(f"{n} spheres, φ = {p['phi']:.4f}, Z = {p['pressure']:.1e}")
plt.tight_layout()
plt.savefig(os.path.join(out, "packing_gr.png"), dpi=100)
print("\n".join(p["summary"]))
