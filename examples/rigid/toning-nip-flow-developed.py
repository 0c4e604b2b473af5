#!/usr/bin/env python3
"""The developed mass per area of a flowing toning nip, from its outflow.csv.

In steady flow the toner the belt carries out of the nip is the developed
toner: the belt outlet (outlet 0 of example:toning-nip-flow) takes the toner
lying on the belt at the exit. Each is on the image or the background by its
x in the belt's frame, x - v t (mod L), when it left; the mass on each over
the belt area that passed the exit under it in [t0, t1) is the developed
mass per area (1 kg/m² = 100 mg/cm²). Give whole periods of the image
(1 ms in the example).

    examples/rigid/toning-nip-flow-developed.py OUT/outflow.csv T0 T1 [SCENE]

SCENE (default examples/rigid/toning-nip-flow.toml) gives the box, the
belt's speed and the patches ([rigid.latent_image]).
"""
import sys
import tomllib

if len(sys.argv) not in (4, 5):
    sys.exit(__doc__)
outflow, t0, t1 = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
scene = sys.argv[4] if len(sys.argv) == 5 else "examples/rigid/toning-nip-flow.toml"
with open(scene, "rb") as f:
    s = tomllib.load(f)
(x_lo, y_lo, _), (x_hi, y_hi, _) = s["box"]["lo"], s["box"]["hi"]
period, width = x_hi - x_lo, y_hi - y_lo
image = s["rigid"]["latent_image"]
speed, patches = image["speed"], [(p[0], p[1]) for p in image["patches"]]
share = sum(b - a for a, b in patches) / period

mass = {"image": 0.0, "background": 0.0}
count = 0
for line in open(outflow):
    if line.startswith("#") or line.startswith("step"):
        continue
    row = [float(v) for v in line.split(",")]
    t, outlet, m, x = row[1], row[3], row[4], row[7]
    if outlet != 0 or not t0 <= t < t1:
        continue
    u = (x - speed * t - x_lo) % period
    mass["image" if any(a <= u < b for a, b in patches) else "background"] += m
    count += 1
area = speed * width * (t1 - t0)
print(
    f"{count} toner left on the belt in [{t0}, {t1}): "
    f"M/A image {100 * mass['image'] / (area * share):.4f} mg/cm², "
    f"background {100 * mass['background'] / (area * (1 - share)):.4f} mg/cm²"
)
