"""Energy of a mass on a spring over time under explicit Euler (grows by 1 + (ωh)² each
step), implicit Euler (decays) and velocity Verlet (oscillates within O((ωh)²) and does
not drift). Run: python examples/spring_energy.py
"""

import numpy as np

import tumble
from _common import options, plt, save


def energy(integrator, duration, dt=0.01):
    world = tumble.World(gravity=(0, 0, 0), integrator=integrator)
    ball = world.add_body(tumble.Sphere(0.05), mass=1.0, position=(0.1, 0, 0))
    world.add_spring(ball, world_point=(0, 0, 0), stiffness=100.0)
    traj = world.simulate(duration=duration, dt=dt, diagnostics=True)
    return traj.time, traj.total


def main():
    args = options("spring_energy", __doc__)
    duration = 2.0 if args.quick else 10.0
    fig, ax = plt.subplots(figsize=(7, 4.5))
    e0 = 0.5 * 100.0 * 0.1**2
    final = {}
    for integrator in ("explicit_euler", "implicit_euler", "velocity_verlet"):
        t, e = energy(integrator, duration)
        ax.plot(t, e / e0, label=integrator)
        final[integrator] = e[-1] / e0
        print(f"{integrator:16s} E(t = {duration:g} s) / E0 = {e[-1] / e0:.4f}")
    assert final["explicit_euler"] > 1.5 and final["implicit_euler"] < 0.7
    assert abs(final["velocity_verlet"] - 1) < 0.01
    ax.set_yscale("log")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("E / E0")
    ax.set_title("Spring, k = 100 N/m, m = 1 kg, dt = 0.01 s")
    ax.legend()
    save(fig, args.out)


if __name__ == "__main__":
    main()
