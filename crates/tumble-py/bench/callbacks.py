"""The cost of Python callbacks per call, measured (a benchmark, not a test).

1. force callbacks: a world of free balls (symplectic Euler: one force evaluation a step)
   stepped with K callbacks added, against the same world with none; the difference over
   steps × K calls is the cost of one call. K is large (50 to 200) so that the calls, not
   the machine's noise on the step, make the difference. Empty callbacks on 1 ball (the
   fixed cost: taking the interpreter, the call, the context opened and closed), on 1,000
   balls (every call copies every body's state), on 300 balls stepping on 2 threads (the
   call made on one of the world's threads); and one that reads a position and adds a
   force, the smallest useful callback.
2. controllers: `simulate(steps=N, controller=fn)` against `simulate(steps=N)`: an empty
   fn on an empty world, and a PD controller that reads a hinge's position and rate and
   sets its motor on a jointed arm.

Each time is the best of 5 runs, the two runs of a pair taken in turn.
Run from the repository, in the environment scripts/test.sh builds:
    target/venv/bin/python crates/tumble-py/bench/callbacks.py
"""

import math
import time

import tumble

REPEATS = 5


def best_of(base, timed):
    """The least time of each of two runs, taken in turn, so that a busy moment of the
    machine falls on both alike."""
    times = ([], [])
    for _ in range(REPEATS):
        for run, out in zip((base, timed), times):
            start = time.perf_counter()
            run()
            out.append(time.perf_counter() - start)
    return min(times[0]), min(times[1])


def balls(n, threads=1):
    # Sleeping off: a resting body falls asleep, and forces on it are not evaluated.
    world = tumble.World(gravity=(0, 0, 0), threads=threads, sleep=False)
    for i in range(n):
        world.add_body(tumble.Sphere(0.1), mass=1.0, position=(i % 20, i // 20, 0))
    return world, world.bodies[0]


def report(label, base, timed, calls, steps):
    per_call = (timed - base) / calls * 1e6
    print(f"{label:56s} {per_call:6.2f} µs per call  (step {base / steps * 1e6:7.2f} µs without)")


def force_cost(label, n, callback, k, steps, threads=1):
    def run(count):
        world, ball = balls(n, threads)
        for _ in range(count):
            world.add_force_callback(callback(ball))
        return lambda: world.step(0.01, steps=steps)

    base, timed = best_of(run(0), run(k))
    report(label, base, timed, k * steps, steps)


def empty(ball):
    return lambda ctx: None


def pull(ball):
    def f(ctx):
        ctx.add_force(ball, -ctx.position(ball))
    return f


def controller_cost(label, world, make, steps):
    controller = make()
    base, timed = best_of(lambda: world.simulate(steps=steps, dt=1 / 240),
                          lambda: world.simulate(steps=steps, dt=1 / 240, controller=controller))
    report(label, base, timed, steps, steps)


def pd():
    world = tumble.World(gravity=(0, -9.8, 0), sleep=False)
    body = world.add_body(tumble.Box((0.5, 0.05, 0.05)), mass=1.0, position=(0.5, 0, 0))
    joint = world.add_joint("hinge", body, anchor=(-0.5, 0, 0), axis=(0, 0, 1))

    def make():
        def control(w, t):
            tau = 40 * (0.5 - joint.position) - 5 * joint.velocity
            joint.motor = tumble.Motor(math.copysign(1e3, tau), abs(tau))
        return control
    return world, make


def main():
    force_cost("force callback, empty, 1 body", 1, empty, 200, 1000)
    force_cost("force callback, position + add_force, 1 body", 1, pull, 200, 1000)
    force_cost("force callback, empty, 1,000 bodies", 1000, empty, 50, 100)
    force_cost("force callback, empty, 300 bodies, 1 thread", 300, empty, 50, 100)
    force_cost("force callback, empty, 300 bodies, 2 threads (pool thread)", 300, empty, 50, 100, 2)
    controller_cost("controller, empty, empty world", tumble.World(), lambda: lambda w, t: None, 50_000)
    world, make = pd()
    controller_cost("controller, PD: joint position and rate, set motor", world, make, 20_000)


if __name__ == "__main__":
    main()
