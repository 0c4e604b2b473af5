"""Overhead of the Python API (issue 18): sim.step(1) against one step
inside sim.run on a 1000-atom LJ liquid, and the hand-over of a 10^6-particle
positions array (a view, no copy). Needs `import mote` built in release
(pip install ./crates/mote-py). Median of 5 repeats, CPU time of this process.

    python bench/python_overhead.py
"""

import statistics
import time

import numpy as np

import mote

LJ = """
units = "lj"
seed = 1
[run]
integrator = "leapfrog"
dt = 0.005
[lennard_jones]
cutoff = 2.5
skin = 0.3
[[fcc]]
cells = {cells}
density = 0.8442
kt = 1.44
[output]
observables_every = 100
trajectory_every = 0
"""

STEPS = 2000


def per_step(kind):
    sim = mote.Simulation.from_toml(LJ.format(cells="[5, 5, 10]"))
    assert len(sim) == 1000
    sim.run(steps=100)  # warm: lists built, caches filled
    t0 = time.process_time()
    if kind == "run":
        sim.run(steps=STEPS)
    else:
        for _ in range(STEPS):
            sim.step(1)
    return (time.process_time() - t0) / STEPS


runs = [per_step("run") for _ in range(5)]
steps = [per_step("step") for _ in range(5)]
r, s = statistics.median(runs), statistics.median(steps)
print(f"1000-atom LJ: {r * 1e6:.1f} µs per step inside run, {s * 1e6:.1f} µs per step(1): overhead {100 * (s / r - 1):+.1f} %")

big = mote.Simulation.from_toml(LJ.format(cells="[63, 63, 63]"))
n = len(big)
t0 = time.perf_counter()
for _ in range(1000):
    x = big.positions
hand_over = (time.perf_counter() - t0) / 1000
copy0 = time.perf_counter()
y = np.array(x)
copy = time.perf_counter() - copy0
print(f"{n} positions: handed over in {hand_over * 1e6:.1f} µs (view: base is the simulation: {x.base is big}, shares memory with a second access: {np.shares_memory(x, big.positions)}); a copy would take {copy * 1e3:.1f} ms")

# The cost of a callback: every step, a no-op, against the same run without.
def with_callback(every):
    sim = mote.Simulation.from_toml(LJ.format(cells="[5, 5, 10]"))
    sim.run(steps=100)
    t0 = time.process_time()
    sim.run(steps=STEPS, callback=(lambda s: None) if every else None, every=every or 100)
    return time.process_time() - t0


plain = statistics.median(with_callback(0) for _ in range(5))
called = statistics.median(with_callback(1) for _ in range(5))
print(f"a callback every step: {(called - plain) / STEPS * 1e6:.1f} µs per call ({100 * (called / plain - 1):+.1f} % on this run)")
