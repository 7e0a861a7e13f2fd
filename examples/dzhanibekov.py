"""The Dzhanibekov effect: a box spun about its intermediate axis flips over and over.
Plotted as the body-frame angular velocity ω_body = R(q)ᵀ ω, from the built-in scene
`dzhanibekov` (20 s at dt = 1/240 s, no gravity). Run: python examples/dzhanibekov.py
"""

import numpy as np

import tumble
from _common import options, plt, save


def body_frame(q, w):
    """Rotate world vectors w (T, 3) into the frames of unit quaternions q (T, 4) [x, y, z, w]."""
    u, s = -q[:, :3], q[:, 3:4]  # the inverse rotation
    t = 2 * np.cross(u, w)
    return w + s * t + np.cross(u, t)


def main():
    args = options("dzhanibekov", __doc__)
    world = tumble.World.from_scene("dzhanibekov")
    traj = world.simulate(duration=8.0 if args.quick else None, every=2)
    omega = body_frame(traj.orientation[:, 0], traj.angular_velocity[:, 0])
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for i, label in enumerate(("ω_x (body)", "ω_y (body)", "ω_z (body)")):
        ax.plot(traj.time, omega[:, i], label=label)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("angular velocity (rad/s)")
    ax.set_title("Dzhanibekov flip: spin about the intermediate axis reverses")
    ax.legend()
    # The spin about the middle axis changes sign: the flip.
    main_axis = np.argmax(np.abs(omega[0]))
    flips = np.count_nonzero(np.diff(np.sign(omega[:, main_axis])) != 0)
    print(f"{flips} sign changes of the spin about body axis {main_axis} in {traj.time[-1]:g} s")
    assert flips >= 1
    save(fig, args.out)


if __name__ == "__main__":
    main()
