#!/usr/bin/env python3
"""Granular settling with its particles in space order (BENCHMARKS.md,
"...particles in space order measured"): writes DIR/data.sorted, the
atoms of ../shared/bench/data.cloud10k sorted along a Morton (Z-order)
curve of cells of one diameter (4 mm) and renumbered in that order, and
DIR/settle-sorted.toml and DIR/settle-file.toml, bench/settle.toml
reading the sorted file and the file as it is, both with `[granular]
order = "file"` (stored as read: the experiment of stop 64). Since stop
65 mote sorts a granular scene's particles itself (`order = "space"`, the
default), so bench/settle.toml beside settle-file.toml measures that:

    mote -q --threads 1 run bench/settle.toml -o /tmp/sfc/space

    python3 bench/space-order.py /tmp/sfc
    mote -q --threads 1 run /tmp/sfc/settle-file.toml -o /tmp/sfc/file
    mote -q --threads 1 run /tmp/sfc/settle-sorted.toml -o /tmp/sfc/sorted
"""
import pathlib
import sys

if len(sys.argv) != 2:
    sys.exit(__doc__)
out = pathlib.Path(sys.argv[1]).resolve()
out.mkdir(parents=True, exist_ok=True)
bench = pathlib.Path(__file__).resolve().parent
data = (bench / "../../shared/bench/data.cloud10k").resolve()

lines = data.read_text().split("\n")
at = next(k for k, l in enumerate(lines) if l.startswith("Atoms"))
atoms = [l.split() for l in lines[at + 2:] if l.strip()]


def morton(x, y, z, cell=0.004):
    """Interleaved bits of the cell's integer coordinates (10 an axis)."""
    c = [int(v / cell) for v in (x, y, z)]
    return sum(((c[a] >> b) & 1) << (3 * b + a) for b in range(10) for a in range(3))


atoms.sort(key=lambda a: morton(*map(float, a[4:7])))
body = [" ".join([str(k + 1)] + a[1:]) for k, a in enumerate(atoms)]
(out / "data.sorted").write_text("\n".join(lines[: at + 2] + body) + "\n")

scene = (bench / "settle.toml").read_text()
name = "../../shared/bench/data.cloud10k"
assert name in scene
skin = "skin = 0.001"
assert skin in scene
scene = scene.replace(skin, 'order = "file"      # stored as read\n' + skin, 1)
(out / "settle-sorted.toml").write_text(scene.replace(name, str(out / "data.sorted")))
(out / "settle-file.toml").write_text(scene.replace(name, str(data)))
