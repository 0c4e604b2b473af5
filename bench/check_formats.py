#!/usr/bin/env python3
"""Check that other programs read mote's trajectory files as mote means them.

Usage: check_formats.py DIR

DIR holds what crates/mote-io/tests/formats.rs writes: t.xyz (extended XYZ),
t.dump (LAMMPS dump text), t.gsd (HOOMD's GSD), t.vtu and t.vtp (VTK XML) and expected.json (positions,
velocities, cell vectors and origin of every frame). The extended XYZ is read with ASE, the dump
and GSD with MDAnalysis, the GSD with gsd, the VTU with meshio, and all but the
VTU with OVITO; positions and box must agree to 1e-6
(relative). Exit status: 0 all agree, 1 a mismatch, 77 skipped (a package is
missing: `pip install ase MDAnalysis meshio`; gsd and ovito are checked
where they import).
"""
import json
import os
import sys
import warnings


def close(a, b, tol=1e-6):
    a = [float(x) for x in a]
    b = [float(x) for x in b]
    return len(a) == len(b) and all(abs(x - y) <= tol * max(1.0, abs(y)) for x, y in zip(a, b))


def flat(rows):
    return [x for r in rows for x in r]


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    d = sys.argv[1]
    try:
        import numpy as np
        import ase.io
        import MDAnalysis
        import meshio
    except ImportError as e:
        print(f"SKIP: {e.name} is not importable; run `pip install ase MDAnalysis meshio`")
        return 77
    warnings.filterwarnings("ignore")
    with open(os.path.join(d, "expected.json")) as f:
        want = json.load(f)
    failures = []

    def check(what, ok):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            failures.append(what)

    # Extended XYZ with ASE: positions, cell vectors (rows) per frame.
    atoms = ase.io.read(os.path.join(d, "t.xyz"), index=":")
    check(f"ASE reads {len(want)} frames of t.xyz", len(atoms) == len(want))
    for k, (a, w) in enumerate(zip(atoms, want)):
        # A periodic cell is written from the origin (ASE has no cell origin):
        # ASE's positions are mote's minus the box's lower corner.
        shifted = [[p[i] - w["origin"][i] for i in range(3)] for p in w["positions"]]
        check(f"ASE frame {k} positions (shifted to the cell)", close(flat(a.get_positions()), flat(shifted)))
        check(f"ASE frame {k} cell", close(flat(a.get_cell()[:]), flat(w["cell"])))
        check(f"ASE frame {k} velocities (momenta / masses)", close(flat(a.get_velocities()), flat(w["velocities"])))
        check(f"ASE frame {k} symbols {a.get_chemical_symbols()}", a.get_chemical_symbols() == ["Fe", "O"])

    # LAMMPS dump with MDAnalysis: positions and box lengths (orthogonal box).
    u = MDAnalysis.Universe(os.path.join(d, "t.dump"), format="LAMMPSDUMP")
    check(f"MDAnalysis reads {len(want)} frames of t.dump", len(u.trajectory) == len(want))
    for k, ts in enumerate(u.trajectory):
        w = want[k]
        pos = u.atoms.positions
        # MDAnalysis keeps float32 positions; it may report them relative to the box origin.
        exp = [[p[i] for i in range(3)] for p in w["positions"]]
        shifted = [[p[i] - w["origin"][i] for i in range(3)] for p in w["positions"]]
        ok = close(flat(pos), flat(exp), 1e-5) or close(flat(pos), flat(shifted), 1e-5)
        check(f"MDAnalysis frame {k} positions", ok)
        lengths = [w["cell"][0][0], w["cell"][1][1], w["cell"][2][2]]
        check(f"MDAnalysis frame {k} box {list(ts.dimensions[:3])}", close(ts.dimensions[:3], lengths, 1e-5))

    # GSD with the gsd package (HOOMD's reader) and MDAnalysis: f32 positions
    # relative to the box centre, box lengths, types, velocities.
    try:
        import gsd.hoomd
    except Exception:  # noqa: BLE001
        gsd = None
        print("note: the gsd package is not importable (pip install gsd); t.gsd not checked")
    if gsd is not None:
        with gsd.hoomd.open(os.path.join(d, "t.gsd"), "r") as traj:
            check(f"gsd reads {len(want)} frames of t.gsd", len(traj) == len(want))
            for k, (fr, w) in enumerate(zip(traj, want)):
                lengths = [w["cell"][0][0], w["cell"][1][1], w["cell"][2][2]]
                centre = [w["origin"][i] + 0.5 * lengths[i] for i in range(3)]
                rel = [[p[i] - centre[i] for i in range(3)] for p in w["positions"]]
                check(f"gsd frame {k} positions (from the box centre)", close(flat(fr.particles.position), flat(rel), 1e-6))
                check(f"gsd frame {k} box", close(fr.configuration.box[:3], lengths, 1e-6))
                check(f"gsd frame {k} velocities", close(flat(fr.particles.velocity), flat(w["velocities"]), 1e-6))
                check(f"gsd frame {k} types {fr.particles.types}", list(fr.particles.types) == ["Fe", "O"])
        u = MDAnalysis.Universe(os.path.join(d, "t.gsd"))
        check(f"MDAnalysis reads {len(want)} frames of t.gsd", len(u.trajectory) == len(want))

    # OVITO (pip install ovito): every format mote writes, as particles.
    # Probe the import in a child first: a wheel that cannot load its
    # libraries may crash the interpreter rather than raise.
    import subprocess
    try:
        probe = subprocess.run([sys.executable, "-c", "import ovito.io"], capture_output=True, timeout=300)
        importable = probe.returncode == 0
    except Exception:  # noqa: BLE001
        importable = False
    import_file = None
    if importable:
        try:
            from ovito.io import import_file
        except Exception as e:  # noqa: BLE001 - a missing library is as good as a missing package
            print(f"note: ovito is not importable ({e}); OVITO not checked")
    else:
        print("note: ovito is not importable (pip install ovito); OVITO not checked")
    if import_file is not None:
        for fname in ["t.xyz", "t.dump", "t.gsd", "t.vtp"]:
            try:
                pipe = import_file(os.path.join(d, fname))
                n_frames = pipe.source.num_frames
                data = pipe.compute(n_frames - 1)
            except Exception as e:  # noqa: BLE001 - report any reader failure
                check(f"OVITO reads {fname} ({e})", False)
                continue
            w = want[-1]
            pos = np.asarray(data.particles.positions)
            exp = np.asarray(w["positions"])
            if fname == "t.xyz":  # periodic cell written from the origin (Shift=)
                exp = exp - np.asarray(w["origin"])
            if fname == "t.gsd":  # HOOMD's box is centred on the origin
                lengths = np.array([w["cell"][0][0], w["cell"][1][1], w["cell"][2][2]])
                exp = exp - np.asarray(w["origin"]) - 0.5 * lengths
            check(f"OVITO {fname}: {n_frames} frame(s), positions", close(pos.ravel(), exp.ravel(), 1e-5))
            if "Radius" in data.particles:
                check(f"OVITO {fname}: radii", close(np.asarray(data.particles["Radius"]), [0.5, 0.75], 1e-6))
            else:
                check(f"OVITO {fname}: radii (no Radius property)", False)
            if "Velocity" in data.particles:
                check(f"OVITO {fname}: velocities", close(np.asarray(data.particles["Velocity"]).ravel(), flat(w["velocities"]), 1e-6))
            else:
                check(f"OVITO {fname}: velocities (no Velocity property)", False)

    # VTU with meshio: points, and the cell stored as field data.
    m = meshio.read(os.path.join(d, "t.vtu"))
    w = want[-1]
    check("meshio t.vtu points", close(flat(m.points), flat(w["positions"])))
    check("meshio t.vtu radius array", "radius" in m.point_data and len(m.point_data["radius"]) == len(w["positions"]))
    if "cell" in m.field_data:
        check("meshio t.vtu cell (field data)", close(np.asarray(m.field_data["cell"]).ravel(), flat(w["cell"])))
    else:
        print("note: meshio does not expose the field data 'cell'; box not compared for VTU")
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all formats agree")
    return 0


if __name__ == "__main__":
    sys.exit(main())
