"""Issue 17 from Python: sensors (world.sensor_events(), body.sensor) and one-way
platforms (add_body(..., one_way=...)), against the closed forms of the Rust tests
(crates/tumble/tests/sensors.rs, one_way.rs) and with the same field-named errors."""

import math

import numpy as np
import pytest

import tumble

G = 9.8


@pytest.mark.parametrize("r, h, low, high, dt", [
    (0.1, 5.0, 1.0, 2.0, 1 / 60),
    (0.3, 3.0, -1.0, 0.5, 1 / 240),
])
def test_a_falling_ball_enters_and_leaves_at_the_free_fall_times(r, h, low, high, dt):
    # Each event is stamped at the end of the step that saw it: within one step of the
    # exact time (see sensors.rs). The ball falls as if the sensor were not there.
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    gate = world.add_body(tumble.Box((2, (high - low) / 2, 2)), kind="static",
                          position=(0, (low + high) / 2, 0), sensor=True, name="gate")
    ball = world.add_body(tumble.Sphere(r), position=(0, h, 0))
    assert gate.sensor and not ball.sensor
    events = []
    inside = []
    while world.time < math.sqrt(2 * (h - low + r) / G) + 0.2:
        world.step(dt)
        events += world.sensor_events()
        inside.append(len(world.sensor_overlaps("gate")))
    assert [(e.sensor, e.body, e.began) for e in events] == [(gate, ball, True),
                                                            (gate, ball, False)]
    exact = [math.sqrt(2 * (h - high - r) / G), math.sqrt(2 * (h - low + r) / G)]
    for e, t in zip(events, exact):
        assert abs(e.time - t) <= dt
        assert "SensorEvent" in repr(e)
    assert max(inside) == 1 and inside[-1] == 0
    assert ball.velocity[0] == 0.0 and ball.velocity[2] == 0.0


def test_the_sensor_flag_is_settable_and_removal_ends_overlaps():
    world = tumble.World(gravity=(0, 0, 0))
    gate = world.add_body(tumble.Box((1, 1, 1)), kind="static", sensor=True)
    a = world.add_body(tumble.Sphere(0.1), position=(0.5, 0, 0))
    b = world.add_body(tumble.Sphere(0.1), position=(-0.5, 0, 0))
    world.step(0.1)
    assert world.sensor_overlaps(gate) == [a, b]
    removed_at = world.time
    world.remove_body(a)
    world.step(0.1)
    [end] = world.sensor_events()
    assert (end.sensor, end.began, end.time) == (gate, False, removed_at)
    gate.sensor = False
    assert not gate.sensor
    world.step(0.1)
    assert [(e.body, e.began) for e in world.sensor_events()] == [(b, False)]
    assert world.sensor_overlaps(gate) == []


def test_a_box_jumps_up_through_a_one_way_platform_and_lands_on_it():
    dt, half, top = 1 / 60, 0.2, 1.0
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    platform = world.add_body(tumble.Box((2, 0.05, 2)), kind="static",
                              position=(0, top - 0.05, 0), one_way=(0, 2, 0))
    assert np.array_equal(platform.one_way, [0, 1, 0])
    # Up to 0.4 m above the top face (symplectic Euler's apex, see one_way.rs).
    y0 = 0.2
    v0 = math.sqrt(2 * G * (top + 0.4 + half - y0)) + 0.5 * G * dt
    box = world.add_body(tumble.Box((half, half, half)), position=(0, y0, 0),
                         velocity=(0, v0, 0))
    peak = y0
    for _ in range(round(3 / dt)):
        world.step(dt)
        peak = max(peak, box.position[1])
    assert peak > top + half + 0.3
    assert box.position[1] == pytest.approx(top + half, abs=0.01)
    assert np.linalg.norm(box.velocity) < 0.01
    platform.one_way = None
    assert platform.one_way is None


@pytest.mark.parametrize("bad, message", [
    ((0, 0, 0), "one_way: must be a non-zero vector"),
    ((0, float("nan"), 0), "one_way: must be finite numbers"),
])
def test_one_way_is_checked_as_the_scene_loader_checks_it(bad, message):
    world = tumble.World()
    with pytest.raises(ValueError, match=f"^{message}$"):
        world.add_body(tumble.Sphere(0.1), one_way=bad)
    body = world.add_body(tumble.Box((1, 1, 1)), kind="static", one_way=(0, 1, 0))
    with pytest.raises(ValueError, match=f"^{message}$"):
        body.one_way = bad
    assert np.array_equal(body.one_way, [0, 1, 0])
    with pytest.raises(ValueError, match=r"^bodies\[0\]\.one_way: must be a non-zero vector$"):
        tumble.World.from_json(
            '{"bodies": [{"shape": {"type": "sphere", "radius": 1}, "one_way": [0, 0, 0]}]}')
    with pytest.raises(TypeError):
        world.add_body(tumble.Sphere(0.1), one_way="up")


def test_a_scene_with_a_sensor_reports_from_python():
    world = tumble.World.from_json("""{"bodies": [
        {"name": "gate", "kind": "static", "sensor": true, "position": [0, 1, 0],
         "shape": {"type": "box", "half_extents": [1, 0.5, 1]}},
        {"name": "ball", "position": [0, 3, 0], "shape": {"type": "sphere", "radius": 0.1}}
    ]}""")
    began = []
    for _ in range(120):
        world.step(1 / 60)
        began += [e.began for e in world.sensor_events()]
    assert began == [True, False]
