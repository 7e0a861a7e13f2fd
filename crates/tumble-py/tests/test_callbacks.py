"""Python callbacks (issue 17, point 7): force callbacks (`World.add_force_callback`) and
controllers (`World.simulate(controller=...)`), against closed forms; exceptions in either
leave the world as it was before the step they stopped."""

import math
import threading
import traceback

import numpy as np
import pytest

import tumble

G = 9.8
EXACT = 1e-5 if tumble.SINGLE_PRECISION else 1e-12


def free_ball(integrator, mass=1.0, position=(0, 0, 0), gravity=(0, 0, 0)):
    world = tumble.World(gravity=gravity, integrator=integrator)
    ball = world.add_body(tumble.Sphere(0.1), mass=mass, position=position, name="ball")
    return world, ball


# --- force callbacks -------------------------------------------------------------------


@pytest.mark.parametrize("integrator", ["velocity_verlet", "rk4", "symplectic_euler"])
@pytest.mark.parametrize("mass,force,dt", [(1.0, 3.0, 0.01), (2.5, -7.0, 1 / 240), (0.2, 0.5, 0.05)])
def test_a_constant_force_callback_gives_half_f_over_m_t_squared(integrator, mass, force, dt):
    # x = ½ (F/m) t² is quadratic in t: velocity Verlet and RK4 integrate it exactly, so
    # only rounding separates them from it (1e-12 m over at most 200 steps of metre-sized
    # numbers). Symplectic Euler updates v first: x_n = a dt² n(n+1)/2, the closed form
    # of its own scheme, ½ a t² + ½ a t dt, to rounding too.
    world, ball = free_ball(integrator, mass)
    world.add_force_callback(lambda ctx: ctx.add_force(ball, (force, 0, 0)))
    traj = world.simulate(duration=2.0, dt=dt)
    t, x, a = traj.time, traj.position[:, 0, 0], force / mass
    exact = 0.5 * a * t**2 + (0.5 * a * t * dt if integrator == "symplectic_euler" else 0)
    np.testing.assert_allclose(x, exact, rtol=0, atol=EXACT * max(1.0, abs(a)) * 10)
    np.testing.assert_allclose(traj.position[:, 0, 1:], 0.0, atol=0)


@pytest.mark.parametrize(
    "integrator,mass,k,dt",
    [("rk4", 1.0, 100.0, 1e-3), ("velocity_verlet", 2.5, 40.0, 2e-3), ("symplectic_euler", 0.5, 200.0, 5e-4)],
)
def test_a_spring_written_as_a_callback_has_the_period_two_pi_root_m_over_k(integrator, mass, k, dt):
    # F = −k x on a free ball: T = 2π √(m/k). The symplectic methods' numerical frequency is
    # (2/dt) asin(ω dt / 2), a period short by (ω dt)²/24 ≤ 4.2e-6 relative here; RK4's error
    # is far smaller; the interpolated zero crossings add less than 1e-8 s. Hence 1e-5.
    world, ball = free_ball(integrator, mass, position=(0.2, 0, 0))

    def spring(ctx):
        ctx.add_force(ball, -k * ctx.position(ball))

    world.add_force_callback(spring)
    period = 2 * math.pi * math.sqrt(mass / k)
    traj = world.simulate(duration=3.2 * period, dt=dt)
    x, t = traj.position[:, 0, 0], traj.time
    up = np.where((x[:-1] < 0) & (x[1:] >= 0))[0]
    crossings = t[up] - x[up] * (t[up + 1] - t[up]) / (x[up + 1] - x[up])
    assert len(crossings) == 3
    np.testing.assert_allclose(np.diff(crossings), period, rtol=1e-5)
    # The amplitude stays the start's: these three keep the oscillator's energy to 1e-4.
    assert abs(x).max() == pytest.approx(0.2, rel=1e-4)


CALLS_PER_STEP = {
    "explicit_euler": 1, "symplectic_euler": 1, "implicit_euler": 1, "verlet": 1,
    "midpoint": 2, "velocity_verlet": 2, "rk4": 4,
}


@pytest.mark.parametrize("integrator", tumble.INTEGRATORS)
def test_a_free_body_calls_back_as_often_as_add_force_callback_says(integrator):
    world, ball = free_ball(integrator)
    times = []
    world.add_force_callback(lambda ctx: times.append(ctx.time))
    world.step(0.01, steps=10)
    n = CALLS_PER_STEP[integrator]
    assert len(times) == 10 * n
    # Every call is at a time within its step.
    for k in range(10):
        assert all(0.01 * k - EXACT <= s <= 0.01 * (k + 1) + EXACT for s in times[k * n : (k + 1) * n])


def test_bodies_in_contact_call_back_once_per_substep():
    world = tumble.World(substeps=6, sleep=False)
    world.add_body(tumble.Plane((0, 1, 0), 0.0), kind="static")
    world.add_body(tumble.Box((0.2, 0.2, 0.2)), mass=1.0, position=(0, 0.2, 0))
    calls = []
    world.add_force_callback(calls.append)
    world.step(1 / 60, steps=5)
    assert len(calls) == 30


def test_the_context_reads_each_body_as_the_world_had_it_before_the_step():
    # Symplectic Euler evaluates once, at the step's start: the context's state is the
    # world's before the step, bit for bit, by handle and by name.
    world = tumble.World(gravity=(0, 0, 0))
    box = world.add_body(
        tumble.Box((0.3, 0.2, 0.1)), mass=2.5, position=(1, 2, 3), orientation=(0, 0, 0.3428, 0.9394),
        velocity=(0.5, -0.25, 2), angular_velocity=(0, 3, 1), center_of_mass=(0.1, 0, 0), name="box",
    )
    world.add_body(tumble.Sphere(0.1), mass=1.0, position=(-4, 0, 0))
    seen = {}

    def look(ctx):
        for body in (box, "box"):
            seen[body if isinstance(body, str) else "handle"] = (
                ctx.time, ctx.position(body), ctx.center_of_mass(body), ctx.orientation(body),
                ctx.velocity(body), ctx.angular_velocity(body), ctx.mass(body),
            )

    world.add_force_callback(look)
    for _ in range(3):
        expected = (world.time, box.position, box.center_of_mass, box.orientation, box.velocity,
                    box.angular_velocity, box.mass)
        world.step(0.01)
        for key in ("handle", "box"):
            for got, want in zip(seen[key], expected):
                np.testing.assert_array_equal(got, want)


def test_a_force_at_a_point_moves_a_body_as_world_add_force_does():
    # The context hands a force at a point to the engine, which turns it into r × F as it
    # does an applied force's: the same sums from zero, so the same bits, step after step
    # of a box spinning about an axis off its centre of mass.
    def run(callback):
        world = tumble.World(gravity=(0, 0, 0), integrator="rk4")
        box = world.add_body(tumble.Box((0.4, 0.1, 0.2)), mass=3.0, center_of_mass=(0.05, 0, 0))
        force, point = (0.0, 2.0, 1.0), (0.4, 0.1, -0.2)
        if callback:
            world.add_force_callback(lambda ctx: ctx.add_force(box, force, point=point))
            world.add_force_callback(lambda ctx: ctx.add_torque(box, (0.3, 0, 0)))
        else:
            world.add_force(box, force=force, point=point, torque=(0.3, 0, 0))
        world.step(0.01, steps=100)
        return np.concatenate([box.position, box.orientation, box.angular_velocity])

    a, b = run(True), run(False)
    assert np.abs(b[7:]).max() > 1.0  # it does spin
    np.testing.assert_array_equal(a, b)


# --- exceptions ----------------------------------------------------------------------


def snapshot(world):
    return (world.time, world.step_count, world.state_hash(), world.positions.tobytes(),
            world.orientations.tobytes(), world.velocities.tobytes(), world.angular_velocities.tobytes())


def busy_world(integrator):
    """A ball on the ground (contact), a pendulum (joint) and a free ball."""
    world = tumble.World(integrator=integrator, sleep=False)
    world.add_body(tumble.Plane((0, 1, 0), 0.0), kind="static")
    world.add_body(tumble.Sphere(0.2), mass=1.0, position=(0, 0.2, 0), velocity=(1, 0, 0))
    bob = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(3, 2, 0), velocity=(0, 0, 1))
    world.add_joint("ball", bob, anchor=(-1, 0, 0), other_anchor=(2, 2, 0))
    world.add_body(tumble.Sphere(0.1), mass=1.0, position=(-3, 5, 0), velocity=(0, 3, 0))
    return world


class Boom(Exception):
    pass


@pytest.mark.parametrize("integrator,fail_at", [("rk4", 5), ("rk4", 7), ("symplectic_euler", 5), ("verlet", 14)])
def test_an_exception_in_a_callback_undoes_the_step_and_is_raised_as_it_was(integrator, fail_at):
    # Calls per step here: the integrator's (1 or 4, the free ball) and the solver's 4
    # substeps plus one (the pendulum touches nothing): the failing call falls in either.
    world, reference = busy_world(integrator), busy_world(integrator)
    calls = []

    def push(ctx):
        calls.append(ctx.time)
        if len(calls) == fail_at:
            raise Boom(f"call {len(calls)}")

    world.add_force_callback(push)
    reference.add_force_callback(lambda ctx: None)
    while True:
        before = snapshot(world)
        try:
            world.step(1 / 60)
        except Boom as e:
            assert str(e) == f"call {fail_at}"
            frames = [f.name for f in traceback.extract_tb(e.__traceback__)]
            assert frames[-1] == "push"
            break
        reference.step(1 / 60)
    assert len(calls) == fail_at  # nothing called after the exception
    assert snapshot(world) == before
    assert snapshot(world) == snapshot(reference)
    for _ in range(30):
        world.step(1 / 60)
        reference.step(1 / 60)
    assert world.state_hash() == reference.state_hash()


def test_an_exception_in_simulate_stops_it_at_the_step_before():
    # RK4 calls back 4 times a step: the 30th call is the 2nd stage of step 8. The world
    # is left after step 7, as a world pushed by the same constant force element is.
    world, ball = free_ball("rk4", gravity=(0, -G, 0))
    calls = []

    def push(ctx):
        calls.append(ctx.time)
        if len(calls) == 30:
            raise KeyError("eighth step")
        ctx.add_force(ball, (1, 0, 0))

    world.add_force_callback(push)
    with pytest.raises(KeyError, match="eighth step"):
        world.simulate(duration=1.0, dt=0.01)
    assert world.step_count == 7 and len(calls) == 30
    expected, b = free_ball("rk4", gravity=(0, -G, 0))
    expected.add_force(b, force=(1, 0, 0))
    expected.step(0.01, steps=7)
    np.testing.assert_allclose(world.positions, expected.positions, rtol=0, atol=EXACT)
    np.testing.assert_allclose(world.velocities, expected.velocities, rtol=0, atol=EXACT)
    assert world.time == expected.time


def test_bad_values_and_misuse_inside_a_callback_stop_the_step_with_their_error():
    other_world, other = free_ball("symplectic_euler")
    cases = [
        (lambda w, b: lambda ctx: ctx.add_force(b, (math.nan, 0, 0)), ValueError,
         r"^force: must be finite numbers$"),
        (lambda w, b: lambda ctx: ctx.add_force(b, (1, 0, 0), point=(2e9, 0, 0)), ValueError,
         r"^point: must be at most 1e9 m in magnitude$"),
        (lambda w, b: lambda ctx: ctx.add_torque(b, (1, 2)), ValueError,
         r"^torque: expected 3 numbers \[x, y, z\], got 2 numbers$"),
        (lambda w, b: lambda ctx: ctx.add_force("nobody", (1, 0, 0)), ValueError,
         r"^body: no body named 'nobody'$"),
        (lambda w, b: lambda ctx: ctx.position(other), ValueError,
         r"^body: this body belongs to another world$"),
        (lambda w, b: lambda ctx: ctx.velocity(3), TypeError,
         r"^body: expected a tumble.Body or a body's name, got int$"),
        (lambda w, b: lambda ctx: b.position, RuntimeError, r"the world is busy"),
        (lambda w, b: lambda ctx: w.step(0.01), RuntimeError, r"the world is busy"),
    ]
    for make, error, message in cases:
        world, ball = free_ball("symplectic_euler", position=(0, 1, 0))
        world.step(0.01)
        world.add_force_callback(lambda ctx: ctx.add_force(ball, (1, 0, 0)))
        world.add_force_callback(make(world, ball))
        before = snapshot(world)
        with pytest.raises(error, match=message):
            world.step(0.01)
        assert snapshot(world) == before
    # A context kept past its call is closed.
    world, ball = free_ball("symplectic_euler")
    kept = []
    world.add_force_callback(kept.append)
    world.step(0.01)
    with pytest.raises(RuntimeError, match=r"^ForceContext: only valid inside the force callback it was passed to$"):
        kept[0].position("ball")
    assert repr(kept[0]) == "<tumble.ForceContext: closed>"
    with pytest.raises(TypeError, match=r"^callback: expected a callable fn\(ctx\), got int$"):
        world.add_force_callback(3)
    assert other_world.step_count == 0


# --- threads ---------------------------------------------------------------------------


def grid(threads, pull):
    """1,200 free balls (a step of fewer than 1,000 bodies stays on the caller's thread)
    pulled towards the origin by a callback."""
    world = tumble.World(gravity=(0, 0, 0), threads=threads, integrator="rk4")
    balls = [world.add_body(tumble.Sphere(0.1), mass=1.0 + i % 3, position=(i % 20, i // 20, 0))
             for i in range(1200)]
    world.add_force_callback(pull(balls))
    return world


def test_callbacks_on_two_threads_give_the_same_bits_and_run_on_the_worlds_thread():
    callers = set()

    def pull(balls):
        def f(ctx):
            callers.add(threading.get_ident())
            for b in balls[::7]:
                ctx.add_force(b, -ctx.position(b))
        return f

    one, two = grid(1, pull), grid(2, pull)
    one.step(0.01, steps=3)
    one.simulate(steps=2, dt=0.01)
    assert callers == {threading.get_ident()}  # one thread: the caller's
    callers.clear()
    two.step(0.01, steps=3)
    two.simulate(steps=2, dt=0.01)
    # With 2 threads the step runs in the world's pool: the callback took the interpreter
    # there, while the caller waited without it (no deadlock).
    assert callers and threading.get_ident() not in callers
    assert one.state_hash() == two.state_hash()


def test_an_exception_on_the_worlds_thread_undoes_the_step_too():
    def pull(balls):
        count = [0]

        def f(ctx):
            count[0] += 1
            if count[0] == 10:
                raise Boom("on a pool thread")
            ctx.add_force(balls[0], (1, 0, 0))
        return f

    world = grid(2, pull)
    world.step(0.01, steps=2)
    before = snapshot(world)
    with pytest.raises(Boom, match="on a pool thread"):
        world.step(0.01)
    assert snapshot(world) == before
    world.step(0.01)
    assert world.step_count == 3


# --- controllers -----------------------------------------------------------------------


def arm(mass):
    """A 1 m arm (0.1 m square section) hinged about z at the origin, along +x."""
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    body = world.add_body(tumble.Box((0.5, 0.05, 0.05)), mass=mass, position=(0.5, 0, 0))
    joint = world.add_joint("hinge", body, anchor=(-0.5, 0, 0), axis=(0, 0, 1))
    return world, body, joint, mass * (1.01 / 12 + 0.25)


def torque_motor(torque):
    """A motor that gives exactly `torque` (its cap) by chasing a speed it never reaches."""
    return tumble.Motor(math.copysign(1e3, torque), abs(torque))


@pytest.mark.parametrize("mass,kp,target,dt", [(1.0, 40.0, 0.5, 1 / 240), (4.0, 200.0, 1.0, 1 / 120), (2.0, 60.0, -0.3, 1 / 240)])
def test_a_pd_controller_through_a_motor_holds_the_arm_where_its_torque_meets_gravity(mass, kp, target, dt):
    # τ = kp (θ* − θ) − kd θ̇, set as the motor's torque before every step. At rest it
    # balances gravity's m g (l/2) cos θ: kp (θ* − θ) = ½ m g cos θ, solved by Newton's
    # method here; gravity's sag (0.06 to 0.15 rad) is what is measured. Damped at
    # ζ = 0.7 the arm settles well within the 4 s run (the last 0.5 s move it < 1e-8 rad).
    # The brief's bound is 0.01 rad; it lands within 2e-3: at rest the joint's rate reads
    # −½ h α_g rather than 0 (a jointed body's kick is split around the drift, so the rate
    # after a step holds half the next substep's gravity kick, h = dt/4), which the kd
    # term turns into kd ½ h α_g / kp ≈ 1e-3 rad (measured 0.95e-3 to 1.1e-3).
    world, body, joint, inertia = arm(mass)
    kd = 2 * 0.7 * math.sqrt(kp * inertia)
    angles = []

    def control(w, t):
        assert w is world
        angles.append(joint.position)
        joint.motor = torque_motor(kp * (target - joint.position) - kd * joint.velocity)

    world.simulate(duration=4.0, dt=dt, controller=control)
    theta = target
    for _ in range(50):
        f = kp * (target - theta) - 0.5 * mass * G * math.cos(theta)
        theta -= f / (-kp + 0.5 * mass * G * math.sin(theta))
    assert abs(target - theta) > 0.05
    assert abs(joint.position - theta) < 2e-3
    last = angles[-int(0.5 / dt) :]
    assert max(last) - min(last) < 1e-8
    c = body.position
    assert math.atan2(c[1], c[0]) == pytest.approx(joint.position, abs=1e-3)


@pytest.mark.parametrize("mass,torque,switch,dt", [(1.0, 2.0, 0.8, 0.01), (3.0, 12.0, 0.5, 0.01), (2.0, 3.0, 0.7, 1 / 240)])
def test_a_controller_that_reads_the_time_reverses_a_motor(mass, torque, switch, dt):
    # A door hinged about y, gravity along the hinge: the motor alone turns it. At +1 rad/s
    # until the first step that starts at t ≥ switch (t_s), then −1 rad/s, each at most
    # `torque`: α = τ/I. Continuously, the ramp up lags the ideal by 1/(2α) rad and the
    # reversal (2/α s at −α) gains 2/α: θ(T) = t_s − (T − t_s) + 1.5/α. The solver's
    # substeps (h = dt/4) change the rate before they drift, as symplectic Euler does, so
    # a ramp by Δv leads that by ½ h Δv: −½ h over the two. What is left is the substep
    # in which a ramp ends, within α h² (measured 3.4e-6 rad at most); the rate ends at −1
    # within the hinge's soft lock's give (6e-6 measured).
    world = tumble.World(gravity=(0, -G, 0), sleep=False)
    slab = world.add_body(tumble.Box((0.5, 1.0, 0.025)), mass=mass, position=(0.5, 1.0, 0))
    hinge = world.add_joint("hinge", slab, anchor=(-0.5, 0, 0), axis=(0, 1, 0))
    alpha, h = torque / (mass * (1.0 + 0.05**2) / 12 + mass * 0.25), dt / 4
    times, switched = [], []

    def control(w, t):
        times.append(t)
        speed = 1.0 if t < switch else -1.0
        if speed < 0 and not switched:
            switched.append(t)
        hinge.motor = tumble.Motor(speed, torque)

    traj = world.simulate(duration=2.0, dt=dt, controller=control)
    # Called once before every step, with the time that step starts from.
    np.testing.assert_allclose(times, traj.time[:-1], rtol=0, atol=1e-12)
    t_s, end = switched[0], traj.time[-1]
    expected = t_s - (end - t_s) + 1.5 / alpha - 0.5 * h
    assert hinge.position == pytest.approx(expected, abs=alpha * h * h)
    assert hinge.velocity == pytest.approx(-1.0, abs=2e-5)


def test_an_exception_in_a_controller_stops_simulate_before_that_step():
    world, ball = free_ball("velocity_verlet", gravity=(0, -G, 0))
    seen = []

    def control(w, t):
        seen.append(snapshot(w))
        if len(seen) == 6:
            raise Boom("sixth")

    with pytest.raises(Boom, match="sixth") as info:
        world.simulate(duration=1.0, dt=0.01, controller=control)
    assert info.traceback[-1].name == "control"
    assert world.step_count == 5
    assert snapshot(world) == seen[-1]
    world.simulate(steps=3, dt=0.01, controller=lambda w, t: None)
    assert world.step_count == 8


def test_a_controller_with_a_force_callback_that_raises_leaves_the_step_undone():
    world, ball = free_ball("rk4")
    before = []
    world.add_force_callback(lambda ctx: 1 / 0 if ctx.time > 0.042 else None)
    with pytest.raises(ZeroDivisionError):
        world.simulate(duration=1.0, dt=0.01, controller=lambda w, t: before.append(snapshot(w)))
    # Step 5 (t 0.04 → 0.05) evaluates at 0.04, 0.045 (twice) and 0.05: its 2nd raised.
    assert world.step_count == 4
    assert snapshot(world) == before[-1]


def test_a_controller_may_not_change_which_bodies_there_are():
    world, ball = free_ball("rk4")

    def grow(w, t):
        if t > 0.02:
            w.add_body(tumble.Sphere(0.1))

    with pytest.raises(ValueError, match=r"^controller: added or removed a body; simulate records a fixed set of bodies$"):
        world.simulate(duration=1.0, dt=0.01, controller=grow)
    with pytest.raises(TypeError, match=r"^controller: expected a callable fn\(world, t\), got str$"):
        world.simulate(duration=1.0, controller="pd")


def test_a_world_asleep_calls_no_callback_and_adding_one_wakes_it():
    # Forces on a sleeping body are not evaluated (add_force_callback's docstring): a ball
    # resting on the ground falls asleep and the calls stop; a new callback wakes it.
    world = tumble.World()
    world.add_body(tumble.Plane((0, 1, 0), 0.0), kind="static")
    ball = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(0, 0.1, 0))
    calls = []
    world.add_force_callback(calls.append)
    world.step(1 / 60, steps=300)
    assert not ball.awake
    n = len(calls)
    world.step(1 / 60, steps=10)
    assert len(calls) == n
    world.add_force_callback(lambda ctx: ctx.add_force(ball, (0, 20, 0)))
    assert ball.awake
    world.step(1 / 60, steps=10)
    assert len(calls) - n >= 10  # at least once a step again
    assert ball.position[1] > 0.1


def test_a_world_whose_callback_holds_its_body_is_collected():
    # callback -> Body (or Joint) -> World -> the engine's closure -> callback: a cycle,
    # which the garbage collector must see through (the handles, the world and the
    # context report their references) or every such world would live until the
    # interpreter exits. A token held by the callbacks tells whether they were freed.
    import gc
    import weakref

    class Token:
        pass

    def build(integrator, token, held):
        world, ball = free_ball(integrator)
        hinge = world.add_joint("ball", ball, anchor=(-1, 0, 0))
        if held == "body":
            world.add_force_callback(lambda ctx: token and ctx.add_force(ball, (1, 0, 0)))
        else:
            world.add_force_callback(lambda ctx: token and hinge and None)
        world.simulate(steps=3, dt=0.01, controller=lambda w, t: None)

    refs = []
    for integrator, held in (("rk4", "body"), ("symplectic_euler", "joint")):
        token = Token()
        refs.append(weakref.ref(token))
        build(integrator, token, held)
        del token
    gc.collect()
    assert [r() for r in refs] == [None, None]
