"""Physics through Python, against closed forms. Tolerances are justified per test."""

import math

import numpy as np
import pytest

import tumble

G = 9.8


def test_free_fall_velocity_verlet_is_exact():
    # Under constant gravity velocity Verlet integrates x'' = -g exactly: only rounding
    # (~1e-15 relative, over 100 steps) separates it from 5 - g t^2 / 2.
    world = tumble.World(integrator="velocity_verlet")
    world.add_body(tumble.Sphere(0.1), mass=1.0, position=(0, 5, 0))
    traj = world.simulate(duration=1.0, dt=0.01)
    y = traj.position[:, 0, 1]
    np.testing.assert_allclose(y, 5 - 0.5 * G * traj.time**2, rtol=0, atol=1e-12)
    np.testing.assert_allclose(traj.velocity[:, 0, 1], -G * traj.time, rtol=0, atol=1e-12)


def test_free_fall_symplectic_euler_follows_its_own_closed_form():
    # Symplectic Euler updates v first: y_n = y0 - g h^2 n(n+1)/2, an O(h) error of
    # g h t / 2 against the exact curve (the seed's table); both hold to rounding.
    world = tumble.World()
    world.add_body(tumble.Sphere(0.1), mass=1.0, position=(0, 5, 0))
    h = 0.01
    traj = world.simulate(duration=1.0, dt=h)
    n = np.arange(len(traj.time))
    np.testing.assert_allclose(traj.position[:, 0, 1], 5 - G * h * h * n * (n + 1) / 2, atol=1e-12)
    error = (5 - 0.5 * G * traj.time**2) - traj.position[:, 0, 1]
    np.testing.assert_allclose(error, G * h * traj.time / 2, atol=1e-12)


def test_spring_period_and_amplitude():
    # m = 1 kg, k = 100 N/m: omega = 10 rad/s, period 2 pi / 10. RK4's global error is
    # about (omega h)^4 omega t A / 120 = 1e-8 * 20 * 0.1 / 120 < 1e-10 m here; 1e-8 leaves room.
    world = tumble.World(gravity=(0, 0, 0), integrator="rk4")
    ball = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(0.1, 0, 0))
    world.add_spring(ball, world_point=(0, 0, 0), stiffness=100.0)
    traj = world.simulate(duration=2.0, dt=0.001)
    x = traj.position[:, 0, 0]
    np.testing.assert_allclose(x, 0.1 * np.cos(10 * traj.time), atol=1e-8)
    # Upward zero crossings, interpolated: the period to 1e-6 s.
    up = np.where((x[:-1] < 0) & (x[1:] >= 0))[0]
    t = traj.time[up] - x[up] * (traj.time[up + 1] - traj.time[up]) / (x[up + 1] - x[up])
    assert len(t) >= 2
    np.testing.assert_allclose(np.diff(t), 2 * math.pi / 10, atol=1e-6)


def test_spring_energy_velocity_verlet_bounded_explicit_euler_grows():
    # Explicit Euler multiplies the oscillator's energy by 1 + (omega h)^2 each step, so
    # after n steps it is (1 + 0.01)^n times the start; velocity Verlet keeps it within
    # O((omega h)^2) = 1% of the start without drift.
    energies = {}
    for integrator in ("explicit_euler", "velocity_verlet"):
        world = tumble.World(gravity=(0, 0, 0), integrator=integrator)
        ball = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(0.1, 0, 0))
        world.add_spring(ball, world_point=(0, 0, 0), stiffness=100.0)
        traj = world.simulate(duration=1.0, dt=0.01, diagnostics=True)
        energies[integrator] = traj.total
    e0 = 0.5 * 100 * 0.1**2
    np.testing.assert_allclose(energies["explicit_euler"], e0 * 1.01 ** np.arange(101), rtol=1e-9)
    assert np.max(np.abs(energies["velocity_verlet"] / e0 - 1)) < 0.01


def test_torque_free_box_keeps_angular_momentum():
    # A box spun near its intermediate axis tumbles (Dzhanibekov) but its world angular
    # momentum is constant; the default integrator turns bodies with an exact rotor
    # splitting, so L holds to rounding (1e-12 relative) and energy to the 2e-6 the
    # integrator docs measure.
    world = tumble.World(gravity=(0, 0, 0))
    box = world.add_body(tumble.Box((0.5, 0.2, 0.1)), density=1000.0, angular_velocity=(0.01, 6.0, 0.0))
    l0 = box.angular_momentum
    traj = world.simulate(duration=10.0, dt=1 / 240, every=24, diagnostics=True)
    np.testing.assert_allclose(traj.angular_momentum, np.tile(l0, (len(traj.time), 1)), rtol=0, atol=1e-12 * np.linalg.norm(l0))
    e = traj.kinetic
    assert np.max(np.abs(e / e[0] - 1)) < 1e-5
    # It does flip: the body y axis turns over at least once.
    q = traj.orientation[:, 0]
    y_axis_y = 1 - 2 * (q[:, 0] ** 2 + q[:, 2] ** 2)
    assert y_axis_y.min() < -0.9


def test_resting_stack_carries_its_weight():
    # Three 1 kg unit cubes on a ground plane settle and stay: after 2 s none moves faster
    # than 1 cm/s, each sits within 1 cm (twice the 5 mm contact slop) of its stacked height,
    # and the ground's contacts push up with the stack's weight, 3 m g dt per step, to 2%.
    world = tumble.World()
    world.add_body(tumble.Plane((0, 1, 0)), kind="static", name="ground")
    cubes = [world.add_body(tumble.Box((0.5, 0.5, 0.5)), mass=1.0, position=(0, 0.5 + i, 0)) for i in range(3)]
    world.sleep = False
    dt = 1 / 60
    world.simulate(duration=2.0, dt=dt)
    for i, cube in enumerate(cubes):
        assert abs(cube.position[1] - (0.5 + i)) < 0.01
        assert np.linalg.norm(cube.velocity) < 0.01
    ground = world.body("ground")
    push = sum(
        p.normal_impulse
        for c in world.contacts()
        if ground in (c.body_a, c.body_b)
        for p in c.points
    )
    assert push == pytest.approx(3 * G * dt, rel=0.02)



def test_rolling_resistance_and_torsional_friction_closed_forms():
    # A solid ball rolling on level ground with rolling resistance mu_r slows at
    # (5/7) mu_r g (torque mu_r r N against I = 2/5 m r^2 and the rolling constraint) and
    # stops after v^2 / 2a; spinning about the vertical on its point of contact with
    # torsional friction mu_t (m) it slows at mu_t m g / I. The engine meets both within
    # 0.2 % (crates/tumble/tests/rolling_friction.rs); 1 % leaves room. The ground has
    # neither coefficient: a pair uses the larger.
    r, mu_r, mu_t, v0, w0, dt = 0.1, 0.05, 0.002, 2.0, 20.0, 1 / 120
    world = tumble.World()
    world.sleep = False
    world.add_body(tumble.Plane((0, 1, 0)), kind="static", friction=0.8)
    roller = world.add_body(tumble.Sphere(r), mass=1.0, position=(0, r, 0), velocity=(v0, 0, 0),
                            angular_velocity=(0, 0, -v0 / r), friction=0.8, rolling_resistance=mu_r)
    spinner = world.add_body(tumble.Sphere(r), mass=1.0, position=(5, r, 5), angular_velocity=(0, w0, 0),
                             torsional_friction=mu_t)
    assert (roller.rolling_resistance, roller.torsional_friction) == (mu_r, 0.0)
    assert (spinner.rolling_resistance, spinner.torsional_friction) == (0.0, mu_t)
    a = 5 / 7 * mu_r * G
    spin = mu_t * G / (0.4 * r * r)
    t1 = 0.5 * w0 / spin  # 2.04 s: the spinner at half speed
    world.simulate(duration=t1, dt=dt)
    assert spinner.angular_velocity[1] == pytest.approx(w0 - spin * t1, rel=0.01)
    t2 = 0.5 * v0 / a  # 2.86 s: the roller at half speed
    world.simulate(duration=t2 - t1, dt=dt)
    assert roller.velocity[0] == pytest.approx(v0 - a * t2, rel=0.01)
    world.simulate(duration=1.2 * v0 / a - t2, dt=dt)
    assert abs(roller.velocity[0]) < 1e-3
    assert roller.position[0] == pytest.approx(v0 * v0 / (2 * a), rel=0.01)
    assert abs(spinner.angular_velocity[1]) < 1e-3

def test_distance_joint_pendulum_period():
    # A point-like ball on a 1 m rod swinging 0.1 rad: period 2 pi sqrt(L/g) (1 + theta^2/16)
    # to 0.1%; the rod length holds to 1 mm under the joint solver's soft correction.
    world = tumble.World()
    ball = world.add_body(tumble.Sphere(0.01), mass=1.0, position=(math.sin(0.1), -math.cos(0.1), 0))
    world.add_joint("distance", ball, other_anchor=(0, 0, 0), length=1.0)
    traj = world.simulate(duration=4.0, dt=1 / 240)
    r = np.linalg.norm(traj.position[:, 0], axis=1)
    assert np.max(np.abs(r - 1)) < 1e-3
    x = traj.position[:, 0, 0]
    down = np.where((x[:-1] > 0) & (x[1:] <= 0))[0]
    t = traj.time[down] - x[down] * (traj.time[down + 1] - traj.time[down]) / (x[down + 1] - x[down])
    expected = 2 * math.pi * math.sqrt(1 / G) * (1 + 0.1**2 / 16)
    assert np.mean(np.diff(t)) == pytest.approx(expected, rel=1e-3)


def test_hinge_motor_reaches_its_speed():
    # A wheel on a hinge to the world driven at 2 rad/s by a motor strong enough to overcome
    # its inertia within the first steps: its spin about the axis is 2 rad/s to 1%.
    world = tumble.World(gravity=(0, 0, 0))
    wheel = world.add_body(tumble.Cylinder(0.5, 0.1), mass=1.0)
    world.add_joint("hinge", wheel, axis=(0, 1, 0), motor=tumble.Motor(2.0, 100.0))
    world.simulate(duration=1.0, dt=1 / 60)
    assert wheel.angular_velocity[1] == pytest.approx(2.0, rel=0.01)
    assert abs(wheel.angular_velocity[0]) < 1e-6 and abs(wheel.angular_velocity[2]) < 1e-6
