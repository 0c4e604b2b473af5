#!/usr/bin/env python3
"""Writes the XYZ fixtures of crates/mote-io/tests/xyz_others.rs with ASE.

Run from this folder: python3 make_fixtures.py (ASE 3.29 wrote the
committed files). Three argon atoms and one iron atom in a periodic
4 × 5 × 6 box, velocities in ASE units.
"""
from ase import Atoms
import ase.io

positions = [[0.5, 1.0, 1.5], [2.25, 0.125, 3.0], [3.5, 4.75, 5.5], [1.0, 2.0, 0.25]]
velocities = [[0.01, -0.02, 0.03], [0.0, 0.5, -0.25], [-0.125, 0.0, 0.0625], [0.3, 0.2, 0.1]]
atoms = Atoms("Ar3Fe", positions=positions, cell=[4.0, 5.0, 6.0], pbc=True)
atoms.set_velocities(velocities)
ase.io.write("ase_momenta.extxyz", atoms, format="extxyz")  # species, pos, momenta
plain = Atoms("Ar3Fe", positions=positions)
ase.io.write("ase_default.extxyz", plain, format="extxyz")  # species, pos
ase.io.write("ase_plain.xyz", plain, format="xyz")  # no Properties
