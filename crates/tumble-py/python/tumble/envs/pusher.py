"""Pusher: a kinematic puck slides a box across a floor with friction to a goal."""

from __future__ import annotations

import math
from typing import Any, Optional

import tumble

from ._common import TumbleEnv, np, spaces


class PusherEnv(TumbleEnv):
    """Planar pushing on a floor with friction: Tumble's contacts do the work.

    Why a pusher: it exercises what Tumble does well, box-on-plane contact with Coulomb
    friction (a box slides, stops and turns by its friction alone), kinematic bodies driven
    by poses (they push with whatever force it takes), with no actuated joint chain.

    Scene: gravity 9.81 m/s² along -y; a static ground plane y = 0; a 1 kg box, 0.2 m a
    side, friction 0.5 (with the ground's 0.5, μ = 0.5); a kinematic upright cylinder (the
    pusher, radius 0.05 m) whose velocity in the floor's x-z plane is the action; a goal
    marker (a flat sensor disc: seen, never touched). The pusher stays inside the arena
    |x|, |z| <= 1 m.

    - Action space: ``Box(-1, 1, (2,))`` float32, the pusher's velocity (vx, vz) in m/s,
      clipped to ±1.
    - Observation space: ``Box(10,)`` float32, ``[pusher x, z, box x, z, cos yaw,
      sin yaw, box vx, vz, goal x, z]`` (m, m/s; yaw the box's turn about +y), unbounded
      but for cos and sin.
    - Step: 0.05 s (five Tumble steps of 0.01 s, the pusher's pose target moved each).
    - Reward: ``-|box - goal| - 0.1 |pusher - box| - 0.01 |action|²`` (distances in the
      floor's plane), plus 10 on the step that reaches the goal.
    - Terminated: the box's centre within 0.05 m of the goal.
    - Truncated: after 200 steps (the registration's limit).
    - Start (seeded ``np_random``): box centre uniform in [-0.3, 0.3]², goal uniform in
      [-0.6, 0.6]² at least 0.3 m from the box, pusher uniform in [-0.8, 0.8]² at least
      0.25 m from the box; everything at rest.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}
    camera = ((0.0, 2.6, 2.2), (0.0, 0.0, 0.0))

    half = 0.1
    radius = 0.05
    arena = 1.0
    dt = 0.05
    substeps = 5
    success = 0.05

    def __init__(self, render_mode: Optional[str] = None):
        super().__init__(render_mode)
        high = np.full(10, np.inf, dtype=np.float32)
        high[4:6] = 1.0
        self.observation_space = spaces.Box(-high, high, dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
        self._pusher = np.zeros(2)
        self._goal = np.zeros(2)

    def _build(self, box: np.ndarray) -> None:
        h = self.half
        w = tumble.World(gravity=(0, -9.81, 0), sleep=False)
        w.add_body(tumble.Plane((0, 1, 0)), kind="static", friction=0.5, name="ground")
        self.box = w.add_body(
            tumble.Box((h, h, h)), mass=1.0, friction=0.5, position=(box[0], h, box[1]), name="box"
        )
        self.pusher = w.add_body(
            tumble.Cylinder(self.radius, h),
            kind="kinematic",
            friction=0.5,
            position=(self._pusher[0], h, self._pusher[1]),
            name="pusher",
        )
        w.add_body(
            tumble.Cylinder(self.success, 0.002),
            kind="static",
            sensor=True,
            position=(self._goal[0], 0.002, self._goal[1]),
            name="goal",
        )
        self.world = w

    def _away(self, centre: np.ndarray, low: float, distance: float) -> np.ndarray:
        while True:
            p = self.np_random.uniform(-low, low, size=2)
            if np.hypot(*(p - centre)) >= distance:
                return p

    def _box(self) -> np.ndarray:
        p = self.box.position
        return np.array([p[0], p[2]])

    def _obs(self) -> np.ndarray:
        x, y, z, w = self.box.orientation
        # The box's x axis turned by its orientation, projected on the floor.
        ax, az = 1 - 2 * (y * y + z * z), 2 * (x * z - w * y)
        n = math.hypot(ax, az) or 1.0
        v = self.box.velocity
        b = self._box()
        return np.array(
            [*self._pusher, *b, ax / n, -az / n, v[0], v[2], *self._goal], dtype=np.float32
        )

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None):
        super().reset(seed=seed)
        box = self.np_random.uniform(-0.3, 0.3, size=2)
        self._goal = self._away(box, 0.6, 0.3)
        self._pusher = self._away(box, 0.8, self.half + self.radius + 0.1)
        self._build(box)
        return self._obs(), {}

    def step(self, action):
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape != (2,) or not np.all(np.isfinite(a)):
            raise ValueError(f"action: must be 2 finite numbers (vx, vz), got {action!r}")
        a = np.clip(a, -1.0, 1.0)
        w = self._world()
        h = self.dt / self.substeps
        for _ in range(self.substeps):
            self._pusher = np.clip(self._pusher + a * h, -self.arena, self.arena)
            self.pusher.set_kinematic_target((self._pusher[0], self.half, self._pusher[1]), (0, 0, 0, 1))
            w.step(h)
        b = self._box()
        to_goal = float(np.hypot(*(b - self._goal)))
        terminated = to_goal < self.success
        reward = -to_goal - 0.1 * float(np.hypot(*(self._pusher - b))) - 0.01 * float(a @ a)
        return self._obs(), reward + (10.0 if terminated else 0.0), terminated, False, {}
