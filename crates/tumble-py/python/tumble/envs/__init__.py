"""Gymnasium environments simulated by Tumble (``pip install 'tumble[envs]'``).

Importing this module registers them with gymnasium::

    import gymnasium as gym
    import tumble.envs  # noqa: F401  (registers tumble/CartPole-v0, ...)
    env = gym.make("tumble/CartPole-v0", render_mode="rgb_array")

or, without the import, ``gym.make("tumble.envs:tumble/CartPole-v0")``.

=====================  ==========================  ==================  ==========
id                     class                       actions             max steps
=====================  ==========================  ==================  ==========
tumble/CartPole-v0     :class:`CartPoleEnv`        Discrete(2)         500
tumble/Pendulum-v0     :class:`PendulumEnv`        Box(-2, 2, (1,))    200
tumble/Acrobot-v0      :class:`AcrobotEnv`         Discrete(3)         500
tumble/Pusher-v0       :class:`PusherEnv`          Box(-1, 1, (2,))    200
=====================  ==========================  ==================  ==========

Each class's docstring and docs/envs.md give the observation, reward, termination and
start state. The vectorised versions of the first three (``gym.make_vec(id, num_envs=W,
vectorization_mode="vector_entry_point")``, module :mod:`tumble.envs.vector`) step W
copies in one ``tumble.Batch`` and are imported only when asked for; they need
``tumble.Batch``.
"""

from __future__ import annotations

from ._common import gym
from .acrobot import AcrobotEnv
from .cartpole import CartPoleEnv
from .pendulum import PendulumEnv
from .pusher import PusherEnv

# id: (module, class, max_episode_steps)
ENVS = {
    "tumble/CartPole-v0": ("cartpole", "CartPoleEnv", 500),
    "tumble/Pendulum-v0": ("pendulum", "PendulumEnv", 200),
    "tumble/Acrobot-v0": ("acrobot", "AcrobotEnv", 500),
    "tumble/Pusher-v0": ("pusher", "PusherEnv", 200),
}


def register() -> None:
    """Registers every environment with gymnasium (done on import; harmless to repeat)."""
    for env_id, (module, cls, steps) in ENVS.items():
        if env_id in gym.envs.registry:
            continue
        # The Pusher has no vectorised version (see tumble.envs.vector).
        vector = None if module == "pusher" else f"tumble.envs.vector:{cls[:-3]}VectorEnv"
        gym.register(
            id=env_id,
            entry_point=f"tumble.envs.{module}:{cls}",
            vector_entry_point=vector,
            max_episode_steps=steps,
        )


register()

__all__ = ["ENVS", "AcrobotEnv", "CartPoleEnv", "PendulumEnv", "PusherEnv", "register"]
