"""Acrobot: a two-link chain hanging from a fixed hinge, swung up by a torque at the elbow."""

from __future__ import annotations

import math
from typing import Any, Optional

import tumble

from ._common import Efforts, TumbleEnv, np, spaces, wrap
from .cartpole import _axis_angle_z


class AcrobotEnv(TumbleEnv):
    """Sutton's acrobot (the book's dynamics), simulated by Tumble's hinges.

    Mechanism: two links of 1 kg and 1 m, centres of mass at their middles, each with a
    moment of inertia of 1 kg·m² about its centre for turns in the plane (as in the
    classic task; set through ``inertia``). The upper link hangs on a ``hinge``
    ("shoulder") to the world at the origin, the lower on a ``hinge`` ("elbow") at the
    upper link's end, both about +z; gravity 9.8 m/s² along -y. Only the elbow is driven:
    its torque turns the lower link by +torque and the upper by -torque about +z (what a
    motor at the elbow exerts; applied as body torques, which tumble.Batch takes per world,
    so the vectorised version is the same).

    - Action space: ``Discrete(3)``: elbow torque -1, 0 or +1 N·m.
    - Observation space: ``Box(6,)`` float32, ``[cos t1, sin t1, cos t2, sin t2, t1_dot,
      t2_dot]``: t1 the upper link's angle from hanging straight down, t2 the lower
      link's angle relative to the upper (rad, counter-clockwise seen from +z, read from
      the hinges), and their rates, bounded by ±4 pi and ±9 pi rad/s.
    - Step: 0.2 s (twenty Tumble steps of 0.01 s); after it the rates are clipped to
      those bounds (the links' velocities set accordingly).
    - Reward: -1 for every step that does not reach the goal, 0 for the one that does.
    - Terminated: the tip is more than one link length above the shoulder,
      ``-cos(t1) - cos(t1 + t2) > 1``.
    - Truncated: after 500 steps (the registration's limit).
    - Start: t1, t2, t1_dot, t2_dot each uniform in [-0.1, 0.1] (seeded ``np_random``).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 5}
    camera = ((0.0, 0.0, 7.0), (0.0, 0.0, 0.0))

    gravity = 9.8
    length = 1.0
    mass = 1.0
    moment = 1.0
    max_rates = (4 * math.pi, 9 * math.pi)
    torques = (-1.0, 0.0, 1.0)
    dt = 0.2
    substeps = 20

    def __init__(self, render_mode: Optional[str] = None):
        super().__init__(render_mode)
        high = np.array([1, 1, 1, 1, *self.max_rates], dtype=np.float32)
        self.observation_space = spaces.Box(-high, high, dtype=np.float32)
        self.action_space = spaces.Discrete(3)

    def _link(self, w: tumble.World, y: float, name: str) -> tumble.Body:
        i = self.moment
        return w.add_body(
            tumble.Box((0.03, self.length / 2, 0.03)),
            mass=self.mass,
            inertia=[[i, 0, 0], [0, 0.01, 0], [0, 0, i]],
            position=(0, y, 0),
            name=name,
        )

    def _build(self) -> None:
        l = self.length
        w = tumble.World(gravity=(0, -self.gravity, 0), sleep=False)
        self.upper = self._link(w, -l / 2, "upper")
        self.lower = self._link(w, -1.5 * l, "lower")
        z = (0, 0, 1)
        self.shoulder = w.add_joint(
            "hinge", self.upper, None, anchor=(0, l / 2, 0), other_anchor=(0, 0, 0),
            axis=z, other_axis=z, name="shoulder",
        )
        self.elbow = w.add_joint(
            "hinge", self.lower, self.upper, anchor=(0, l / 2, 0), other_anchor=(0, -l / 2, 0),
            axis=z, other_axis=z, name="elbow",
        )
        self.world = w
        self.efforts = Efforts()

    def arrays(self, t1: float, t2: float, r1: float, r2: float) -> dict:
        """set_state's arrays for both links at angles (t1, t2) and rates (r1, r2)."""
        l, a = self.length, t1 + t2
        d1 = (math.sin(t1) * l, -math.cos(t1) * l)
        d2 = (math.sin(a) * l, -math.cos(a) * l)
        c1 = (d1[0] / 2, d1[1] / 2, 0)
        c2 = (d1[0] + d2[0] / 2, d1[1] + d2[1] / 2, 0)
        w1, w2 = r1, r1 + r2
        v1 = (-w1 * c1[1], w1 * c1[0], 0)  # (w z) x c1
        v2 = (-w1 * d1[1] - w2 * d2[1] / 2, w1 * d1[0] + w2 * d2[0] / 2, 0)
        return dict(
            positions=[c1, c2],
            orientations=[_axis_angle_z(t1), _axis_angle_z(a)],
            velocities=[v1, v2],
            angular_velocities=[(0, 0, w1), (0, 0, w2)],
        )

    def _pose(self, t1: float, t2: float, r1: float, r2: float) -> None:
        """Places both links at angles (t1, t2) and rates (r1, r2), on their hinges."""
        self._world().set_state(**self.arrays(t1, t2, r1, r2))

    def _state(self) -> tuple:
        s, e = self.shoulder, self.elbow
        return float(s.position), float(e.position), float(s.velocity), float(e.velocity)

    def _obs(self) -> np.ndarray:
        t1, t2, r1, r2 = self._state()
        obs = np.array(
            [math.cos(t1), math.sin(t1), math.cos(t2), math.sin(t2), r1, r2], dtype=np.float32
        )
        # The rates are clipped after every step; this only removes rounding past the bound.
        return np.clip(obs, self.observation_space.low, self.observation_space.high)

    def _reached(self) -> bool:
        t1, t2, _, _ = self._state()
        return bool(-math.cos(t1) - math.cos(t1 + t2) > 1.0)

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None):
        super().reset(seed=seed)
        self._build()
        self._pose(*self.np_random.uniform(-0.1, 0.1, size=4))
        return self._obs(), {}

    def step(self, action):
        if not self.action_space.contains(action):
            raise ValueError(f"action: must be 0, 1 or 2, got {action!r}")
        torque = self.torques[int(action)]
        z = (0.0, 0.0, torque)
        self.efforts.apply(self._world(), [(self.upper, (0.0, 0.0, -torque)), (self.lower, z)])
        self._world().step(self.dt / self.substeps, steps=self.substeps)
        t1, t2, r1, r2 = self._state()
        c1 = float(np.clip(r1, -self.max_rates[0], self.max_rates[0]))
        c2 = float(np.clip(r2, -self.max_rates[1], self.max_rates[1]))
        if (c1, c2) != (r1, r2):
            self._pose(wrap(t1), wrap(t2), c1, c2)
        terminated = self._reached()
        return self._obs(), (0.0 if terminated else -1.0), terminated, False, {}
