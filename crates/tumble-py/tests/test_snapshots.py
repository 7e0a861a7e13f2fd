"""Snapshots (issue 18): world.snapshot() / restore / World.from_snapshot, pickle and
copy.deepcopy continue a world bit-identically; bad snapshots raise ValueError."""

import copy
import pickle

import pytest

import tumble

DT = 1 / 60


def run(world, n):
    """The state hash and positions after each of n steps: the run's fingerprint."""
    out = []
    for _ in range(n):
        world.step(DT)
        out.append((world.state_hash(), world.positions.tobytes()))
    return out


def pile():
    world = tumble.World(integrator="verlet")
    world.add_body(tumble.Plane((0, 1, 0), 0.0), kind="static")
    for i in range(40):
        x, z, y = (i % 4) * 0.5 - 0.75, (i // 4 % 2) * 0.5, 0.3 + 0.45 * (i // 8)
        shape = tumble.Box((0.2, 0.2, 0.2)) if i % 2 else tumble.Sphere(0.2)
        world.add_body(shape, position=(x, y, z), mass=1.0 + i % 3)
    run(world, 60)
    return world


@pytest.mark.parametrize("name", ["pyramid", "ragdoll", "cradle", "rope_bridge"])
def test_a_restored_snapshot_continues_bit_identically(name):
    world = tumble.World.from_scene(name)
    run(world, 60)
    data = world.snapshot()
    assert isinstance(data, bytes)
    straight = run(world, 60)
    fresh = tumble.World.from_snapshot(data)
    assert fresh.time == pytest.approx(60 * DT, rel=1e-6)
    assert run(fresh, 60) == straight
    assert fresh.snapshot() == world.snapshot()


def test_restore_rewinds_the_same_world():
    world = pile()
    data = world.snapshot()
    once = run(world, 30)
    world.restore(data)
    assert run(world, 30) == once


def test_pickle_and_deepcopy_continue_bit_identically():
    world = pile()
    world.add_spring(world.bodies[3], world_point=(0, 4, 0), stiffness=50.0, rest_length=0.5)
    pickled = pickle.loads(pickle.dumps(world))
    deep = copy.deepcopy(world)
    shallow = copy.copy(world)
    straight = run(world, 40)
    for other in (pickled, deep, shallow):
        assert other is not world
        assert run(other, 40) == straight


@pytest.mark.parametrize(
    "mangle, message",
    [
        (lambda b: b[: len(b) - 1], r"^snapshot: truncated at byte \d+$"),
        (lambda b: b[:10], r"^snapshot: truncated at byte 10$"),
        (lambda b: b[:100] + bytes([b[100] ^ 1]) + b[101:], r"^snapshot: checksum mismatch"),
        (lambda b: b[:8] + bytes([2]) + b[9:], r"^snapshot: version 2, this build reads 5$"),
        (lambda b: b"hello world, not a snapshot", r"^snapshot: not a Tumble snapshot"),
        (lambda b: b + b"\0", r"^snapshot: 1 bytes after the end at byte \d+$"),
    ],
)
def test_a_bad_snapshot_raises_valueerror_and_changes_nothing(mangle, message):
    world = pile()
    good = world.snapshot()
    with pytest.raises(ValueError, match=message):
        world.restore(mangle(good))
    assert world.snapshot() == good
    with pytest.raises(ValueError, match=message):
        tumble.World.from_snapshot(mangle(good))


def test_the_other_precision_is_refused():
    data = bytearray(pile().snapshot())
    this, that = ("f32", "f64") if tumble.SINGLE_PRECISION else ("f64", "f32")
    data[12] = 8 if this == "f32" else 4
    with pytest.raises(ValueError, match=f"^snapshot: written in {that}, this build is {this}$"):
        tumble.World.from_snapshot(bytes(data))


def test_force_callbacks_are_reattached_and_must_match():
    world = pile()
    world.add_force_callback(lambda ctx: None)
    data = world.snapshot()
    with pytest.raises(ValueError, match="^snapshot: 1 force callbacks in the snapshot, 0 attached$"):
        tumble.World.from_snapshot(data)
    with pytest.raises(ValueError, match="force callbacks"):
        pickle.loads(pickle.dumps(world))
    straight = run(world, 20)
    other = tumble.World()
    other.add_force_callback(lambda ctx: None)
    other.restore(data)
    assert run(other, 20) == straight


def built_in_python():
    """Every shape kind, every force element, joints with options, unnamed bodies."""
    world = tumble.World(integrator="velocity_verlet", substeps=6, contact_hertz=45.0)
    world.add_body(tumble.Plane((0, 1, 0), 0.0), kind="static", friction=0.8)
    hull = tumble.ConvexHull([(0, 0, 0), (0.3, 0, 0), (0, 0.3, 0), (0, 0, 0.3), (0.2, 0.2, 0.2)])
    a = world.add_body(hull, position=(0, 1, 0), mass=2.0, name="hull")
    parts = tumble.Compound([tumble.Sphere(0.1), (tumble.Box((0.1, 0.05, 0.1)), (0, 0.2, 0))])
    b = world.add_body(parts, position=(1, 1.5, 0), angular_velocity=(0, 2, 1), restitution=0.3)
    c = world.add_body(tumble.Capsule(0.1, 0.2), position=(-1, 2, 0), linear_damping=0.1)
    d = world.add_body(tumble.Cylinder(0.2, 0.1), position=(2, 3, 0), gravity_scale=0.5)
    mesh = tumble.TriMesh([(-5, 0.01, -5), (5, 0.01, -5), (5, 0.01, 5)], [(0, 2, 1)])
    world.add_body(mesh, kind="static", position=(0, 0, 8))
    world.add_body(tumble.HeightField([[0, 0.1, 0], [0.2, 0, 0.1]], scale=(1, 1, 1)),
                   kind="static", position=(0, 0, -8))
    world.add_spring(a, other=b, stiffness=30.0, rest_length=0.4, damping=0.2)
    world.add_drag(c, linear=0.3, quadratic=0.1)
    world.add_force(d, force=(1, 0, 0), torque=(0, 0.1, 0))
    world.add_joint("hinge", c, None, anchor=(0, 0.3, 0), axis=(0, 0, 1), limits=(-0.5, 0.5),
                    motor=tumble.Motor(1.0, 2.0), name="elbow")
    world.add_joint("distance", d, a, max=3.0)
    run(world, 30)
    return world


def test_a_scene_built_in_python_saved_with_its_state_loads_as_the_same_world(tmp_path):
    world = built_in_python()
    path = tmp_path / "saved.json"
    world.save_scene(path)
    loaded = tumble.World.from_scene(path)
    assert loaded.snapshot() == world.snapshot()
    assert run(loaded, 60) == run(world, 60)


def test_a_scene_saved_without_state_is_the_same_scene(tmp_path):
    world = built_in_python()
    path = tmp_path / "fresh.json"
    world.save_scene(path, state=False)
    assert '"state"' not in path.read_text()
    loaded = tumble.World.from_scene(path)
    assert len(loaded.bodies) == len(world.bodies)
    assert loaded.integrator == world.integrator
    # Positions go body origin -> centre of mass -> body origin: a few ulps.
    tol = 1e-5 if tumble.SINGLE_PRECISION else 1e-12
    assert abs(loaded.positions - world.positions).max() < tol
    assert (loaded.velocities == world.velocities).all()
