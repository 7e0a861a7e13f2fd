"""CartPole: a pole hinged on a cart that slides on a rail, kept upright by pushing the cart."""

from __future__ import annotations

import math
from typing import Any, Optional

import tumble

from ._common import TumbleEnv, drive, np, spaces


def _axis_angle_z(angle: float, sign: float = 1.0) -> tuple:
    """The quaternion [x, y, z, w] of a turn by `angle` about sign * z."""
    return (0.0, 0.0, sign * math.sin(angle / 2), math.cos(angle / 2))


class CartPoleEnv(TumbleEnv):
    """The cart-pole of Barto, Sutton and Anderson (1983), simulated by Tumble's joints.

    Mechanism: a 1 kg box cart on a ``slider`` joint to the world along +x, and a 0.1 kg
    uniform pole 1 m long (a thin box, so a half-length of 0.5 m) on a ``hinge`` joint at
    the cart's centre about -z, so that a positive angle tilts the pole towards +x. Gravity
    is 9.8 m/s² along -y. Nothing collides. The push is the slider's motor, saturated at
    10 N (a motor asked for a speed it never reaches pushes with exactly its limit).

    - Action space: ``Discrete(2)``: 0 pushes the cart with 10 N towards -x, 1 towards +x.
    - Observation space: ``Box(4,)`` float32, ``[x, x_dot, theta, theta_dot]``: cart
      position (m) and velocity (m/s) read from the slider, pole angle from upright (rad)
      and its rate (rad/s) read from the hinge. Bounds ±4.8 m, ±0.418 rad (24°), the
      rates unbounded.
    - Step: 0.02 s of simulated time (two Tumble steps of 0.01 s, symplectic Euler, the
      soft-step joint solver with 4 substeps).
    - Reward: +1 for every step, the one that terminates included; 0 after that.
    - Terminated: ``|x| > 2.4`` m or ``|theta| > 12°`` (0.2095 rad).
    - Truncated: after 500 steps (``max_episode_steps`` of the registration).
    - Start: the four state variables drawn uniformly from [-0.05, 0.05] by the seeded
      ``np_random``: ``reset(seed=s)`` twice gives the same trajectory for the same actions.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 50}
    camera = ((0.0, 0.6, 6.0), (0.0, 0.6, 0.0))

    gravity = 9.8
    cart_mass = 1.0
    pole_mass = 0.1
    half_length = 0.5
    force = 10.0
    tau = 0.02
    substeps = 2
    x_limit = 2.4
    theta_limit = 12 * 2 * math.pi / 360

    def __init__(self, render_mode: Optional[str] = None):
        super().__init__(render_mode)
        high = np.array(
            [self.x_limit * 2, np.inf, self.theta_limit * 2, np.inf], dtype=np.float32
        )
        self.observation_space = spaces.Box(-high, high, dtype=np.float32)
        self.action_space = spaces.Discrete(2)
        self._done = False

    def _build(self) -> None:
        w = tumble.World(gravity=(0, -self.gravity, 0), sleep=False)
        self.cart = w.add_body(tumble.Box((0.25, 0.125, 0.15)), mass=self.cart_mass, name="cart")
        self.pole = w.add_body(
            tumble.Box((0.025, self.half_length, 0.025)),
            mass=self.pole_mass,
            position=(0, self.half_length, 0),
            name="pole",
        )
        self.slider = w.add_joint("slider", self.cart, None, axis=(1, 0, 0), name="slider")
        self.hinge = w.add_joint(
            "hinge",
            self.pole,
            self.cart,
            anchor=(0, -self.half_length, 0),
            other_anchor=(0, 0, 0),
            axis=(0, 0, -1),
            other_axis=(0, 0, -1),
            name="hinge",
        )
        self.world = w

    def arrays(self, x: float, x_dot: float, theta: float, theta_dot: float) -> dict:
        """set_state's arrays (cart, pole) for the state (x, x_dot, theta, theta_dot):
        the pole's pose and velocity rigidly consistent with the hinge and the slider."""
        h, s, c = self.half_length, math.sin(theta), math.cos(theta)
        return dict(
            positions=[(x, 0, 0), (x + h * s, h * c, 0)],
            orientations=[(0, 0, 0, 1), _axis_angle_z(theta, -1.0)],
            velocities=[(x_dot, 0, 0), (x_dot + h * c * theta_dot, -h * s * theta_dot, 0)],
            angular_velocities=[(0, 0, 0), (0, 0, -theta_dot)],
        )

    def _pose(self, *state: float) -> None:
        """Places cart and pole at the state (x, x_dot, theta, theta_dot)."""
        self._world().set_state(**self.arrays(*state))

    def _obs(self) -> np.ndarray:
        return np.array(
            [self.slider.position, self.slider.velocity, self.hinge.position, self.hinge.velocity],
            dtype=np.float32,
        )

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None):
        super().reset(seed=seed)
        self._build()
        self._pose(*self.np_random.uniform(-0.05, 0.05, size=4))
        self._done = False
        return self._obs(), {}

    def step(self, action):
        if not self.action_space.contains(action):
            raise ValueError(f"action: must be 0 or 1, got {action!r}")
        w = self._world()
        drive(self.slider, self.force if int(action) == 1 else -self.force)
        w.step(self.tau / self.substeps, steps=self.substeps)
        obs = self._obs()
        x, theta = float(self.slider.position), float(self.hinge.position)
        terminated = abs(x) > self.x_limit or abs(theta) > self.theta_limit
        reward = 0.0 if self._done else 1.0
        self._done = self._done or terminated
        return obs, reward, terminated, False, {}
