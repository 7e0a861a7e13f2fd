"""What the environments share: the gymnasium import, actuation, rendering."""

from __future__ import annotations

import math
from typing import Any, Optional, Tuple

try:
    import gymnasium as gym
    from gymnasium import spaces
except ImportError as e:  # pragma: no cover - depends on the installation
    raise ImportError(
        "tumble.envs needs gymnasium: pip install 'tumble[envs]' (or pip install gymnasium)"
    ) from e

import numpy as np

import tumble

# A motor asked for this speed (rad/s or m/s) never reaches it within a step, so it pushes
# with exactly its max_force all step long: a motor is how an environment applies a
# force or torque of a given size along a joint (the joint's two bodies get it equal and
# opposite, as an actuator at the joint would).
FAR = 1.0e3


def drive(joint: tumble.Joint, effort: float) -> None:
    """Applies `effort` (N or N·m, signed) along `joint` through its motor for the next steps."""
    joint.motor = tumble.Motor(math.copysign(FAR, effort), abs(float(effort)))


class Efforts:
    """Constant torques on bodies for the next steps: each call replaces the last's (as
    world.add_force elements; tumble.Batch.apply_forces does the same per world, so the
    vectorised environments follow the single ones bit for bit)."""

    def __init__(self) -> None:
        self.ids: list = []

    def apply(self, world: tumble.World, torques: list) -> None:
        """`torques`: (body, (tx, ty, tz)) pairs, N·m."""
        for i in self.ids:
            world.remove_force(i)
        self.ids = [world.add_force(b, torque=t) for b, t in torques]


class TumbleEnv(gym.Env):
    """Base: a world rebuilt by `_build` at every reset, rendered by `tumble.World.render`."""

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 50}
    # Camera (eye, target) in world coordinates; subclasses set them.
    camera: Tuple[Tuple[float, float, float], Tuple[float, float, float]] = ((0, 0, 5), (0, 0, 0))
    width = 400
    height = 300

    def __init__(self, render_mode: Optional[str] = None):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode: must be one of {self.metadata['render_modes']} or None, "
                f"got {render_mode!r}"
            )
        self.render_mode = render_mode
        self.world: Optional[tumble.World] = None

    def render(self) -> Optional[np.ndarray]:
        """(height, width, 3) uint8 RGB of the world now, with render_mode="rgb_array"."""
        if self.render_mode != "rgb_array":
            return None
        if self.world is None:
            raise RuntimeError("render: call reset() first")
        eye, target = self.camera
        return self.world.render(self.width, self.height, camera=eye, target=target, joints=True)

    def _world(self) -> tumble.World:
        if self.world is None:
            raise RuntimeError("step: call reset() first")
        return self.world


def wrap(angle: float) -> float:
    """`angle` (rad) into [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


__all__ = ["gym", "spaces", "np", "drive", "Efforts", "TumbleEnv", "wrap", "FAR"]
