"""Vectorised CartPole, Pendulum and Acrobot: W copies stepped together in one ``tumble.Batch``.

``gym.make_vec("tumble/CartPole-v0", num_envs=W, vectorization_mode="vector_entry_point")``
(or ``CartPoleVectorEnv(num_envs=W, threads=2)``). Each copy is the single environment's
mechanism, built by the single environment and copied W times; the state is read from the
batch's (W, N, ...) arrays and the bodies' poses, the actions go in as arrays. Episodes that
end are reset on the next ``step`` (Gymnasium's NEXT_STEP autoreset): that step returns the
new episode's first observation with reward 0.

CartPole's push is its slider's motor, as in the single environment (the batch sets each
world's motor speed to ±FAR); Pendulum's and Acrobot's torques are body torques
(``Batch.apply_forces``; the elbow's an equal and opposite pair on the two links), as in
the single environments. The Pusher
has no vectorised version (its pusher is moved by kinematic targets, which a Batch does
not take per world).
"""

from __future__ import annotations

import math
from typing import Any, Optional

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

import tumble

from . import ENVS
from ._common import FAR
from .acrobot import AcrobotEnv
from .cartpole import CartPoleEnv
from .pendulum import PendulumEnv


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2 * np.pi) - np.pi


def _angle_z(q: np.ndarray) -> np.ndarray:
    """The turn about +z (rad) of quaternions (..., 4) [x, y, z, w] that turn about z only."""
    return _wrap(2 * np.arctan2(q[..., 2], q[..., 3]))


class _BatchVectorEnv(VectorEnv):
    """W copies of `single` (a TumbleEnv class) in one tumble.Batch."""

    single: type = CartPoleEnv
    env_id = ""

    def __init__(
        self,
        num_envs: int = 1,
        *,
        threads: Optional[int] = None,
        max_episode_steps: Optional[int] = None,
        **kwargs: Any,
    ):
        if not hasattr(tumble, "Batch"):
            raise ImportError("tumble.envs.vector needs tumble.Batch (issue 20, batched worlds)")
        if isinstance(num_envs, bool) or not isinstance(num_envs, int) or num_envs < 1:
            raise ValueError(f"num_envs: must be a whole number >= 1, got {num_envs!r}")
        self.num_envs = num_envs
        self.template = self.single()
        self.template.reset(seed=0)
        self._prepare()
        self.batch = tumble.Batch(self.template.world, copies=num_envs, threads=threads)
        self.single_observation_space = self.template.observation_space
        self.single_action_space = self.template.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}
        self.render_mode = None
        self.max_episode_steps = max_episode_steps or ENVS[self.env_id][2]
        self._steps = np.zeros(num_envs, dtype=np.int64)
        self._ended = np.zeros(num_envs, dtype=bool)

    # What each task defines.
    def _prepare(self) -> None:
        """Readies the template world before it is copied (motors)."""

    def _draw(self) -> list:
        """One start state for the template's `arrays`, from self.np_random."""
        raise NotImplementedError

    def _act(self, actions: np.ndarray) -> None:
        raise NotImplementedError

    def _state(self) -> np.ndarray:
        """(W, k) of the task's state variables, from the batch's arrays."""
        raise NotImplementedError

    def _finish(self, state: np.ndarray, actions: np.ndarray, before: np.ndarray) -> tuple:
        """(observations, rewards, terminated) after a step."""
        raise NotImplementedError

    # The loop.
    def _set(self, worlds: np.ndarray, states: list) -> None:
        """Resets `worlds` to the start states `states` (one list per world)."""
        if len(worlds) == 0:
            return
        arrays = [self.template.arrays(*s) for s in states]
        stacked = {k: np.array([a[k] for a in arrays], dtype=float) for k in arrays[0]}
        self.batch.reset(worlds=[int(i) for i in worlds], **stacked)

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None):
        super().reset(seed=seed)
        everyone = np.arange(self.num_envs)
        self._set(everyone, [self._draw() for _ in everyone])
        self._steps[:] = 0
        self._ended[:] = False
        obs, _, _ = self._finish(self._state(), None, self._state())
        return obs, {}

    def step(self, actions):
        actions = np.asarray(actions)
        if not self.action_space.contains(actions.astype(self.action_space.dtype)):
            raise ValueError(f"actions: must be in {self.action_space}, got {actions!r}")
        before = self._state()
        self._act(actions)
        t = self.template
        interval = t.tau if isinstance(t, CartPoleEnv) else t.dt  # one environment step (s)
        self.batch.step(interval / t.substeps, steps=t.substeps)
        obs, rewards, terminated = self._finish(self._state(), actions, before)
        self._steps += 1
        truncated = self._steps >= self.max_episode_steps
        restart = np.flatnonzero(self._ended)
        if len(restart):
            self._set(restart, [self._draw() for _ in restart])
            self._steps[restart] = 0
            fresh, _, _ = self._finish(self._state(), None, self._state())
            obs[restart] = fresh[restart]
            rewards[restart] = 0.0
            terminated[restart] = False
            truncated[restart] = False
        self._ended = terminated | truncated
        return obs, rewards.astype(np.float64), terminated, truncated, {}


class CartPoleVectorEnv(_BatchVectorEnv):
    """W cart-poles (see CartPoleEnv) in one tumble.Batch."""

    single = CartPoleEnv
    env_id = "tumble/CartPole-v0"

    def _prepare(self) -> None:
        self.template.slider.motor = tumble.Motor(FAR, self.template.force)

    def _draw(self) -> list:
        return list(self.np_random.uniform(-0.05, 0.05, size=4))

    def _act(self, actions: np.ndarray) -> None:
        self.batch.set_joint_targets("slider", np.where(actions == 1, FAR, -FAR), kind="velocity")

    def _state(self) -> np.ndarray:
        p, v = self.batch.positions, self.batch.velocities
        q, w = self.batch.orientations, self.batch.angular_velocities
        # The pole turns about -z (a positive angle leans it towards +x).
        return np.stack([p[:, 0, 0], v[:, 0, 0], -_angle_z(q[:, 1]), -w[:, 1, 2]], axis=1)

    def _finish(self, state, actions, before):
        t = self.template
        terminated = (np.abs(state[:, 0]) > t.x_limit) | (np.abs(state[:, 2]) > t.theta_limit)
        rewards = np.where(self._ended, 0.0, 1.0)
        return state.astype(np.float32), rewards, terminated


class PendulumVectorEnv(_BatchVectorEnv):
    """W pendulums (see PendulumEnv) in one tumble.Batch."""

    single = PendulumEnv
    env_id = "tumble/Pendulum-v0"

    def _draw(self) -> list:
        return [self.np_random.uniform(-math.pi, math.pi), self.np_random.uniform(-1.0, 1.0)]

    def _act(self, actions: np.ndarray) -> None:
        u = np.clip(actions.reshape(self.num_envs).astype(float), -2.0, 2.0)
        torques = np.zeros((self.num_envs, 1, 3))
        torques[:, 0, 2] = u
        self.batch.apply_forces(np.zeros_like(torques), torques)

    def _state(self) -> np.ndarray:
        q, w = self.batch.orientations, self.batch.angular_velocities
        return np.stack([_angle_z(q[:, 0]), w[:, 0, 2]], axis=1)

    def _finish(self, state, actions, before):
        t = self.template
        fast = np.abs(state[:, 1]) > t.max_speed
        if actions is not None and fast.any():
            clipped = np.clip(state[:, 1], -t.max_speed, t.max_speed)
            self._rewrite(np.flatnonzero(fast), [[state[i, 0], clipped[i]] for i in np.flatnonzero(fast)])
            state = self._state()
        obs = np.stack([np.cos(state[:, 0]), np.sin(state[:, 0]), state[:, 1]], axis=1)
        rewards = np.zeros(self.num_envs)
        if actions is not None:
            u = np.clip(actions.reshape(self.num_envs).astype(float), -2.0, 2.0)
            rewards = -(before[:, 0] ** 2 + 0.1 * before[:, 1] ** 2 + 0.001 * u**2)
        high = self.single_observation_space.high
        return np.clip(obs, -high, high).astype(np.float32), rewards, np.zeros(self.num_envs, bool)

    def _rewrite(self, worlds: np.ndarray, states: list) -> None:
        """Sets the state of `worlds` (keeping their time) from the task's variables."""
        arrays = [self.template.arrays(*s) for s in states]
        for name in ("positions", "orientations", "velocities", "angular_velocities"):
            whole = getattr(self.batch, name)
            for i, a in zip(worlds, arrays):
                whole[i] = np.asarray(a[name], dtype=float)
            setattr(self.batch, name, whole)


class AcrobotVectorEnv(_BatchVectorEnv):
    """W acrobots (see AcrobotEnv) in one tumble.Batch."""

    single = AcrobotEnv
    env_id = "tumble/Acrobot-v0"
    _rewrite = PendulumVectorEnv._rewrite

    def _draw(self) -> list:
        return list(self.np_random.uniform(-0.1, 0.1, size=4))

    def _act(self, actions: np.ndarray) -> None:
        tau = np.asarray(self.template.torques)[actions.astype(int)]
        torques = np.zeros((self.num_envs, 2, 3))
        torques[:, 0, 2] = -tau  # the elbow turns the links against each other
        torques[:, 1, 2] = tau
        self.batch.apply_forces(np.zeros_like(torques), torques)

    def _state(self) -> np.ndarray:
        q, w = self.batch.orientations, self.batch.angular_velocities
        a1, a2 = _angle_z(q[:, 0]), _angle_z(q[:, 1])
        return np.stack([a1, _wrap(a2 - a1), w[:, 0, 2], w[:, 1, 2] - w[:, 0, 2]], axis=1)

    def _finish(self, state, actions, before):
        r1max, r2max = self.template.max_rates
        fast = (np.abs(state[:, 2]) > r1max) | (np.abs(state[:, 3]) > r2max)
        if actions is not None and fast.any():
            rows = np.flatnonzero(fast)
            s = state.copy()
            s[:, 2] = np.clip(s[:, 2], -r1max, r1max)
            s[:, 3] = np.clip(s[:, 3], -r2max, r2max)
            self._rewrite(rows, [list(s[i]) for i in rows])
            state = self._state()
        t1, t2 = state[:, 0], state[:, 1]
        obs = np.stack([np.cos(t1), np.sin(t1), np.cos(t2), np.sin(t2), state[:, 2], state[:, 3]], axis=1)
        terminated = -np.cos(t1) - np.cos(t1 + t2) > 1.0
        rewards = np.where(terminated, 0.0, -1.0)
        high = self.single_observation_space.high
        return np.clip(obs, -high, high).astype(np.float32), rewards, terminated


__all__ = ["AcrobotVectorEnv", "CartPoleVectorEnv", "PendulumVectorEnv"]
