"""Order of accuracy of the seven integrators, made visible: the error of a harmonic
oscillator's position after 1 s against dt on log-log axes. A method of order p draws a
line of slope p (explicit, symplectic and implicit Euler 1; midpoint, Störmer–Verlet and
velocity Verlet 2; RK4 4). Run: python examples/integrator_order.py
"""

import math

import numpy as np

import tumble
from _common import options, plt, save

K, M, A, T = 100.0, 1.0, 0.1, 1.0  # omega = 10 rad/s
OMEGA = math.sqrt(K / M)
EXPECTED = {
    "explicit_euler": 1,
    "symplectic_euler": 1,
    "implicit_euler": 1,
    "midpoint": 2,
    "rk4": 4,
    "verlet": 2,
    "velocity_verlet": 2,
}


def error(integrator, dt):
    world = tumble.World(gravity=(0, 0, 0), integrator=integrator)
    ball = world.add_body(tumble.Sphere(0.05), mass=M, position=(A, 0, 0))
    world.add_spring(ball, world_point=(0, 0, 0), stiffness=K)
    world.simulate(duration=T, dt=dt)
    return abs(ball.position[0] - A * math.cos(OMEGA * T))


def main():
    args = options("integrator_order", __doc__)
    dts = 0.01 / 2.0 ** np.arange(4 if args.quick else 6)
    fig, ax = plt.subplots(figsize=(7, 5.5))
    for integrator in tumble.INTEGRATORS:
        errors = np.array([error(integrator, dt) for dt in dts])
        slope = np.polyfit(np.log(dts), np.log(errors), 1)[0]
        ax.loglog(dts, errors, "o-", label=f"{integrator} (slope {slope:.2f})")
        print(f"{integrator:17s} measured order {slope:.2f}, expected {EXPECTED[integrator]}")
        assert abs(slope - EXPECTED[integrator]) < 0.25, (integrator, slope)
    ax.set_xlabel("dt (s)")
    ax.set_ylabel("|x(1 s) − A cos ωt| (m)")
    ax.set_title("Global error against step: spring, ω = 10 rad/s")
    ax.legend(fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    save(fig, args.out)


if __name__ == "__main__":
    main()
