"""A PD controller balancing 64 cart-poles at once through tumble.Batch.

Every copy starts with its own random push (Batch.randomize); each control step reads the
whole batch's state as arrays, computes the cart force of a linear state feedback (a PD
law on the pole angle plus a weak one on the cart position, gains chosen by hand, no
training) for all copies in one numpy expression, sets it with Batch.apply_forces and
steps every copy together. The same pushes without the controller let every pole fall.
Run: python examples/cartpole_pd_batch.py
"""

import numpy as np

import tumble
from _common import options, plt, save

DT = 0.01
CART_POLE = {
    "gravity": [0, 0, -9.81],
    "dt": DT,
    "sleep": False,
    "bodies": [
        {"name": "cart", "shape": {"type": "box", "half_extents": [0.2, 0.1, 0.05]}, "mass": 1.0},
        {"name": "pole", "shape": {"type": "box", "half_extents": [0.02, 0.02, 0.5]},
         "mass": 0.1, "position": [0, 0, 0.5]},
    ],
    "joints": [
        {"type": "slider", "name": "track", "body": "cart", "axis": [1, 0, 0]},
        {"type": "hinge", "name": "pivot", "body": "pole", "other": "cart",
         "anchor": [0, 0, -0.5], "axis": [0, 1, 0]},
    ],
}
# F = K_THETA θ + K_OMEGA θ̇ + K_X x + K_V ẋ (N), θ > 0 when the pole leans towards +x.
# Leaning towards +x, the cart must run under it (push +x); the cart terms have the same
# sign, as a linear-quadratic regulator's do: to come back to x = 0 the cart first lets
# the pole lean towards the origin, then follows it.
K_THETA, K_OMEGA, K_X, K_V = 40.0, 8.0, 1.0, 2.5


def pole_angles(batch, pole):
    """Each copy's pole angle from the vertical, about the hinge's y axis (rad)."""
    x, y, z, w = np.moveaxis(batch.orientations[:, pole], -1, 0)
    # The pole's own z axis in the world: R e_z, from the quaternion [x, y, z, w].
    up_x = 2 * (x * z + w * y)
    up_z = 1 - 2 * (x * x + y * y)
    return np.arctan2(up_x, up_z)


def run(copies, seconds, control, seed=1):
    batch = tumble.Batch(CART_POLE, copies=copies, threads=2)
    cart, pole = batch.body_index("cart"), batch.body_index("pole")
    batch.randomize(np.random.default_rng(seed), velocities=0.4)
    steps = int(round(seconds / DT))
    angles = np.empty((steps + 1, copies))
    angles[0] = pole_angles(batch, pole)
    forces = np.zeros((copies, 2, 3))
    for k in range(steps):
        theta = angles[k]
        omega = batch.angular_velocities[:, pole, 1]
        x, v = batch.positions[:, cart, 0], batch.velocities[:, cart, 0]
        if control:
            forces[:, cart, 0] = K_THETA * theta + K_OMEGA * omega + K_X * x + K_V * v
            batch.apply_forces(forces)
        batch.step(steps=1)
        angles[k + 1] = pole_angles(batch, pole)
    return angles, batch.positions[:, cart, 0]


def main():
    args = options("cartpole_pd_batch", __doc__)
    copies, seconds = (16, 6.0) if args.quick else (64, 8.0)
    held, carts = run(copies, seconds, control=True)
    fallen, _ = run(copies, seconds, control=False)
    t = np.arange(held.shape[0]) * DT
    # Controlled: every pole upright and still at the end, every cart near the origin.
    print(f"controlled: largest |θ| over the last second {np.abs(held[-100:]).max():.4f} rad, "
          f"carts within {np.abs(carts).max():.3f} m of the origin")
    assert np.abs(held[-100:]).max() < 0.02, np.abs(held[-100:]).max(axis=0)
    assert np.abs(carts).max() < 0.3, carts
    # Uncontrolled, from the same pushes: every pole has fallen past 1 rad.
    assert (np.abs(fallen).max(axis=0) > 1.0).all(), np.abs(fallen).max(axis=0)
    print(f"uncontrolled: every pole past 1 rad within {seconds} s")
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4), sharey=False)
    a.plot(t, held, lw=0.7)
    a.set_title(f"{copies} cart-poles, PD control (tumble.Batch)")
    a.set_xlabel("t (s)")
    a.set_ylabel("pole angle θ (rad)")
    b.plot(t, np.clip(fallen, -np.pi, np.pi), lw=0.7)
    b.set_title("the same pushes, no control")
    b.set_xlabel("t (s)")
    save(fig, args.out)


if __name__ == "__main__":
    main()
