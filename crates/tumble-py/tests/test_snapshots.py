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
        (lambda b: b[:8] + bytes([2]) + b[9:], r"^snapshot: version 2, this build reads 1$"),
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
