"""Pendulum: swing a rod hinged at one end up and hold it there with a weak torque."""

from __future__ import annotations

import math
from typing import Any, Optional

import tumble

from ._common import Efforts, TumbleEnv, np, spaces, wrap
from .cartpole import _axis_angle_z


class PendulumEnv(TumbleEnv):
    """The inverted-pendulum swing-up, simulated by Tumble's hinge.

    Mechanism: a uniform rod of 1 kg and 1 m (a thin box whose inertia is set to the thin
    rod's, m l²/12 about its centre, so m l²/3 about the pivot) on a ``hinge`` joint to
    the world at its lower end, about +z; gravity 10 m/s² along -y. The torque acts on the
    rod about +z, constant over the step (what a motor at the hinge exerts; applied as a
    body torque, which tumble.Batch takes per world, so the vectorised version is the same).

    - Action space: ``Box(-2, 2, (1,))`` float32, the torque u (N·m, +z), clipped to ±2.
    - Observation space: ``Box(3,)`` float32, ``[cos(theta), sin(theta), theta_dot]``,
      theta the rod's angle from upright (rad, counter-clockwise seen from +z, read from
      the hinge) and theta_dot its rate (rad/s), bounds ±1, ±1, ±8.
    - Step: 0.05 s (five Tumble steps of 0.01 s). After it the rate is clipped to ±8 rad/s
      (the rod's velocities are scaled, which keeps it on the hinge).
    - Reward: ``-(theta² + 0.1 theta_dot² + 0.001 u²)`` with the state before the step
      and theta wrapped into [-pi, pi): at most 0, at least about -16.27.
    - Terminated: never. Truncated: after 200 steps (the registration's limit).
    - Start: theta uniform in [-pi, pi], theta_dot uniform in [-1, 1] (seeded ``np_random``).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}
    camera = ((0.0, 0.0, 4.0), (0.0, 0.0, 0.0))

    gravity = 10.0
    mass = 1.0
    length = 1.0
    max_speed = 8.0
    max_torque = 2.0
    dt = 0.05
    substeps = 5

    def __init__(self, render_mode: Optional[str] = None):
        super().__init__(render_mode)
        high = np.array([1.0, 1.0, self.max_speed], dtype=np.float32)
        self.observation_space = spaces.Box(-high, high, dtype=np.float32)
        self.action_space = spaces.Box(
            -self.max_torque, self.max_torque, shape=(1,), dtype=np.float32
        )

    def _build(self) -> None:
        m, l = self.mass, self.length
        w = tumble.World(gravity=(0, -self.gravity, 0), sleep=False)
        i = m * l * l / 12
        self.rod = w.add_body(
            tumble.Box((0.02, l / 2, 0.02)),
            mass=m,
            inertia=[[i, 0, 0], [0, 1e-4, 0], [0, 0, i]],
            position=(0, l / 2, 0),
            name="rod",
        )
        self.hinge = w.add_joint(
            "hinge",
            self.rod,
            None,
            anchor=(0, -l / 2, 0),
            other_anchor=(0, 0, 0),
            axis=(0, 0, 1),
            other_axis=(0, 0, 1),
            name="hinge",
        )
        self.world = w
        self.efforts = Efforts()

    def arrays(self, theta: float, theta_dot: float) -> dict:
        """set_state's arrays for the rod at (theta, theta_dot), on its hinge."""
        h, s, c = self.length / 2, math.sin(theta), math.cos(theta)
        return dict(
            positions=[(-h * s, h * c, 0)],
            orientations=[_axis_angle_z(theta)],
            velocities=[(-h * c * theta_dot, -h * s * theta_dot, 0)],
            angular_velocities=[(0, 0, theta_dot)],
        )

    def _pose(self, theta: float, theta_dot: float) -> None:
        self._world().set_state(**self.arrays(theta, theta_dot))

    def _state(self) -> tuple:
        return float(self.hinge.position), float(self.hinge.velocity)

    def _obs(self) -> np.ndarray:
        theta, theta_dot = self._state()
        obs = np.array([math.cos(theta), math.sin(theta), theta_dot], dtype=np.float32)
        # The rate is clipped after every step; this only removes rounding past the bound.
        return np.clip(obs, self.observation_space.low, self.observation_space.high)

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None):
        super().reset(seed=seed)
        self._build()
        theta = self.np_random.uniform(-math.pi, math.pi)
        theta_dot = self.np_random.uniform(-1.0, 1.0)
        self._pose(theta, theta_dot)
        return self._obs(), {}

    def step(self, action):
        u = np.asarray(action, dtype=np.float64).reshape(-1)
        if u.shape != (1,) or not np.isfinite(u[0]):
            raise ValueError(f"action: must be one finite torque (shape (1,)), got {action!r}")
        u = float(np.clip(u[0], -self.max_torque, self.max_torque))
        theta, theta_dot = self._state()
        cost = wrap(theta) ** 2 + 0.1 * theta_dot**2 + 0.001 * u**2
        self.efforts.apply(self._world(), [(self.rod, (0.0, 0.0, u))])
        self._world().step(self.dt / self.substeps, steps=self.substeps)
        theta, theta_dot = self._state()
        if abs(theta_dot) > self.max_speed:
            self._pose(theta, math.copysign(self.max_speed, theta_dot))
        return self._obs(), -cost, False, False, {}
