"""Threads: a world's steps give the same bits on any thread count (issue 16)."""

import pytest

import tumble


def pile(threads):
    world = tumble.World(threads=threads, sleep=False)
    world.add_body(tumble.Plane((0, 1, 0), 0.0), kind="static")
    for i in range(120):
        x, z, y = (i % 6) * 0.5 - 1.25, (i // 6 % 4) * 0.5 - 0.75, 0.3 + 0.45 * (i // 24)
        shape = tumble.Box((0.2, 0.2, 0.2)) if i % 2 else tumble.Sphere(0.2)
        world.add_body(shape, position=(x, y, z), mass=1.0 + i % 3)
    return world


def test_every_thread_count_gives_the_same_state():
    hashes = {}
    for threads in (1, 2, 3):
        world = pile(threads)
        assert world.threads == threads
        for _ in range(90):
            world.step(1 / 60)
        hashes[threads] = (world.state_hash(), world.positions.tobytes())
    assert hashes[2] == hashes[1] and hashes[3] == hashes[1]


def test_the_default_is_every_core_or_tumble_threads():
    assert tumble.World().threads >= 1


@pytest.mark.parametrize("value", [0, -1, 257])
def test_a_bad_thread_count_is_refused_and_changes_nothing(value):
    with pytest.raises(ValueError, match=r"^threads: must be between 1 and 256, got -?\d+$"):
        tumble.World(threads=value)
    world = tumble.World(threads=2)
    with pytest.raises(ValueError, match=r"^threads: must be between 1 and 256"):
        world.threads = value
    assert world.threads == 2
    world.threads = 1
    assert world.threads == 1
