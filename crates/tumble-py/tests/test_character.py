"""tumble.CharacterController: the engine's character controller from Python.

The physics is the engine's (crates/tumble/tests/character.rs tests it at length); these
check that Python drives it the same way, against the same closed forms: a ramp climbed on
the line a skin above it, a step climbed and a higher one refused, a wall slid along with
the tangential velocity, a thin wall never passed at 20 m/s, a ball pushed with bounded
impulses, and every bad argument refused naming its field.
"""

import math
import re

import numpy as np
import pytest

import tumble

SKIN = 0.02
G = 9.8


def floor_world():
    world = tumble.World(gravity=(0, -G, 0))
    world.add_body(tumble.Plane((0, 1, 0)), kind="static", name="floor")
    return world


def walk(c, velocity, dt, steps, gravity=(0, -G, 0)):
    """The scene format's walker: `velocity`, plus gravity accumulated while in the air;
    the positions after each move."""
    fall = np.zeros(3)
    out = []
    for _ in range(steps):
        fall = np.zeros(3) if c.on_ground else fall + np.asarray(gravity) * dt
        c.move((np.asarray(velocity) + fall) * dt, dt)
        out.append(c.position)
    return out


def test_it_stands_on_the_ground_with_the_defaults():
    world = floor_world()
    c = tumble.CharacterController(world, position=(0, 0.92, 0))
    assert c.on_ground
    np.testing.assert_array_equal(c.ground_normal, [0, 1, 0])
    assert c.ground_body.name == "floor"
    assert (c.radius, c.half_height, c.step_height, c.skin) == (0.3, 0.6, 0.3, 0.02)
    assert c.max_slope == pytest.approx(math.pi / 4, abs=1e-6)
    assert c.world is world or c.world.time == world.time
    air = tumble.CharacterController(world, position=(0, 5, 0))
    assert not air.on_ground and air.ground_normal is None and air.ground_body is None


@pytest.mark.parametrize("radius,dt", [(0.2, 1 / 30), (0.3, 1 / 60), (0.45, 1 / 240)])
def test_a_20_degree_ramp_is_climbed_on_the_line_a_skin_above_it(radius, dt):
    """Centre height tan θ (x − foot) + (r + skin)/cos θ + h on the ramp, to half a skin
    (the gap the controller keeps, within its sweep's stop)."""
    theta = math.radians(20)
    world = floor_world()
    length, t = 8.0, 0.5
    n = np.array([-math.sin(theta), math.cos(theta), 0])
    mid = np.array([1 + 0.5 * length * math.cos(theta), 0.5 * length * math.sin(theta), 0])
    q = (0, 0, math.sin(theta / 2), math.cos(theta / 2))
    world.add_body(
        tumble.Box((0.5 * length, t, 3)), kind="static", position=mid - n * t, orientation=q
    )
    c = tumble.CharacterController(world, radius=radius, position=(0, radius + 0.6 + SKIN, 0))
    on_ramp = 0
    for _ in range(int(3 / dt)):
        p = walk(c, (2, 0, 0), dt, 1)[-1]
        assert c.on_ground
        if np.allclose(c.ground_normal, n, atol=1e-6):
            on_ramp += 1
            line = math.tan(theta) * (p[0] - 1) + (radius + SKIN) / math.cos(theta) + 0.6
            assert abs(p[1] - line) <= 0.5 * SKIN
    assert on_ramp * dt > 1.0


@pytest.mark.parametrize("ratio,climbed", [(0.8, True), (1.5, False)])
def test_steps_below_the_step_height_are_climbed_and_higher_ones_refused(ratio, climbed):
    h = ratio * 0.3
    world = floor_world()
    world.add_body(tumble.Box((2, h / 2, 3)), kind="static", position=(3, h / 2, 0))
    c = tumble.CharacterController(world, position=(0, 0.92, 0), step_height=0.3)
    p = walk(c, (1.5, 0, 0), 1 / 60, 120)[-1]
    if climbed:
        assert abs(p[1] - (h + 0.92)) <= 0.5 * SKIN and p[0] > 2 and c.on_ground
    else:
        assert abs(p[1] - 0.92) <= 0.5 * SKIN
        assert abs(p[0] - (1 - 0.3 - SKIN)) <= 0.5 * SKIN


def test_a_wall_at_45_degrees_is_slid_along_with_the_tangential_velocity():
    """v − (v·n) n to 1e-9 m/s once it slides: the plane solver's exact projection."""
    world = floor_world()
    n = np.array([-1, 0, 1]) / math.sqrt(2)
    q = (0, math.sin(math.pi / 8), 0, math.cos(math.pi / 8))
    world.add_body(
        tumble.Box((0.1, 2, 20)), kind="static", position=np.array([2, 0, 0]) - n * 0.1,
        orientation=q,
    )
    c = tumble.CharacterController(world, position=(0, 0.92, 0))
    v = np.array([3.0, 0, 0])
    walk(c, v, 1 / 60, 90)
    tangential = v - n * v.dot(n)
    np.testing.assert_allclose(c.velocity, tangential, atol=1e-9 if not tumble.SINGLE_PRECISION else 1e-3)


def test_no_tunnelling_through_a_5_cm_wall_at_20_m_s():
    world = floor_world()
    world.add_body(tumble.Box((0.025, 2, 5)), kind="static", position=(3.025, 2, 0))
    for dt in (1 / 15, 1 / 60):
        c = tumble.CharacterController(world, radius=0.1, position=(0, 0.72, 0))
        for p in walk(c, (20, 0, 0), dt, int(1 / dt)):
            assert p[0] <= 3 - 0.1 - 0.4 * SKIN


def test_pushes_are_bounded_by_max_push_force():
    """A 500 kg ball on a frictionless floor, pushed with at most 100 N: every push is
    F·dt (to 1e-6 relative) and the ball's momentum their sum (to 1e-6 relative)."""
    world = tumble.World(gravity=(0, -G, 0))
    world.add_body(tumble.Plane((0, 1, 0)), kind="static", friction=0.0)
    ball = world.add_body(tumble.Sphere(0.5), mass=500.0, position=(2, 0.5, 0), friction=0.0)
    c = tumble.CharacterController(world, position=(0, 0.92, 0), max_push_force=100.0)
    dt, total, count = 1 / 60, np.zeros(3), 0
    for _ in range(120):
        c.move((1.5 * dt, 0, 0), dt)
        for push in c.pushes:
            assert push.body == ball
            assert np.linalg.norm(push.impulse) == pytest.approx(100 * dt, rel=1e-6)
            total += push.impulse
            count += 1
        world.step(dt)
    assert count > 0
    assert ball.linear_momentum[0] == pytest.approx(total[0], rel=1e-6)
    assert total[0] == pytest.approx(100 * dt * count, rel=1e-6)


def test_bad_arguments_are_refused_naming_the_field():
    world = floor_world()
    cases = [
        (dict(radius=0), ValueError, "character.radius: must be > 0"),
        (dict(radius=float("nan")), ValueError, "character.radius: must be a finite number"),
        (dict(half_height=-1), ValueError, "character.half_height: must be >= 0"),
        (dict(max_slope=2.0), ValueError, "character.max_slope: must be >= 0 and below π/2 rad (90°), got 2"),
        (dict(step_height=-0.1), ValueError, "character.step_height: must be >= 0"),
        (dict(skin=0.5), ValueError, "character.skin: must be less than radius (0.3 m)"),
        (dict(snap_distance=-1), ValueError, "character.snap_distance: must be >= 0"),
        (dict(max_push_force=-1), ValueError, "character.max_push_force: must be >= 0"),
        (dict(up=(0, 0, 0)), ValueError, "character.up: must be a non-zero vector"),
        (dict(position=(0, 1)), ValueError, "character.position: expected 3 numbers [x, y, z], got 2 numbers"),
        (dict(position="up"), TypeError, "character.position: expected 3 numbers [x, y, z]"),
        (dict(collision_mask=-1), ValueError, "character.collision_mask: must be a whole number in [0, 2**32)"),
        (dict(exclude="nobody"), ValueError, "character.exclude: no body named 'nobody'"),
    ]
    for kwargs, error, message in cases:
        with pytest.raises(error) as e:
            tumble.CharacterController(world, **kwargs)
        assert str(e.value).startswith(message), (kwargs, str(e.value))
    c = tumble.CharacterController(world, position=(0, 0.92, 0))
    c.move((0.1, 0, 0), 0.1)
    before = (c.position.copy(), c.velocity.copy(), c.on_ground)
    for displacement, dt, message in [
        ((float("nan"), 0, 0), 0.1, "displacement: must be finite numbers"),
        ((1, 0, 0), 0.0, "dt: must be > 0"),
        ((2e9, 0, 0), 0.1, "displacement: must be at most 1e9 m in magnitude"),
    ]:
        with pytest.raises(ValueError, match=r"^" + message.replace("(", r"\(").replace(")", r"\)")):
            c.move(displacement, dt)
        np.testing.assert_array_equal(c.position, before[0])
        np.testing.assert_array_equal(c.velocity, before[1])
    with pytest.raises(TypeError):
        c.move("east", 0.1)
    with pytest.raises(ValueError, match="^position: must be finite numbers"):
        c.position = (0, float("inf"), 0)
    c.position = (1, 0.92, 0)
    np.testing.assert_array_equal(c.position, [1, 0.92, 0])


def test_the_course_scene_is_a_builtin_and_its_walker_a_body():
    assert "character_course" in tumble.SCENES
    world = tumble.World.from_scene("character_course")
    walker = world.body("walker")
    assert walker.kind == "kinematic"
    assert (walker.collision_group, walker.collision_mask) == (0, 0)


@pytest.mark.parametrize("dt", [1 / 60, 1 / 240])
def test_a_saved_run_continues_as_the_run_that_never_stopped(dt):
    # A world with a box to walk onto and a dynamic crate to push; the walker's state is
    # saved with the world's snapshot mid-run, and the saved run, restored into the same
    # world and controller after they went on elsewhere, retraces the first run exactly.
    world = floor_world()
    world.add_body(tumble.Box((0.5, 0.1, 2.0)), kind="static", position=(2.0, 0.1, 0.0))
    world.add_body(tumble.Box((0.2, 0.2, 0.2)), mass=2.0, position=(4.0, 0.2, 0.0))
    c = tumble.CharacterController(world, position=(0.0, 0.95, 0.0))

    def run(steps):
        out = []
        for k in range(steps):
            p = walk(c, (1.5, 0.0, 0.1 * math.sin(k * dt * 3)), dt, 1)[-1]
            world.step(dt)
            out.append((p.copy(), world.state_hash(), c.on_ground))
        return out

    run(int(1.0 / dt))
    snap, state = world.snapshot(), c.state()
    assert state["ground"] is not None  # (the box's edge, climbing onto it)
    first = run(int(2.0 / dt))
    assert first[-1][0][0] > 3.0, "walked onto the box and on to the crate"
    world.restore(snap)
    c.restore(state)
    second = run(int(2.0 / dt))
    for (p1, h1, g1), (p2, h2, g2) in zip(first, second):
        assert np.array_equal(p1, p2) and h1 == h2 and g1 == g2


def test_restore_refuses_bad_states_naming_the_key_and_changes_nothing():
    world = floor_world()
    c = tumble.CharacterController(world, position=(0.0, 0.95, 0.0))
    c.move((0.0, -0.1, 0.0), 1 / 60)
    good = c.state()
    assert good["ground"] is not None
    other = floor_world()
    stranger = other.add_body(tumble.Sphere(0.1), position=(0, 5, 0))
    ground = dict(good["ground"])
    cases = [
        (TypeError, "state: expected a dict", [1, 2, 3]),
        (ValueError, "state.position: required", {"velocity": [0, 0, 0]}),
        (ValueError, "state.colour: unknown key", dict(good, colour=1)),
        (ValueError, "state.position", dict(good, position=[0, 1])),
        (ValueError, "state.velocity", dict(good, velocity=[0, float("nan"), 0])),
        (TypeError, "state.ground: expected a dict or None", dict(good, ground=3)),
        (ValueError, "state.ground.normal: required", dict(good, ground={"body": ground["body"], "point": [0, 0, 0]})),
        (ValueError, "state.ground.normal: must be a unit vector", dict(good, ground=dict(ground, normal=[0, 2, 0]))),
        (ValueError, "state.ground.body: this body belongs to another world", dict(good, ground=dict(ground, body=stranger))),
        (ValueError, "state.position: ", dict(good, position=[1e300, 0, 0])),
    ]
    for error, text, bad in cases:
        with pytest.raises(error, match="^" + re.escape(text)):
            c.restore(bad)
        assert np.array_equal(c.position, good["position"]) and c.on_ground
    # Velocity and ground may be left out: at rest, in the air.
    c.restore({"position": [0.0, 3.0, 0.0]})
    assert not c.on_ground and np.array_equal(c.velocity, [0, 0, 0])
