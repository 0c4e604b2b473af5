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

# A GSD trajectory written by the gsd package (HOOMD's schema): two frames,
# the second with positions only (the rest comes from frame 0).
import gsd.hoomd

first = gsd.hoomd.Frame()
first.configuration.box = [4.0, 5.0, 6.0, 0.0, 0.0, 0.0]
first.particles.N = 3
first.particles.types = ["A", "B"]
first.particles.typeid = [0, 1, 0]
first.particles.position = [[-1.5, 0.5, 2.0], [0.25, -2.0, -2.5], [1.0, 1.0, 1.0]]
first.particles.velocity = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, -3.0]]
first.particles.diameter = [1.0, 0.5, 2.0]
first.particles.mass = [1.0, 2.0, 4.0]
second = gsd.hoomd.Frame()
second.configuration.step = 10
second.configuration.box = first.configuration.box
second.particles.N = 3
second.particles.position = [[-1.25, 0.5, 2.0], [0.25, -1.75, -2.5], [1.0, 1.0, 1.25]]
with gsd.hoomd.open("gsd_hoomd.gsd", "w") as f:
    f.append(first)
    f.append(second)

# VTU files as meshio writes them by default (binary, zlib-compressed) and
# uncompressed: three vertices with a radius array.
import meshio
import numpy as np

points = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.5], [-0.25, 0.5, 1e-3]])
cells = [("vertex", np.array([[0], [1], [2]]))]
mesh = meshio.Mesh(points, cells, point_data={"radius": np.array([0.5, 0.25, 0.125])})
mesh.write("meshio_default.vtu")
mesh.write("meshio_uncompressed.vtu", compression=None)

# OVITO 3.17 (pip install ovito): XYZ, a dump with BOX BOUNDS abc origin and
# a data file with an avec/bvec/cvec box, a cell whose corner is not the origin.
from ovito.data import DataCollection
from ovito.io import export_file
from ovito.pipeline import StaticSource, Pipeline
data = DataCollection()
cell = data.create_cell([[4.0, 0, 0], [0, 5.0, 0], [0, 0, 6.0]], pbc=(True, True, True))
m = np.array(data.cell_[...])
m[:, 3] = (-1.0, 0.5, 2.0)
data.cell_[...] = m
p = data.create_particles(count=3)
p.create_property("Position", data=[[0.0, 1.0, 2.5], [1.5, 2.25, 3.0], [2.5, 5.0, 7.5]])
p.create_property("Velocity", data=[[0.5, 0.0, -0.25], [0.0, 1.0, 0.0], [0.125, 0.0, 2.0]])
p.create_property("Radius", data=[0.5, 0.25, 0.75])
t = p.create_property("Particle Type", data=[1, 2, 1])
p.create_property("Particle Identifier", data=[1, 2, 3])
pipe = Pipeline(source=StaticSource(data=data))
export_file(pipe, "ovito.xyz", "xyz", columns=["Position.X", "Position.Y", "Position.Z", "Velocity.X", "Velocity.Y", "Velocity.Z", "Radius"])
export_file(pipe, "ovito.dump", "lammps/dump", columns=["Particle Identifier", "Particle Type", "Position.X", "Position.Y", "Position.Z", "Velocity.X", "Velocity.Y", "Velocity.Z", "Radius"])
export_file(pipe, "ovito.data", "lammps/data", atom_style="atomic")

# MDAnalysis 2.11: a LAMMPS data file (an Atoms section without a style
# comment: id mol type x y z) and a plain XYZ.
import warnings

import MDAnalysis as mda

warnings.filterwarnings("ignore")
u = mda.Universe.empty(3, trajectory=True, atom_resindex=[0, 0, 0], residue_segindex=[0])
u.add_TopologyAttr("type", ["1", "2", "1"])
u.add_TopologyAttr("name", ["Ar", "Fe", "Ar"])
u.add_TopologyAttr("masses", [39.948, 55.845, 39.948])
u.add_TopologyAttr("ids", [1, 2, 3])
for attr in ["bonds", "angles", "dihedrals", "impropers"]:
    u.add_TopologyAttr(attr, [])
u.atoms.positions = np.array([[0.5, 1.0, 1.5], [2.25, 0.125, 3.0], [3.5, 4.75, 5.5]])
u.dimensions = [4.0, 5.0, 6.0, 90, 90, 90]
u.atoms.write("mdanalysis.data")
u.atoms.write("mdanalysis.xyz")

# VTK 9.7 (pip install vtk), the writer ParaView uses: appended data, raw
# (ParaView's default) and base64 (VTK's), zlib-compressed and not, and LZ4;
# three vertices with radius and velocity arrays (Float32 velocity).
import vtk
from vtk.util.numpy_support import numpy_to_vtk

def poly():
    pd = vtk.vtkPolyData()
    pts = vtk.vtkPoints()
    pts.SetDataTypeToDouble()
    for p in [[0.0, 0.0, 0.0], [1.0, 2.0, 3.5], [-0.25, 0.5, 1e-3]]:
        pts.InsertNextPoint(p)
    pd.SetPoints(pts)
    verts = vtk.vtkCellArray()
    for i in range(3):
        verts.InsertNextCell(1)
        verts.InsertCellPoint(i)
    pd.SetVerts(verts)
    r = numpy_to_vtk(np.array([0.5, 0.25, 0.125]), deep=True)
    r.SetName("radius")
    pd.GetPointData().AddArray(r)
    v = numpy_to_vtk(np.array([[1.0, 0.0, -0.5], [0.0, 2.0, 0.0], [0.25, 0.0, 4.0]], dtype=np.float32), deep=True)
    v.SetName("Velocity")
    pd.GetPointData().AddArray(v)
    return pd

for name, raw, compressor in [
    ("vtk_raw_zlib.vtp", True, "zlib"),
    ("vtk_raw.vtp", True, None),
    ("vtk_base64_zlib.vtp", False, "zlib"),
    ("vtk_raw_lz4.vtp", True, "lz4"),
]:
    w = vtk.vtkXMLPolyDataWriter()
    w.SetFileName(name)
    w.SetInputData(poly())
    w.SetDataModeToAppended()
    w.SetEncodeAppendedData(0 if raw else 1)
    if compressor == "zlib":
        w.SetCompressorTypeToZLib()
    elif compressor == "lz4":
        w.SetCompressorTypeToLZ4()
    else:
        w.SetCompressorTypeToNone()
    w.Write()
