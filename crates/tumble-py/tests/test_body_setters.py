"""Issue 17 from Python: damping, the body setters, gravity scale and kinematic targets,
against the same closed forms as the Rust tests (crates/tumble/tests/damping.rs,
body_setters.rs, kinematic_targets.rs), and the same field-named errors."""

import math
import re

import numpy as np
import pytest

import tumble

G = 9.8


@pytest.mark.parametrize("integrator", ["explicit_euler", "rk4", "verlet", "implicit_euler"])
@pytest.mark.parametrize("c, dt", [(0.1, 1 / 60), (1.0, 1 / 240), (5.0, 1 / 60)])
def test_damping_decays_as_exp_minus_ct(integrator, c, dt):
    # The decay is exact per step (see damping.rs): the 0.5 % has room to spare.
    world = tumble.World(gravity=(0, 0, 0), integrator=integrator, sleep=False)
    v0, w0 = np.array([3.0, -2.0, 1.0]), np.array([1.0, 2.0, -0.5])
    ball = world.add_body(tumble.Sphere(0.3), mass=2.0, velocity=v0, angular_velocity=w0,
                          linear_damping=c, angular_damping=c)
    assert (ball.linear_damping, ball.angular_damping) == (c, c)
    n = round(3 / (c * dt))
    for _ in range(n):
        world.step(dt)
    decay = math.exp(-c * n * dt)
    assert np.allclose(ball.velocity, v0 * decay, rtol=0.005, atol=0)
    assert np.allclose(ball.angular_velocity, w0 * decay, rtol=0.005, atol=0)


def test_damped_fall_reaches_g_over_c_and_the_property_is_settable():
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    ball = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(0, 1000, 0))
    ball.linear_damping = 2.0
    world.simulate(duration=5.0, dt=1 / 120)
    # v(5) = -(g/c)(1 - e^-10): within 0.5 % of g/c.
    assert ball.velocity[1] == pytest.approx(-G / 2.0 * (1 - math.exp(-10)), rel=0.005)


def test_friction_set_to_zero_mid_slide():
    mu, dt = 0.3, 1 / 60
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    ground = world.add_body(tumble.Plane((0, 1, 0), 0.0), kind="static", friction=mu)
    box = world.add_body(tumble.Box((0.25, 0.25, 0.25)), position=(0, 0.25, 0),
                         velocity=(6, 0, 0), friction=mu)
    for _ in range(6):
        world.step(dt)
    v1 = box.velocity[0]
    for _ in range(18):
        world.step(dt)
    v2 = box.velocity[0]
    assert (v1 - v2) / (18 * dt) == pytest.approx(mu * G, rel=0.01)
    ground.friction = 0.0
    assert ground.friction == 0.0
    for _ in range(30):
        world.step(dt)
    assert abs(v2 - box.velocity[0]) / (30 * dt) < 0.01 * mu * G


def test_restitution_set_between_drops():
    r, h, dt = 0.1, 1.0, 1 / 240
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    world.add_body(tumble.Plane((0, 1, 0), 0.0), kind="static")
    ball = world.add_body(tumble.Sphere(r), position=(0, r + h, 0))
    for e in (0.5, 0.8):
        ball.restitution = e
        ball.position, ball.velocity, ball.angular_velocity = (0, r + h, 0), (0, 0, 0), (0, 0, 0)
        rebound = None
        bounced = False
        for _ in range(int(3 / dt)):
            world.step(dt)
            y, vy = ball.position[1] - r, ball.velocity[1]
            bounced |= vy > 0
            if bounced and vy > 0 and y > 0.05:
                rebound = y + vy * vy / (2 * G)
                break
        assert rebound == pytest.approx(e * e * h, rel=0.02)


def test_collision_mask_lets_a_body_fall_through_and_gravity_scale_halves_the_fall():
    dt = 1 / 100
    world = tumble.World(gravity=(0, -G, 0))
    world.add_body(tumble.Plane((0, 1, 0), 0.0), kind="static", collision_group=2)
    ball = world.add_body(tumble.Sphere(0.1), position=(0, 0.1, 0))
    for _ in range(120):
        world.step(dt)
    assert ball.position[1] == pytest.approx(0.1, abs=0.005)
    ball.collision_mask = 0xFFFFFFFF & ~2
    assert (ball.collision_group, ball.collision_mask) == (1, 0xFFFFFFFD)
    assert ball.awake
    for _ in range(50):
        world.step(dt)
    assert ball.position[1] < -1.0
    # Gravity scale: two free balls, exact halves of the fall (to rounding).
    free = tumble.World(gravity=(0, -G, 0))
    a = free.add_body(tumble.Sphere(0.1), position=(0, 10, 0))
    b = free.add_body(tumble.Sphere(0.1), position=(1, 10, 0), gravity_scale=0.5)
    for _ in range(100):
        free.step(dt)
    assert b.velocity[1] == pytest.approx(0.5 * a.velocity[1], rel=1e-5)
    assert 10 - b.position[1] == pytest.approx(0.5 * (10 - a.position[1]), rel=1e-5)
    b.gravity_scale = 0.0
    v = b.velocity.copy()
    free.step(dt)
    assert np.array_equal(b.velocity, v)


def test_bad_values_raise_the_loaders_messages_and_change_nothing():
    world = tumble.World()
    ball = world.add_body(tumble.Sphere(0.1), position=(0, 1, 0))
    cases = [
        ("friction", -1.0, "friction: must be >= 0"),
        ("restitution", 1.5, "restitution: must be <= 1"),
        ("linear_damping", -1.0, "linear_damping: must be >= 0"),
        ("angular_damping", float("nan"), "angular_damping: must be a finite number"),
        ("gravity_scale", float("inf"), "gravity_scale: must be a finite number"),
        ("collision_mask", -1, "collision_mask: must be a whole number in [0, 2**32)"),
    ]
    for name, value, message in cases:
        before = getattr(ball, name)
        with pytest.raises(ValueError, match=re.escape(message)):
            setattr(ball, name, value)
        assert getattr(ball, name) == before, name
    with pytest.raises(TypeError):
        ball.friction = "high"
    with pytest.raises(ValueError, match="linear_damping: must be >= 0"):
        world.add_body(tumble.Sphere(0.1), linear_damping=-2)
    with pytest.raises(ValueError, match="kind: a kinematic target needs a kinematic body"):
        ball.set_kinematic_target((0, 0, 0))


def test_kinematic_platform_hits_its_targets_and_carries_a_box():
    dt = 1 / 60
    world = tumble.World(gravity=(0, -G, 0))
    platform = world.add_body(tumble.Box((2, 0.1, 1)), kind="kinematic", friction=0.8)
    box = world.add_body(tumble.Box((0.2, 0.2, 0.2)), position=(0, 0.3, 0), mass=3.0,
                         friction=0.8)
    for _ in range(30):
        world.step(dt)
    start = box.position.copy()
    n = round(2 / dt)
    worst = 0.0
    for k in range(1, n + 1):
        u = k * dt / 2
        x = u - math.sin(2 * math.pi * u) / (2 * math.pi)
        platform.set_kinematic_target((x, 0, 0), (0, 0, 0, 1))
        world.step(dt)
        assert platform.position[0] == pytest.approx(x, abs=1e-6)
        worst = max(worst, abs(box.position[0] - start[0] - platform.position[0]))
    assert box.position[0] - start[0] == pytest.approx(1.0, abs=3e-3)
    assert worst < 3e-3
    # A turn: exactly at the target orientation after one step.
    q = np.array([0, math.sin(0.6), 0, math.cos(0.6)])
    platform.set_kinematic_target(platform.position, q)
    world.step(dt)
    assert abs(abs(np.dot(platform.orientation, q)) - 1) < 1e-6
    assert platform.angular_velocity[1] == pytest.approx(1.2 / dt, rel=1e-6)
