"""Python overhead of tumble, measured (a benchmark, not a test).

1. simulate: 1,000 free spheres stepped 1,000 times (dt = 0.01 s, every frame recorded)
   through `World.simulate`, against the same run through the Rust API
   (crates/tumble/examples/simulate_bodies.rs, built and run here with cargo). Best of 3.
2. step: the cost of one `world.step(0.01)` call on an empty world, against the same step
   in Rust: the difference is the per-call overhead of the binding.

Run from the repository, in the environment scripts/test.sh builds:
    target/venv/bin/python crates/tumble-py/bench/overhead.py
"""

import pathlib
import subprocess
import time
import timeit

import tumble

ROOT = pathlib.Path(__file__).resolve().parents[3]
BODIES, STEPS, REPEATS = 1000, 1000, 3


def python_simulate():
    best = float("inf")
    for _ in range(REPEATS):
        world = tumble.World()
        for i in range(BODIES):
            world.add_body(tumble.Sphere(0.1), mass=1.0, position=(i % 10, (i // 10) % 10, i // 100))
        start = time.perf_counter()
        traj = world.simulate(steps=STEPS, dt=0.01)
        best = min(best, time.perf_counter() - start)
        assert traj.position.shape == (STEPS + 1, BODIES, 3)
    return best


def rust():
    out = subprocess.run(
        ["cargo", "run", "--quiet", "--release", "-p", "tumble", "--example", "simulate_bodies",
         "--", str(BODIES), str(STEPS), str(REPEATS)],
        cwd=ROOT, check=True, capture_output=True, text=True,
    ).stdout
    values = dict(line.split() for line in out.splitlines())
    return float(values["simulate_s"]), float(values["empty_step_us"])


def python_empty_step():
    world = tumble.World()
    step = world.step
    n = 1_000_000
    return min(timeit.repeat(lambda: step(0.01), number=n, repeat=3)) / n * 1e6


def main():
    rust_sim, rust_step = rust()
    py_sim = python_simulate()
    py_step = python_empty_step()
    print(f"simulate {BODIES} bodies x {STEPS} steps: Python {py_sim * 1e3:.1f} ms, "
          f"Rust {rust_sim * 1e3:.1f} ms, Python / Rust = {py_sim / rust_sim:.3f}")
    print(f"empty-world step: Python {py_step:.3f} us per call, Rust {rust_step:.3f} us, "
          f"overhead {py_step - rust_step:.3f} us per call")


if __name__ == "__main__":
    main()
