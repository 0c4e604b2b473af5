"""mote's Python API: the same numbers as `mote run`, numpy views that
reflect writes, the GIL released while mote computes, and bad input raised
as Python exceptions (never a crash)."""

import threading
import time

import numpy as np
import pytest

import mote

LJ = """
title = "LJ liquid, 256 atoms"
units = "lj"
seed = 5

[run]
integrator = "leapfrog"
dt = 0.005
steps = 200

[lennard_jones]
cutoff = 2.5
skin = 0.3

[[fcc]]
cells = [4, 4, 4]
density = 0.8442
kt = 1.44

[output]
observables_every = 10
trajectory_every = 0
"""


def csv_columns(path):
    """The columns of an observables.csv (comments skipped) by name."""
    with open(path) as f:
        lines = [l for l in f if not l.startswith("#")]
    names = [n.strip() for n in lines[0].split(",")]
    rows = np.array([[float(x) for x in l.split(",")] for l in lines[1:]])
    return {n: rows[:, k] for k, n in enumerate(names)}


def test_run_gives_the_bits_of_mote_run(tmp_path):
    sim = mote.Simulation.from_toml(LJ)
    sim.run()
    assert sim.steps == 200
    out = mote.run(LJ, output=tmp_path, checkpoint_every=1000)
    assert out["ending"] == "finished"
    ref = mote.Simulation.resume(tmp_path / "checkpoint.mote")
    assert ref.steps == 200
    # Bit for bit: the state, and every measured observable.
    assert np.array_equal(sim.positions, ref.positions)
    assert np.array_equal(sim.velocities, ref.velocities)
    table = csv_columns(tmp_path / "observables.csv")
    obs = sim.observables
    assert np.array_equal(table["time"], obs["time"])
    assert np.array_equal(table["kinetic_energy"], obs["kinetic"])
    assert np.array_equal(table["potential_energy"], obs["potential"])


SALT = """
title = "Molten salt, 216 ions, P3M"
units = "lj"
seed = 3

[run]
integrator = "leapfrog"
dt = 0.002
steps = 40

[lennard_jones]
wca = true

[coulomb]
method = "p3m"
accuracy = 1e-4

[[fcc]]
cells = [3, 3, 3]
density = 0.25
kt = 0.5
charge = 1.0

[[fcc]]
cells = [3, 3, 3]
density = 0.25
kt = 0.5
origin = [1.2599210498948732, 0.0, 0.0]
charge = -1.0

[output]
observables_every = 10
trajectory_every = 0
"""


def test_p3m_coulomb_from_python_gives_the_bits_of_mote_run(tmp_path):
    sim = mote.Simulation.from_toml(SALT)
    momentum = sim.velocities.sum(axis=0)
    sim.run()
    out = mote.run(SALT, output=tmp_path)
    assert out["ending"] == "finished"
    # The tuned mesh, order, α and cut-off are told.
    assert any("Coulomb by P3M: mesh" in line for line in out["summary"])
    table = csv_columns(tmp_path / "observables.csv")
    obs = sim.observables
    assert np.array_equal(table["potential_energy"], obs["potential"])
    assert np.array_equal(table["kinetic_energy"], obs["kinetic"])
    # Momentum is conserved (ik-differentiation; equal masses).
    assert np.abs(sim.velocities.sum(axis=0) - momentum).max() < 1e-10


DIPOLAR_FLUID = """
title = "Dipolar fluid, 256 particles, P3M"
units = "lj"
seed = 4

[run]
integrator = "leapfrog"
dt = 0.002
steps = 30

[lennard_jones]
wca = true

[dipolar]
method = "p3m"
accuracy = 1e-3
random_orientation = true

[[fcc]]
cells = [4, 4, 4]
density = 0.7
kt = 1.0
radius = 0.5
dipole = [0.0, 0.0, 1.2]

[output]
observables_every = 10
trajectory_every = 0
"""


def test_p3m_dipoles_from_python_give_the_bits_of_mote_run(tmp_path):
    sim = mote.Simulation.from_toml(DIPOLAR_FLUID)
    sim.run()
    out = mote.run(DIPOLAR_FLUID, output=tmp_path)
    assert out["ending"] == "finished"
    assert any("Dipolar by P3M: mesh" in line for line in out["summary"])
    table = csv_columns(tmp_path / "observables.csv")
    obs = sim.observables
    assert np.array_equal(table["potential_energy"], obs["potential"])
    assert np.array_equal(table["kinetic_energy"], obs["kinetic"])
    # The dipoles turned: the moment is no longer the start's.
    assert not np.array_equal(table["Mz"], np.full_like(table["Mz"], table["Mz"][0]))


def test_with_output_a_simulation_writes_what_mote_run_writes(tmp_path):
    """A stepped Simulation given a folder writes mote run's files there,
    byte for byte, in chunks and with callbacks; without one it writes none,
    and it says where it writes."""
    scene = LJ.replace("trajectory_every = 0", "trajectory_every = 50")
    sim = mote.Simulation.from_toml(scene, output=tmp_path / "py")
    assert sim.output == tmp_path / "py"
    sim.step(30)
    sim.run(steps=170, callback=lambda s: None, every=40)
    del sim  # the folder's lock goes with the simulation
    mote.run(scene, output=tmp_path / "cli")
    for name in ["observables.csv", "trajectory.xyz"]:
        ours = (tmp_path / "py" / name).read_bytes()
        assert len(ours) > 1000, name
        assert ours == (tmp_path / "cli" / name).read_bytes(), name
    assert mote.Simulation.from_toml(scene).output is None
    # Two live simulations cannot write one folder.
    first = mote.Simulation.from_toml(scene, output=tmp_path / "one")
    with pytest.raises(Exception, match="one"):
        mote.Simulation.from_toml(scene, output=tmp_path / "one")
    del first


def test_chunks_and_callbacks_change_nothing():
    whole = mote.Simulation.from_toml(LJ)
    whole.run(steps=200)
    chunked = mote.Simulation.from_toml(LJ)
    for _ in range(4):
        chunked.step(50)
    assert np.array_equal(whole.positions, chunked.positions)
    seen = []
    called = mote.Simulation.from_toml(LJ)
    called.run(steps=200, callback=lambda s: seen.append(s.steps), every=7)
    assert seen == list(range(7, 200, 7)) + [200]
    assert np.array_equal(whole.positions, called.positions)


def test_views_are_mote_memory_and_writes_reach_the_next_step():
    sim = mote.Simulation.from_dict(
        {
            "run": {"integrator": "leapfrog", "dt": 0.5, "steps": 10},
            "particle": [{"position": [0.0, 0.0, 0.0], "mass": 1.0}],
        }
    )
    x = sim.positions
    assert x.shape == (1, 3) and x.base is sim
    # Without a copy: the same memory on every access.
    assert sim.positions.__array_interface__["data"][0] == x.__array_interface__["data"][0]
    sim.velocities[0] = [2.0, 0.0, -1.0]
    sim.step(1)
    assert np.array_equal(x[0], [1.0, 0.0, -0.5])
    x[0] = [10.0, 10.0, 10.0]
    sim.step(2)
    assert np.array_equal(sim.positions[0], [12.0, 10.0, 9.0])
    sim.dt = 0.25
    sim.step(4)
    assert np.array_equal(sim.positions[0], [14.0, 10.0, 8.0])
    assert sim.time == pytest.approx(2.5)
    # Whole arrays assigned are copied in; a wrong shape says the right one.
    sim.positions = np.zeros((1, 3))
    sim.velocities = [[0.0, 0.0, 1.0]]
    sim.step(4)
    assert np.array_equal(sim.positions[0], [0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match=r"expected an array of shape \(1, 3\), got shape \[2, 3\]"):
        sim.positions = np.zeros((2, 3))
    with pytest.raises(ValueError, match=r"shape \(1, 3\)"):
        sim.velocities = "fast"


def test_a_granular_scene_in_space_order_numbers_its_rows():
    """A granular scene stores its particles in space order; `numbers`
    names the scene's particle of each row, and the rows in that order are
    the particles as stored with `order = "file"`."""
    scene = lambda order: {
        "run": {"integrator": "leapfrog", "dt": 2e-5, "steps": 10},
        "granular": {"young": 1e6, "poisson": 0.3, "restitution": 0.5,
                     "friction": 0.5, "order": order},
        "cloud": [{"n": 80, "min": [0.0, 0.0, 0.0], "max": [0.02, 0.02, 0.02],
                   "radius": 0.001, "density": 2500.0}],
    }
    space = mote.Simulation.from_dict(scene("space"), seed=3)
    file = mote.Simulation.from_dict(scene("file"), seed=3)
    assert np.array_equal(file.numbers, np.arange(80))
    assert not np.array_equal(space.numbers, np.arange(80))
    assert np.array_equal(np.sort(space.numbers), np.arange(80))
    rows = np.argsort(space.numbers)
    assert np.array_equal(space.positions[rows], file.positions)


def test_the_gil_is_released_while_mote_computes():
    sim = mote.Simulation.from_toml(LJ.replace("[4, 4, 4]", "[7, 7, 7]"))
    worker = threading.Thread(target=sim.run, kwargs={"steps": 300})
    count = 0
    worker.start()
    start = time.perf_counter()
    while worker.is_alive():
        count += 1
    elapsed = time.perf_counter() - start
    worker.join()
    assert sim.steps == 300
    # Python counted all along; with the GIL held it could not have.
    assert elapsed > 0.05 and count > 10_000, (elapsed, count)


def test_bad_input_raises_with_the_line():
    with pytest.raises(ValueError, match=r"<string>:3: unknown field `foo`"):
        mote.Simulation.from_toml("[run]\ndt = 0.1\nfoo = 3\n")
    with pytest.raises(ValueError, match=r"<dict>:.*unknown field `dtt`"):
        mote.Simulation.from_dict({"run": {"dtt": 0.1}})
    with pytest.raises(TypeError, match="run.dt"):
        mote.Simulation.from_dict({"run": {"dt": object()}})
    with pytest.raises(ValueError, match="mote.run"):
        mote.Simulation.from_file("example:cube")
    with pytest.raises(ValueError, match="dt = -1"):
        mote.Simulation.from_toml(LJ).dt = -1.0
    with pytest.raises(ValueError, match="steps or until"):
        mote.Simulation.from_toml(LJ).run(steps=1, until=1.0)
    with pytest.raises(OSError, match="no/such/scene.toml"):
        mote.Simulation.from_file("no/such/scene.toml")
    # Particles that come and go would move the arrays under the views.
    with pytest.raises(ValueError, match="come and go.*mote.run"):
        mote.Simulation.from_file("example:chute-flow")
    with pytest.raises(ValueError, match="come and go.*mote.run"):
        mote.RigidSimulation.from_file("example:toning-nip-flow")


def test_an_unstable_run_raises_naming_step_and_particle_and_keeps_the_state():
    sim = mote.Simulation.from_dict(
        {
            "run": {"integrator": "leapfrog", "dt": 0.1, "steps": 10},
            "particle": [
                {"position": [0.0, 0.0, 0.0], "mass": 1.0},
                {"position": [1.0, 0.0, 0.0], "mass": 1.0},
            ],
        }
    )
    sim.step(3)
    sim.velocities[1] = [np.inf, 0.0, 0.0]
    with pytest.raises(mote.UnstableError, match=r"step 4 .*particle 1"):
        sim.step(5)
    assert sim.steps == 4
    assert np.isfinite(sim.positions[0]).all()


def test_checkpoints_resume_bit_for_bit(tmp_path):
    a = mote.Simulation.from_toml(LJ)
    a.step(60)
    a.save_checkpoint(tmp_path / "a.mote")
    a.step(70)
    b = mote.Simulation.resume(tmp_path / "a.mote")
    assert b.steps == 60 and b.time == pytest.approx(0.3)
    b.step(70)
    assert np.array_equal(a.positions, b.positions)


def test_every_engine_runs_whole(tmp_path):
    for scene, kw in [
        ("example:cube", {"until": 0.5}),
        ("example:magnet-in-field", {"steps": 20}),
        ("example:chute-flow", {"steps": 600}),
        ("[packing]\nn = 100\nmax_pressure = 1e5\n", {}),
        (LJ, {"steps": 10}),
    ]:
        out = mote.run(scene, output=tmp_path / str(len(kw)) / scene[:8].strip("[:\n"), seed=2, **kw)
        assert out["ending"] == "finished", out
        assert out["summary"]


def test_pack_and_rcp():
    r = mote.pack(200, phi=0.5, seed=1)
    assert r["positions"].shape == (200, 3) and r["radii"].shape == (200,)
    volume = (4.0 / 3.0 * np.pi * r["radii"] ** 3).sum()
    assert volume / np.prod(r["box"]) == pytest.approx(0.5, abs=1e-12)
    # spherepack1d's monodisperse value and the published lognormal one.
    assert round(mote.rcp(diameters=[1.0]), 6) == 0.643485
    assert 0.66 < mote.rcp(sigma=0.3) < 0.68
    with pytest.raises(ValueError):
        mote.rcp(sigma=-1.0)
    # As mote rcp: what the rods cannot resolve is refused, a rough third
    # decimal warned of.
    with pytest.raises(ValueError, match="rods"):
        mote.rcp(diameters=[1.0, 1e5], volumes=[0.5, 0.5])
    with pytest.raises(ValueError, match="more rods"):
        mote.rcp(sigma=8.0)
    with pytest.warns(UserWarning, match="third decimal"):
        assert 0.96 < mote.rcp(sigma=3.0) < 0.98


def test_ase_atoms_in_and_out():
    ase = pytest.importorskip("ase")
    atoms = ase.Atoms("Ar4", positions=[[0, 0, 0], [2, 0, 0], [0, 2, 0], [0, 0, 2.5]], cell=[8, 8, 8], pbc=True)
    atoms.set_velocities([[0.01, 0, 0], [0, 0.02, 0], [0, 0, -0.01], [0.005, 0.005, 0]])
    sim = mote.from_ase(atoms, {"run": {"integrator": "leapfrog", "dt": 0.1}})
    assert len(sim) == 4 and sim.species == ["Ar"] * 4
    assert np.array_equal(sim.positions, atoms.positions)
    assert np.array_equal(sim.velocities, atoms.get_velocities())
    assert np.array_equal(sim.masses, atoms.get_masses())
    sim.step(10)  # no forces: straight lines
    lo, hi, periodic = sim.box
    assert list(lo) == [0, 0, 0] and list(hi) == [8, 8, 8] and periodic == [True] * 3
    back = mote.to_ase(sim)  # the simulation's own box (it was a zero cell)
    assert np.allclose(back.cell.array, np.diag([8.0, 8.0, 8.0])) and all(back.pbc)
    assert np.allclose(back.positions, (atoms.positions + 1.0 * atoms.get_velocities()) % 8.0, atol=1e-12)
    assert np.allclose(back.get_velocities(), atoms.get_velocities(), atol=1e-15)
    assert back.get_chemical_symbols() == ["Ar"] * 4
    with pytest.raises(ValueError, match="skewed"):
        mote.from_ase(ase.Atoms("Ar", positions=[[0, 0, 0]], cell=[[4, 0, 0], [1, 4, 0], [0, 0, 4]], pbc=True), {"run": {"dt": 0.1}})


def test_pictures_as_arrays_and_files(tmp_path):
    sim = mote.Simulation.from_toml(LJ)
    image = sim.render(width=64, height=48)
    assert image.shape == (48, 64, 3) and image.dtype == np.uint8
    assert image.std() > 0  # not blank
    sim.render(tmp_path / "lj.png", width=64, height=48)
    assert (tmp_path / "lj.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    mote.run(LJ.replace("trajectory_every = 0", "trajectory_every = 50"), output=tmp_path / "run", steps=100)
    again = mote.render(tmp_path / "run" / "trajectory.xyz", frame=-1, width=64, height=48)
    assert again.shape == (48, 64, 3)
    with pytest.raises(ValueError, match="no frame 9"):
        mote.render(tmp_path / "run" / "trajectory.xyz", frame=9)


def test_rcp_optimiser_finds_the_densest_binary_mixture():
    best = mote.rcp_optimise([1.0, 4.0])
    assert best["volumes"].sum() == pytest.approx(1.0)
    # No composition of the sweep packs denser than the optimum.
    sweep = [mote.rcp(diameters=[1.0, 4.0], volumes=[1 - f, f]) for f in np.linspace(0.05, 0.95, 19)]
    assert best["phi"] >= max(sweep) - 1e-6
    assert 0.5 < best["volumes"][1] < 0.9
    near = mote.rcp_optimise([1.0, 4.0], target=0.7)
    assert near["phi"] == pytest.approx(0.7, abs=1e-4)
    with pytest.raises(ValueError, match="2 sigmas"):
        mote.rcp_optimise([1.0, 4.0], sigmas=[0.1])


def test_rigid_bodies_in_a_periodic_box_have_the_pressure_of_mote_run(tmp_path):
    gas = """seed = 5
[rigid]
[[rigid.template]]
name = "trimer"
generator = "trimer"
radius = 0.5
distance = 0.5
mass = 1.5
[[rigid.lattice]]
template = "trimer"
n = 27
lo = [0.0, 0.0, 0.0]
hi = [6.0, 6.0, 6.0]
spacing = 2.05
random_orientation = true
speed = 2.0
[box]
lo = [0.0, 0.0, 0.0]
hi = [6.2, 6.2, 6.2]
periodic = [true, true, true]
[rigid.contacts]
young = 136500.0
poisson = 0.3
restitution = 0.9
friction = 0.3
[run]
dt = 5e-4
steps = 400
[output]
observables_every = 50
"""
    sim = mote.RigidSimulation.from_toml(gas)
    sim.run()
    out = mote.run(gas, output=tmp_path)
    assert out["ending"] == "finished", out
    table = csv_columns(tmp_path / "observables.csv")
    obs = sim.observables
    assert np.array_equal(table["pressure"], obs["pressure"])
    # the first row is the ideal gas of the bodies' centres: 2 K_t / 3V
    ideal = 2.0 * obs["translational"][0] / (3.0 * 6.2**3)
    assert obs["pressure"][0] == pytest.approx(ideal, rel=1e-12)
    # an open box has no pressure, as mote run's table has no column
    here = __import__("pathlib").Path(__file__).resolve().parents[3]
    text = (here / "examples/rigid/clumps-settling.toml").read_text().replace("until = 0.5", "steps = 2")
    settling = mote.RigidSimulation.from_toml(text)
    settling.run()
    assert "pressure" not in settling.observables


def test_progress_shows_the_opening_line_on_stderr(capfd, tmp_path):
    sim = mote.Simulation.from_toml(LJ)
    sim.run(steps=10)
    assert capfd.readouterr().err == ""
    sim.run(steps=10, progress=True)
    assert "256 particles, dt = 0.005, 10 steps" in capfd.readouterr().err
    out = mote.run(LJ, steps=5, progress=True, output=tmp_path)
    assert "mote run <string>" in capfd.readouterr().err
    assert out["ending"] == "finished"


def test_rigid_clumps_step_from_python_with_the_bits_of_mote_run(tmp_path):
    here = __import__("pathlib").Path(__file__).resolve().parents[3]
    text = (here / "examples/rigid/clumps-settling.toml").read_text().replace("until = 0.5", "steps = 200")
    text = text.replace("observables_every = 200", "observables_every = 20")
    sim = mote.RigidSimulation.from_toml(text)
    seen = []
    sim.run(callback=lambda s: seen.append(s.steps), every=30)
    assert sim.steps == 200 and seen[-1] == 200
    out = mote.run(text, output=tmp_path)
    assert out["ending"] == "finished", out
    table = csv_columns(tmp_path / "observables.csv")
    obs = sim.observables
    assert np.array_equal(table["time"], obs["time"])
    assert np.array_equal(table["total_energy"], obs["total"])
    assert np.array_equal(table["px"], obs["momentum"][:, 0])
    # Bodies: centres, unit quaternions, spheres with their body.
    n = len(sim)
    assert sim.positions.shape == (n, 3) and sim.positions.base is sim
    q = sim.orientations
    assert q.shape == (n, 4) and np.allclose((q**2).sum(1), 1.0)
    spheres = sim.spheres()
    assert spheres["radii"].shape[0] == spheres["positions"].shape[0] > n
    assert set(spheres["body"]) == set(range(n))
    assert (sim.masses > 0).all()
    with pytest.raises(ValueError, match="not a rigid scene"):
        mote.RigidSimulation.from_toml(LJ)
    # Checkpoints: bodies, spins and contact histories, bit for bit.
    sim.save_checkpoint(tmp_path / "r.mote")
    sim.step(40)
    again = mote.RigidSimulation.resume(tmp_path / "r.mote")
    assert again.steps == 200
    again.step(40)
    assert np.array_equal(sim.positions, again.positions)
    assert np.array_equal(sim.rotations, again.rotations)


def test_a_rigid_scene_in_space_order_numbers_its_bodies():
    """A rigid scene stores its bodies in space order; `numbers` names the
    scene's body of each row, the rows in that order are the bodies as
    stored with `order = "file"`, and the spheres come body after body in
    the scene's numbering either way."""
    here = __import__("pathlib").Path(__file__).resolve().parents[3]
    text = (here / "examples/rigid/clumps-settling.toml").read_text()
    text = text.replace("until = 0.5", "steps = 2")
    space = mote.RigidSimulation.from_toml(text)
    file = mote.RigidSimulation.from_toml(text.replace("[rigid]\n", "[rigid]\norder = \"file\"\n", 1))
    n = len(space)
    assert np.array_equal(file.numbers, np.arange(n))
    assert not np.array_equal(space.numbers, np.arange(n))
    rows = np.argsort(space.numbers)
    assert np.array_equal(space.positions[rows], file.positions)
    assert np.array_equal(space.rotations[rows], file.rotations)
    a, b = space.spheres(), file.spheres()
    assert np.array_equal(a["body"], b["body"])
    assert np.array_equal(a["positions"], b["positions"])


def test_pack_gives_the_packing_of_a_packing_scene(tmp_path):
    ase_io = pytest.importorskip("ase.io")
    p = mote.pack(300, phi=0.55, seed=3, output=tmp_path / "p")
    mote.run({"packing": {"n": 300, "phi": 0.55}}, seed=3, output=tmp_path / "scene")
    a = ase_io.read(tmp_path / "p" / "packing.xyz")
    b = ase_io.read(tmp_path / "scene" / "packing.xyz")
    # The same packing, bit for bit (both files are written exactly).
    assert np.array_equal(a.positions, b.positions)
    assert np.array_equal(a.positions, p["positions"] + 0.0)
    # output is a folder, as everywhere; a packing file's name is refused.
    with pytest.raises(ValueError, match="names the packing's folder"):
        mote.pack(50, phi=0.3, output=tmp_path / "q.xyz")
    assert not (tmp_path / "q.xyz").exists()


HARD_SPHERES = """
seed = 3
[event_driven]
dimension = 3
n = 200
packing_fraction = 0.3
placement = "random"
[run]
until = 2.0
[output]
interval = 0.1
trajectory = false
histogram = false
"""


def checkpoint_particles(path):
    """Positions and velocities of a checkpoint, bit for bit (hex floats)."""
    import struct

    with open(path) as f:
        lines = f.read().splitlines()
    at = next(k for k, l in enumerate(lines) if l.startswith("particles "))
    n = int(lines[at].split()[1])
    rows = [[struct.unpack(">d", bytes.fromhex(h))[0] for h in l.split()[:6]] for l in lines[at + 1 : at + 1 + n]]
    rows = np.array(rows)
    return rows[:, :3], rows[:, 3:6]


def test_hard_spheres_step_from_python_with_the_bits_of_mote_run(tmp_path):
    hs = mote.HardSpheres.from_toml(HARD_SPHERES)
    assert (len(hs), hs.dimension, hs.seed, hs.last_step) == (200, 3, 3, 20)
    # In chunks, with a callback: the same bits as one run.
    seen = []
    hs.step(3)
    hs.run(callback=lambda h: seen.append(h.steps), every=5)
    assert hs.steps == 20 and seen == [8, 13, 18, 20]
    assert hs.time == pytest.approx(2.0)
    out = mote.run(HARD_SPHERES, output=tmp_path, checkpoint_every=1000)
    assert out["ending"] == "finished"
    x, v = checkpoint_particles(tmp_path / "checkpoint.mote")
    # A particle flies on past a periodic face until its next list renewal;
    # the checkpoint holds it wrapped back into the box (rem_euclid).
    L = hs.box
    y = hs.positions
    y = np.where(y < 0, y + L, np.where(y >= L, y - L, y))
    assert np.array_equal(y, x)
    assert np.array_equal(hs.velocities, v)
    table = csv_columns(tmp_path / "observables.csv")
    obs = hs.observables
    assert len(obs["time"]) == 21
    for name in ["time", "collisions", "kinetic_energy", "temperature"]:
        assert np.array_equal(table[name], obs[name]), name
    # Measured columns agree within round-off of the printed value.
    assert np.allclose(table["compressibility"][1:], obs["compressibility"][1:], rtol=1e-12)
    # Hard spheres move and collide: the collision count grows, energy stays.
    assert obs["collisions"][-1] > 1000
    assert abs(obs["energy_drift"][-1]) < 1e-10


def test_hard_spheres_refuse_what_they_cannot_do():
    with pytest.raises(ValueError, match="not an event-driven scene"):
        mote.HardSpheres.from_toml(LJ)
    hs = mote.HardSpheres.from_toml(HARD_SPHERES.replace("n = 200", "n = 20"))
    with pytest.raises(ValueError, match="give steps"):
        hs.run(until=1.0)
    with pytest.raises(ValueError, match="--force"):
        mote.HardSpheres.from_toml(HARD_SPHERES.replace("packing_fraction = 0.3", "packing_fraction = 0.3\nmass = 1e-300"))
    disks = mote.HardSpheres.from_dict(
        {"seed": 1, "event_driven": {"dimension": 2, "n": 50, "packing_fraction": 0.2, "placement": "random"},
         "run": {"until": 0.5}, "output": {"trajectory": False, "histogram": False}}
    )
    disks.run()
    assert disks.positions.shape == (50, 2) and disks.dimension == 2


def test_python_depends_on_no_engine_crate():
    """mote-py reaches every engine through the front (issue 36): its
    manifest names none of the engine crates."""
    import pathlib
    import re

    manifest = (pathlib.Path(__file__).parent.parent / "Cargo.toml").read_text()
    deps = manifest.split("[dependencies]")[1].split("\n[")[0]
    names = set(re.findall(r"^([a-z0-9_-]+)\s*=", deps, re.M))
    assert "mote-front" in names
    assert not names & {"mote-md", "mote-edmd", "mote-nip", "mote-geom"}, names


def test_every_simulation_class_steps_and_runs_the_same_way():
    # One definition (stepping.rs's simulation_class!): the same stepping
    # surface on every class, with the unit of its step in the docstrings.
    for cls, unit in [
        (mote.Simulation, "steps"),
        (mote.RigidSimulation, "steps"),
        (mote.HardSpheres, "output intervals"),
        (mote.Packing, "packing steps"),
    ]:
        assert cls.step.__text_signature__ == "($self, n=1)"
        run = cls.run.__text_signature__
        assert run.startswith("($self, steps=None, until=None, callback=None, every="), run
        assert run.endswith(", progress=False)"), run
        assert f"Advances `n` {unit}" in cls.step.__doc__
        assert f"The {unit} taken" in cls.steps.__doc__
        for attribute in ("time", "steps", "__len__", "observables" if cls is not mote.Packing else "windows"):
            assert hasattr(cls, attribute), (cls, attribute)


PACKING = """seed = 4
[packing]
n = 200
dimension = 2
dist = "bi:1.4:0.5"
rate = 0.3
max_pressure = 1e8
"""


def test_a_packing_steps_from_python_with_the_bits_of_mote_run(tmp_path):
    p = mote.Packing.from_toml(PACKING)
    assert (len(p), p.dimension, p.seed, p.steps, p.stopped) == (200, 2, 4, 0, None)
    assert np.isnan(p.pressure)
    # A window a step, in chunks with a callback, until it jams by itself.
    p.step(3)
    assert p.steps == 3 and p.stopped is None
    seen = []
    p.run(callback=lambda q: seen.append(q.steps), every=10)
    assert p.stopped == "pressure" and p.pressure > 1e8
    assert seen[0] == 13 and seen[-1] == p.steps
    windows = p.windows
    assert len(windows["phi"]) == p.steps
    # φ never falls, to round-off: where the packer restarts its system
    # (a new epoch, or growth stopped near jamming) the radii are re-based,
    # r ← r(0)(1 + δt) rounded, and φ summed again from their cubes moves
    # by some ulps either way while the packing stands still (12 ulps,
    # 1.3e-15, seen at 200 disks).
    phi = windows["phi"]
    assert np.all(np.diff(phi) >= -1e-12 * phi[1:]), np.diff(phi).min()
    assert phi[-1] == pytest.approx(p.phi)
    # mote run of the same scene: the same packing and windows, bit for bit.
    scene = tmp_path / "p.toml"
    scene.write_text(PACKING)
    out = mote.run(scene, output=tmp_path / "run")
    assert out["ending"] == "finished"
    table = csv_columns(tmp_path / "run" / "packing.csv")
    for name in ["collisions", "time", "phi", "pressure"]:
        assert np.array_equal(table[name], windows[name]), name
    # and mote.pack with the same settings spelled as options
    r = mote.pack(200, dimension=2, dist="bi:1.4:0.5", rate=0.3, max_pressure=1e8, seed=4)
    assert np.array_equal(r["positions"], p.positions)
    assert np.array_equal(r["radii"], p.radii)
    with pytest.raises(ValueError, match="until it jams"):
        p.run(until=1.0)


def test_a_packing_refuses_what_it_cannot_do():
    with pytest.raises(ValueError, match="not a packing scene"):
        mote.Packing.from_toml(HARD_SPHERES)
    with pytest.raises(ValueError, match="dimension = 4: must be 2 or 3"):
        mote.Packing.from_toml("[packing]\nn = 100\ndimension = 4\n")
    with pytest.raises(ValueError, match="the soft method packs spheres"):
        mote.Packing.from_toml("[packing]\nn = 100\nmethod = \"soft\"\ndimension = 2\n")


SOFT = """seed = 3
[packing]
method = "soft"
n = 200
min_pressure = 1e-6
"""


def test_a_soft_packing_steps_from_python_with_the_bits_of_mote_run(tmp_path):
    p = mote.Packing.from_toml(SOFT)
    assert (len(p), p.dimension, p.seed, p.steps, p.stopped, p.collisions) == (200, 3, 3, 0, None, None)
    assert np.isnan(p.pressure)
    # A chunk of 100 steps of the barostat or minimiser a step, to the end
    # of the jamming finish.
    p.step(5)
    assert p.steps == 5 and p.stopped is None
    p.run()
    assert p.stopped == "done"
    w = p.windows
    assert list(w) == ["steps", "phi", "pressure", "minimised"]
    assert w["minimised"][-1] == 1.0 and w["pressure"][-1] == p.pressure < 1.5e-6
    # mote run of the same scene, and mote.pack with the same settings as
    # options: the same packing and table, bit for bit.
    scene = tmp_path / "soft.toml"
    scene.write_text(SOFT)
    out = mote.run(scene, output=tmp_path / "run")
    assert out["ending"] == "finished"
    table = csv_columns(tmp_path / "run" / "packing.csv")
    for name in w:
        assert np.array_equal(table[name], w[name]), name
    r = mote.pack(200, method="soft", min_pressure=1e-6, seed=3)
    assert np.array_equal(r["positions"], p.positions)
    assert np.array_equal(r["radii"], p.radii)


def test_the_type_stubs_parse_and_name_every_class():
    import ast
    import pathlib

    stubs = pathlib.Path(mote.__file__).with_name("_mote.pyi")
    tree = ast.parse(stubs.read_text())
    named = {n.name for n in tree.body if isinstance(n, (ast.ClassDef, ast.FunctionDef))}
    native = {n for n in mote.__all__ if hasattr(mote._mote, n)}
    assert native <= named, native - named
