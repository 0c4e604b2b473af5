"""mote: many-particle simulation from Python.

The scene format is the one of ``mote run`` (docs/scene-format.md), given as a
file, a TOML string or a dict; ``Simulation`` steps time-stepped scenes,
``RigidSimulation`` rigid ones, ``HardSpheres`` event-driven ones,
``Packing`` packing scenes (a pressure window per step), ``run`` runs any
engine whole, ``pack`` grows packings from options and ``rcp`` estimates
random close packing fractions. See docs/python.md.
"""

from ._mote import (  # noqa: F401
    HardSpheres,
    MoteError,
    Packing,
    RigidSimulation,
    Simulation,
    UnstableError,
    __version__,
    pack,
    rcp,
    rcp_optimise,
    render,
    run,
)

__all__ = ["HardSpheres", "MoteError", "Packing", "RigidSimulation", "Simulation", "UnstableError", "pack", "rcp", "rcp_optimise", "render", "run"]


def from_ase(atoms, scene=None, seed=None):
    """A Simulation of ASE ``atoms`` under the tables of ``scene`` (a dict:
    ``run``, forces, ``output``; its own particles are added to).

    ASE's numbers are taken as they are: Å, amu, eV and ASE's time unit
    (Å·√(amu/eV) ≈ 10.18 fs) form a coherent unit system, so the scene's
    forces and ``dt`` must be given in it (``units = "lj"``: G = 1 and no
    conversion). Positions, velocities, masses and chemical symbols (as
    species) come from ``atoms``; an orthogonal cell with periodic axes
    becomes the ``[box]`` (its lower corner at the origin); a skewed cell is
    refused.
    """
    import numpy as np

    d = dict(scene or {})
    d.setdefault("units", "lj")
    velocities = atoms.get_velocities()
    if velocities is None:
        velocities = np.zeros((len(atoms), 3))
    particles = list(d.get("particle", []))
    for x, v, m, s in zip(
        atoms.get_positions(), velocities, atoms.get_masses(), atoms.get_chemical_symbols()
    ):
        particles.append(
            {"position": [float(c) for c in x], "velocity": [float(c) for c in v], "mass": float(m), "species": s}
        )
    d["particle"] = particles
    cell = np.asarray(atoms.cell.array)
    pbc = [bool(p) for p in atoms.pbc]
    if any(pbc) and "box" not in d:
        if np.count_nonzero(cell - np.diag(np.diag(cell))):
            raise ValueError("a skewed (triclinic) cell: mote's boxes are orthogonal")
        d["box"] = {"lo": [0.0, 0.0, 0.0], "hi": [float(c) for c in np.diag(cell)], "periodic": pbc}
    return Simulation.from_dict(d, seed=seed)


def to_ase(sim, box=None):
    """The state of ``sim`` as ASE ``Atoms``: positions, velocities, masses,
    species as symbols (``X`` where a species is no element), and ``box``
    (``(lo, hi, periodic)``; by default the simulation's own box where it
    has faces on every axis, else none: a free cluster) as cell and pbc;
    the numbers in the simulation's own units (see ``from_ase``)."""
    import numpy as np
    from ase import Atoms
    from ase.data import chemical_symbols

    if box is None:
        own = getattr(sim, "box", None)
        if own is not None and np.all(np.isfinite(own[0])) and np.all(np.isfinite(own[1])):
            box = own

    names = [s if s in chemical_symbols else "X" for s in sim.species] or ["X"] * len(sim)
    atoms = Atoms(symbols=names, positions=np.array(sim.positions), masses=np.array(sim.masses))
    atoms.set_velocities(np.array(sim.velocities))
    if box is not None:
        lo, hi, periodic = box
        atoms.set_cell(np.diag(np.subtract(hi, lo)))
        atoms.positions -= np.asarray(lo)
        atoms.pbc = periodic
    return atoms


__all__ += ["from_ase", "to_ase"]
