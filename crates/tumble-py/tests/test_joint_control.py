"""Joints changed while the world runs (motor, servo, limits, spring, enabled, break
force) and joint coordinates read and set, against closed forms."""

import math

import pytest

import tumble

G = 9.8


def door(mass):
    """A 1 x 2 x 0.05 m door hinged about y along its left edge; gravity along the hinge."""
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    slab = world.add_body(tumble.Box((0.5, 1.0, 0.025)), mass=mass, position=(0.5, 1.0, 0))
    hinge = world.add_joint("hinge", slab, anchor=(-0.5, 0, 0), axis=(0, 1, 0))
    inertia = mass * (1.0 + 0.05**2) / 12 + mass * 0.25
    return world, slab, hinge, inertia


@pytest.mark.parametrize("mass,tau,dt", [(1.0, 0.5, 1 / 60), (5.0, 4.0, 1 / 120)])
def test_a_door_motor_reversed_mid_run_turns_back_at_torque_over_inertia(mass, tau, dt):
    # While the reversed motor is at its cap τ the rate falls at α = τ/I (the motor row
    # gives exactly τ·h a substep; measured within 4e-6 of τ/I, so 1 % is the brief's
    # bound with room); it ends at −1 rad/s (1e-4: the soft point lock's give).
    world, slab, hinge, inertia = door(mass)
    alpha = tau / inertia
    hinge.motor = tumble.Motor(1.0, tau)
    assert hinge.motor.speed == 1.0 and hinge.motor.max_force == tau
    steps = int(2.0 / (alpha * dt))
    for _ in range(steps + 10):
        world.step(dt)
    assert hinge.velocity == pytest.approx(1.0, abs=1e-4)
    hinge.motor = tumble.Motor(-1.0, tau)
    for _ in range(steps // 4):
        world.step(dt)
    r0, t0 = hinge.velocity, world.time
    for _ in range(steps // 2):
        world.step(dt)
    measured = (r0 - hinge.velocity) / (world.time - t0)
    assert measured == pytest.approx(alpha, rel=0.01)
    for _ in range(steps):
        world.step(dt)
    assert hinge.velocity == pytest.approx(-1.0, abs=1e-4)
    assert slab.angular_velocity[1] == pytest.approx(-1.0, abs=1e-4)
    hinge.motor = None
    assert hinge.motor is None


def arm(world, mass):
    """A 1 m arm hinged about z at the origin, lying along +x."""
    body = world.add_body(tumble.Box((0.5, 0.05, 0.05)), mass=mass, position=(0.5, 0, 0))
    joint = world.add_joint("hinge", body, anchor=(-0.5, 0, 0), axis=(0, 0, 1))
    return body, joint


@pytest.mark.parametrize("target", [0.3, 1.2])
@pytest.mark.parametrize("mass", [1.0, 4.0])
def test_a_servo_holds_an_arm_at_its_target_against_gravity(target, mass):
    # k = 5000 N·m/rad: gravity's torque m g (l/2) cos θ holds it at most τ/k = 0.0037 rad
    # below the target (less: see the Rust test); critically damped, settled in 3 s.
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    body, joint = arm(world, mass)
    k = 5000.0
    inertia = mass * 1.01 / 12 + mass * 0.25
    joint.servo = tumble.Servo(target, k, 2 * math.sqrt(k * inertia), 1000.0)
    world.simulate(duration=3.0, dt=1 / 60)
    sag = mass * G * 0.5 * math.cos(target) / k
    assert abs(joint.position - target) < 0.01
    assert 0 < target - joint.position < 1.01 * sag
    c = body.position
    assert math.atan2(c[1], c[0]) == pytest.approx(joint.position, abs=1e-3)
    assert joint.servo.target == target and joint.servo.stiffness == k


def test_joint_position_follows_the_small_angle_pendulum():
    # A 1 kg ball (r 0.1 m) on a 1 m hinge released at 0.05 rad: the joint reads 0 at
    # creation, then θ₀ cos(Ωt) − θ₀, Ω = √(m g l / I); 2 % of θ₀ as in the Rust test.
    theta0, length, dt = 0.05, 1.0, 1 / 240
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    p = (length * math.sin(theta0), -length * math.cos(theta0), 0)
    bob = world.add_body(tumble.Sphere(0.1), mass=1.0, position=p)
    joint = world.add_joint("hinge", bob, anchor=(-p[0], -p[1], 0), axis=(0, 0, 1))
    assert joint.position == 0.0
    omega = math.sqrt(G * length / (0.4 * 0.01 + length**2))
    for _ in range(240):
        world.step(dt)
        t = world.time
        assert joint.position == pytest.approx(theta0 * math.cos(omega * t) - theta0, abs=0.02 * theta0)
        assert joint.velocity == pytest.approx(-theta0 * omega * math.sin(omega * t), abs=0.02 * theta0 * omega)


def test_setting_a_position_moves_the_outer_links_rigidly():
    # Three hinged links; joint 1 (body = link 0, held by the world) set to q moves links 1
    # and 2 as one: joint 2's coordinate is unchanged and joint 1 reads q back to 1e-9.
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    links = [world.add_body(tumble.Box((0.5, 0.05, 0.05)), mass=1.0 + i, position=(0.5 + i, 0, 0)) for i in range(3)]
    j0 = world.add_joint("hinge", links[0], anchor=(-0.5, 0, 0), axis=(0, 0, 1))
    j1 = world.add_joint("hinge", links[0], links[1], anchor=(0.5, 0, 0), axis=(0, 0, 1))
    j2 = world.add_joint("hinge", links[2], links[1], anchor=(-0.5, 0, 0), axis=(0, 0, 1))
    world.simulate(duration=1.0, dt=1 / 60)
    eps = 1e-5 if tumble.SINGLE_PRECISION else 1e-9
    a0, a2 = j0.position, j2.position
    p0 = links[0].position.copy()
    j1.position = 0.7
    assert j1.position == pytest.approx(0.7, abs=eps)
    assert j0.position == pytest.approx(a0, abs=eps)
    assert j2.position == pytest.approx(a2, abs=eps)
    assert (links[0].position == p0).all()


def test_ball_joint_position_is_a_rotation_vector():
    world = tumble.World(gravity=(0, 0, 0), sleep=False)
    link = world.add_body(tumble.Box((0.5, 0.05, 0.05)), mass=1.0, position=(0.5, 0, 0))
    joint = world.add_joint("ball", link, anchor=(-0.5, 0, 0))
    assert joint.position == (0.0, 0.0, 0.0)
    eps = 1e-5 if tumble.SINGLE_PRECISION else 1e-9
    joint.position = (0.2, -0.4, 0.9)
    assert joint.position == pytest.approx((0.2, -0.4, 0.9), abs=eps)
    link.angular_velocity = (2.0, 0.0, 0.0)
    assert joint.velocity == pytest.approx((2.0, 0.0, 0.0), abs=eps)
    with pytest.raises(TypeError, match=r"position: expected 3 numbers"):
        joint.position = 0.3
    hinge_body = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(5, 0, 0))
    hinge = world.add_joint("hinge", hinge_body, axis=(0, 0, 1))
    with pytest.raises(TypeError, match=r"position: expected a number"):
        hinge.position = (0.1, 0.2, 0.3)


def test_limits_changed_at_run_time_stop_the_arm():
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    _, joint = arm(world, 2.0)
    for _ in range(6):
        world.step(1 / 60)
    assert joint.limits is None
    joint.limits = (-0.4, 0.8)
    assert joint.limits == (-0.4, 0.8)
    lowest = 0.0
    for _ in range(180):
        world.step(1 / 60)
        lowest = min(lowest, joint.position)
    assert lowest > -0.41
    assert joint.position == pytest.approx(-0.4, abs=0.01)
    joint.limits = None
    world.simulate(duration=1.0, dt=1 / 60)
    assert joint.position < -1.0


def test_a_disabled_joint_lets_its_body_fall_freely():
    # A free body's centre gains exactly −g·dt a step (rounding only).
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    body, joint = arm(world, 2.0)
    for _ in range(10):
        world.step(1 / 60)
    joint.enabled = False
    assert joint.enabled is False
    v0 = body.velocity[1]
    for _ in range(20):
        world.step(1 / 60)
    g = (v0 - body.velocity[1]) / (20 / 60)
    assert g == pytest.approx(G, rel=1e-9 if not tumble.SINGLE_PRECISION else 1e-3)
    joint.enabled = True
    assert joint.enabled is True


def test_break_force_and_spring_are_settable():
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    body = world.add_body(tumble.Box((0.05, 0.5, 0.05)), mass=2.0, position=(0, -0.5, 0))
    joint = world.add_joint("hinge", body, anchor=(0, 0.5, 0), axis=(0, 0, 1))
    joint.spring = tumble.JointSpring(2.0, 0.5, 0.1)
    assert joint.spring.hertz == 2.0 and joint.spring.target == 0.1
    joint.spring = None
    joint.break_force = 100.0
    world.simulate(duration=0.5, dt=1 / 60)
    assert not joint.broken and joint.break_force == 100.0
    joint.break_force = 10.0  # the hanging 2 kg arm pulls 19.6 N
    world.step(1 / 60)
    assert joint.broken
    joint.break_force = None
    assert joint.break_force is None


def test_bad_values_are_refused_by_field_and_change_nothing():
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    _, joint = arm(world, 1.0)
    joint.motor = tumble.Motor(1.0, 5.0)
    ball_body = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(5, 0, 0))
    ball = world.add_joint("ball", ball_body)
    cases = [
        ("motor", tumble.Motor(1.0, -1.0), ValueError, "motor.max_force: must be >= 0"),
        ("motor", 3.0, TypeError, "motor: expected a tumble.Motor"),
        ("servo", tumble.Servo(0.1, -1.0, 0.0, 1.0), ValueError, "servo.stiffness: must be >= 0"),
        ("servo", tumble.Servo(0.1, 0.0, 0.0, 1.0), ValueError, "servo.stiffness: must be > 0 when damping is 0"),
        ("limits", (1.0, -1.0), ValueError, "limits: lower must be <= upper"),
        ("limits", (1.0, 2.0, 3.0), (ValueError, TypeError), "limits"),
        ("spring", tumble.JointSpring(-2.0), ValueError, "spring.hertz: must be > 0"),
        ("break_force", 0.0, ValueError, "break_force: must be > 0"),
        ("break_force", "x", TypeError, "break_force: expected a number"),
        ("enabled", "yes", TypeError, "enabled: expected True or False"),
        ("position", float("nan"), ValueError, "position: must be a finite number"),
        ("armature", -1.0, ValueError, "armature: must be >= 0"),
        ("armature", "x", TypeError, "armature: expected a number"),
    ]
    before = (joint.motor.speed, joint.limits, joint.servo, joint.spring, joint.break_force, joint.position)
    for attr, value, error, message in cases:
        with pytest.raises(error, match=message.replace("(", r"\(").replace(")", r"\)")):
            setattr(joint, attr, value)
    assert before == (joint.motor.speed, joint.limits, joint.servo, joint.spring, joint.break_force, joint.position)
    with pytest.raises(ValueError, match=r"motor: not an option of a ball joint \(its options: cone, twist\)"):
        ball.motor = tumble.Motor(1.0, 1.0)
    assert ball.motor is None
    with pytest.raises(ValueError, match="armature: only hinge and slider joints take one"):
        ball.armature = 0.1
    with pytest.raises(ValueError, match="armature: only hinge and slider joints take one"):
        world.add_joint("ball", ball_body, armature=0.1)


@pytest.mark.parametrize("mass,armature", [(1.0, 0.5), (3.0, 2.0)])
def test_armature_set_on_a_door_slows_its_motor_spin_up_as_the_inertia_says(mass, armature):
    # α = τ / (I + a) with the motor at its cap, from add_joint's keyword and from the
    # setter alike (measured within 1e-5 of the closed form; 1e-3 bounds it).
    for how in ("keyword", "setter"):
        world, slab, hinge, inertia = door(mass)
        if how == "keyword":
            world = tumble.World(gravity=(0, -G, 0), sleep=False)
            slab = world.add_body(tumble.Box((0.5, 1.0, 0.025)), mass=mass, position=(0.5, 1.0, 0))
            hinge = world.add_joint("hinge", slab, anchor=(-0.5, 0, 0), axis=(0, 1, 0), armature=armature)
        else:
            hinge.armature = armature
        assert hinge.armature == armature
        hinge.motor = tumble.Motor(100.0, 1.0)
        for _ in range(30):
            world.step(1 / 60)
        assert hinge.velocity == pytest.approx(0.5 / (inertia + armature), rel=1e-3)


def test_add_joint_takes_a_servo_and_a_scene_file_too(tmp_path):
    # The servo keyword of add_joint and the "servo" key of a scene file are the same
    # option: an arm given one holds 0.5 rad within 0.01 rad.
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    body = world.add_body(tumble.Box((0.5, 0.05, 0.05)), mass=1.0, position=(0.5, 0, 0))
    joint = world.add_joint("hinge", body, anchor=(-0.5, 0, 0), axis=(0, 0, 1), servo=tumble.Servo(0.5, 2000.0, 60.0, 100.0))
    world.simulate(duration=2.0, dt=1 / 60)
    assert joint.position == pytest.approx(0.5, abs=0.01)
    scene = tmp_path / "servo.json"
    scene.write_text(
        '{"gravity": [0, -9.8, 0], "sleep": false, "bodies": [{"name": "arm", "shape": {"type": "box", "half_extents": [0.5, 0.05, 0.05]}, "mass": 1, "position": [0.5, 0, 0]}],'
        ' "joints": [{"type": "hinge", "body": "arm", "anchor": [-0.5, 0, 0], "axis": [0, 0, 1],'
        ' "servo": {"target": 0.5, "stiffness": 2000, "damping": 60, "max_torque": 100}}]}'
    )
    world = tumble.World.from_scene(str(scene))
    (joint,) = world.joints
    assert joint.servo.stiffness == 2000.0
    world.simulate(duration=2.0, dt=1 / 60)
    assert joint.position == pytest.approx(0.5, abs=0.01)
