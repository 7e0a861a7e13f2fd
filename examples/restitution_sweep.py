"""A restitution sweep with tumble.sweep: a ball dropped 1 m onto the ground rebounds to e² m.

Every (restitution, dt) pair is one run, on a local Ray cluster when ray is installed
(pip install 'tumble[sweep]'), else one after another; the table comes back in the grid's
order either way. Each run stops just after the first bounce and its metric is the height
the ball will reach, (y - r) + v²/2g (free flight from there on). Run:
python examples/restitution_sweep.py
"""

import time

import numpy as np

import tumble
from _common import options, plt, save

G, R, DROP = 9.8, 0.1, 1.0
SCENE = {
    "gravity": [0, -G, 0],
    "bodies": [
        {"name": "ground", "kind": "static", "shape": {"type": "plane", "normal": [0, 1, 0]}},
        {"name": "ball", "shape": {"type": "sphere", "radius": R}, "mass": 1.0,
         "position": [0, R + DROP, 0]},
    ],
}


def rebound(world):
    """The apex the ball is heading for (m above the ground), from its state now."""
    ball = world.body("ball")
    y, vy = float(ball.position[1]), float(ball.velocity[1])
    return {"rebound": (y - R) + max(vy, 0.0) ** 2 / (2 * G), "vy": vy}


def main():
    args = options("restitution_sweep", __doc__)
    try:
        import ray  # noqa: F401
    except ImportError:
        ray = None
    serial = args.quick or ray is None  # the tests' quick run stays in this process
    e = np.linspace(0.0, 1.0, 6 if args.quick else 11).round(2).tolist()
    grid = {"bodies[ball].restitution": e, "dt": [0.01, 0.002]}
    fall = np.sqrt(2 * DROP / G)  # 0.452 s to the ground
    t0 = time.perf_counter()
    table = tumble.sweep(SCENE, grid, rebound, duration=fall + 0.03,
                         address="local-serial" if serial else None, progress=not args.quick)
    print(f"{len(e) * 2} runs in {time.perf_counter() - t0:.2f} s ({'serial' if serial else 'Ray'})")
    rows = table.to_dict("records") if hasattr(table, "to_dict") else table
    assert all(r["error"] is None or r["error"] != r["error"] for r in rows), rows  # no failures
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ee = np.linspace(0, 1, 101)
    ax.plot(ee, DROP * ee**2, "k-", label="e² × 1 m")
    for dt, marker in [(0.01, "o"), (0.002, "x")]:
        got = [(r["bodies[ball].restitution"], r["rebound"]) for r in rows if r["dt"] == dt]
        x, h = np.array(got).T
        ax.plot(x, h, marker, label=f"Tumble, dt = {dt} s")
        # Within 2 cm + 4 %: the contact's slop (5 mm) and the soft contact's give, and
        # a bounce resolved within one step (dt = 0.01 s: up to 10 cm/s of fall speed).
        assert np.all(np.abs(h - DROP * x**2) < 0.02 + 0.04 * x**2), (dt, x, h)
        print(f"dt = {dt}: rebound heights {np.round(h, 3).tolist()} for e = {x.tolist()}")
    ax.set_xlabel("restitution e")
    ax.set_ylabel("rebound height (m)")
    ax.set_title("Ball dropped from 1 m: rebound against e² (tumble.sweep)")
    ax.legend()
    save(fig, args.out)


if __name__ == "__main__":
    main()
