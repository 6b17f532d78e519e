"""A world built from Python: contact with the ground, momentum, save and restore, threads.

Each physics check compares with a closed-form value and states its tolerance.
"""

import threading

import numpy as np
import pytest

import rapier_fvm as rf

G = 9.81


def rubber() -> rf.Material:
    return rf.Material("stable_neo_hookean", young=1e6, poisson=0.3, density=1000.0)


def cube_on_ground(dt: float = 1 / 60):
    world = rf.World(dt=dt)
    ground = world.add_ground(friction=0.8)
    mesh = rf.Mesh.cuboid((0.1, 0.1, 0.1), (4, 4, 4))
    cube = world.add_soft_body(mesh, rubber(), translation=(0.0, 0.3, 0.0), stiffness_time=0.01)
    return world, ground, cube


def test_a_dropped_cube_rests_on_the_ground_carrying_its_weight():
    world, ground, cube = cube_on_ground()
    world.step(120)
    masses = world.masses(cube)
    # Lumped masses add up to the density times the volume (0.2 m)^3, to round-off.
    assert masses.sum() == pytest.approx(1000.0 * 0.2**3, rel=1e-12)
    force, _ = world.contact_force(cube, ground)
    # At rest after 2 s, the ground carries the weight m g; 1 % allows the last ringing.
    assert -force[1] == pytest.approx(masses.sum() * G, rel=0.01)
    # The lowest point rests on the ground, within the penalty's resting depth (1 mm).
    assert world.positions(cube)[:, 1].min() > -1e-3


def test_a_free_spinning_body_keeps_its_momenta():
    world = rf.World(dt=1 / 60, gravity=(0.0, 0.0, 0.0))
    mesh = rf.Mesh.cuboid((0.1, 0.05, 0.05), (4, 2, 2))
    body = world.add_soft_body(mesh, rubber(), linvel=(0.2, 0.0, 0.0), angvel=(0.0, 0.0, 5.0),
                               stiffness_time=0.01)
    before = world.measures(body)
    world.step(60)
    after = world.measures(body)
    # No external force: linear momentum (0.4 kg m/s) is kept to round-off (1e-12 kg m/s); the
    # default step keeps rigid rotation, angular momentum to 1e-6 (the library's own test).
    np.testing.assert_allclose(after["linear_momentum"], before["linear_momentum"], atol=1e-12)
    lz = before["angular_momentum"][2] - np.cross(
        before["center_of_mass"], before["linear_momentum"])[2]
    lz_after = after["angular_momentum"][2] - np.cross(
        after["center_of_mass"], after["linear_momentum"])[2]
    assert lz_after == pytest.approx(lz, rel=1e-6)


def test_a_stiff_body_stands_in_as_a_rigid_body_with_its_momentum():
    # A stiff free block (E = 100 MPa) allowed a stand-in below a strain of 1e-3 turns rigid at
    # the first frame and moves as a rapier body, spun about its principal axis z: its momentum
    # is the nodes' to rapier's f32 (1e-6, the library's own test); rapier's bodies listed do
    # not include it.
    world = rf.World(dt=1 / 60, gravity=(0.0, 0.0, 0.0))
    stiff = rf.Material("stable_neo_hookean", young=1e8, poisson=0.3, density=1000.0)
    mesh = rf.Mesh.cuboid((0.1, 0.05, 0.05), (4, 2, 2))
    body = world.add_soft_body(mesh, stiff, linvel=(0.2, 0.0, 0.0), angvel=(0.0, 0.0, 5.0),
                               rigid_stand_in=1e-3)
    before = world.measures(body)
    world.step(1)
    assert world.stands_in(body)
    assert world.rigid_bodies == []
    after = world.measures(body)
    # 0.4 kg m/s along x; the other components are round-off (1e-17): 1e-6 of its size.
    np.testing.assert_allclose(after["linear_momentum"], before["linear_momentum"], atol=4e-7)
    with pytest.raises(rf.Error, match="rigid_stand_in"):
        world.add_soft_body(mesh, stiff, rigid_stand_in=2.0)


def test_a_body_force_changes_momentum_at_its_resultant():
    world = rf.World(dt=1 / 60, gravity=(0.0, 0.0, 0.0))
    body = world.add_soft_body(rf.Mesh.cuboid((0.1, 0.1, 0.1), (2, 2, 2)), rubber())
    world.add_body_force(body, (0.0, 0.0, 50.0))
    world.step(30)
    # dp/dt = b V: 50 N/m^3 over 0.008 m^3 for 30 frames, to round-off; rapier holds the
    # frame step in float32 (1/60 s as 0.016666668 s), the step the bodies take.
    p = world.measures(body)["linear_momentum"]
    assert p[2] == pytest.approx(50.0 * 0.008 * 30 * float(np.float32(1 / 60)), rel=1e-12)


def test_a_restored_world_steps_on_bit_for_bit():
    world, _, cube = cube_on_ground()
    box = world.add_rigid_body(rf.Shape.cuboid((0.05, 0.05, 0.05)), translation=(0.02, 0.55, 0.0),
                               angvel=(1.0, 0.0, 0.0))
    world.step(20)
    state = world.save()
    world.step(25)
    first = (world.positions(cube), world.velocities(cube), world.rigid_pose(box), world.time)
    world.restore(state)
    assert world.frame == 20
    world.step(25)
    second = (world.positions(cube), world.velocities(cube), world.rigid_pose(box), world.time)
    assert np.array_equal(first[0], second[0]) and np.array_equal(first[1], second[1])
    assert first[2] == second[2] and first[3] == second[3]


def test_a_step_lets_other_threads_run():
    # The GIL is released while a world steps: a Python thread counting meanwhile gets on.
    world, _, _ = cube_on_ground()
    counted = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            counted.append(1)

    counter = threading.Thread(target=count)
    counter.start()
    before = len(counted)
    world.step(60)
    during = len(counted) - before
    stop.set()
    counter.join()
    assert during > 1000, during


def test_worlds_step_in_threads_as_they_do_alone():
    def run(out, i):
        world, _, cube = cube_on_ground()
        world.step(40)
        out[i] = world.positions(cube)

    alone = [None]
    run(alone, 0)
    together = [None, None]
    threads = [threading.Thread(target=run, args=(together, i)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(np.array_equal(alone[0], x) for x in together)


def test_a_kinematic_box_goes_where_it_is_told_and_pins_move_when_set():
    world = rf.World(dt=1 / 60)
    mover = world.add_rigid_body(rf.Shape.cuboid((0.05, 0.05, 0.05)), kind="kinematic")
    world.set_kinematic_target(mover, (0.0, 0.1, 0.0))
    world.step()
    assert world.rigid_pose(mover)[0] == pytest.approx((0.0, 0.1, 0.0), abs=1e-7)
    mesh = rf.Mesh.cuboid((0.1, 0.02, 0.02), (5, 1, 1))
    held = np.flatnonzero(mesh.nodes[:, 0] < -0.1 + 1e-9)
    beam = world.add_soft_body(mesh, rubber(), translation=(0.0, 1.0, 0.0), pinned=held)
    lifted = world.positions(beam)[held] + (0.0, 0.05, 0.0)
    world.set_positions(beam, lifted, nodes=held)
    world.step(5)
    np.testing.assert_array_equal(world.positions(beam)[held], lifted)


def test_stresses_are_the_cauchy_stress_of_a_uniform_stretch():
    world = rf.World(dt=1 / 60, gravity=(0.0, 0.0, 0.0))
    material = rf.Material("linear", young=1e6, poisson=0.25, density=1000.0)
    body = world.add_soft_body(rf.Mesh.cuboid((0.1, 0.1, 0.1), (2, 2, 2)), material)
    x = world.positions(body)
    world.set_positions(body, x * (1.001, 1.0, 1.0))
    sigma = world.stresses(body)
    # The linear law gives the first Piola-Kirchhoff stress P = lambda tr(e) I + 2 mu e with
    # e = 1e-3 along x, lambda = E nu/((1+nu)(1-2nu)) = 4e5 Pa, mu = E/(2(1+nu)) = 4e5 Pa; the
    # Cauchy stress is P F^T / J with F = diag(1.001, 1, 1), J = 1.001: sigma_xx = (lambda +
    # 2 mu) e, sigma_yy = lambda e / J, to 1e-9 of the values (round-off of the positions).
    lam, mu, e = 4e5, 4e5, 1e-3
    np.testing.assert_allclose(sigma[:, 0, 0], (lam + 2 * mu) * e, rtol=1e-9)
    np.testing.assert_allclose(sigma[:, 1, 1], lam * e / 1.001, rtol=1e-9)
    np.testing.assert_allclose(sigma[:, 0, 1], 0.0, atol=1e-9)


def test_a_pickled_world_steps_on_as_the_original():
    import pickle

    world, ground, cube = cube_on_ground()
    world.step(15)
    copy = pickle.loads(pickle.dumps(world))
    assert (copy.frame, copy.dt) == (world.frame, world.dt)
    world.step(20)
    copy.step(20)
    assert np.array_equal(world.positions(cube), copy.positions(cube))
    assert world.contact_force(cube, ground) == copy.contact_force(cube, ground)
