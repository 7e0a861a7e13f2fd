"""Tumble: a rigid-body dynamics engine with a Rust core, driven from Python.

>>> import tumble
>>> world = tumble.World(gravity=(0, -9.8, 0), integrator="velocity_verlet")
>>> ball = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(0, 5, 0))
>>> traj = world.simulate(duration=1.0, dt=0.01)
>>> traj.position.shape
(101, 1, 3)

SI units throughout (m, kg, s, rad, N); quaternions are [x, y, z, w]; arrays are float64.
Bad input raises ValueError or TypeError whose message starts with the field's name, as
the command-line program prints it: ``shape.radius: must be > 0``. A refused call changes
nothing. A step whose result is not finite or too fast is undone and raises
SimulationError (a RuntimeError) naming the step, the time, the body and the quantity.
"""

from ._tumble import (
    INTEGRATORS,
    SCENES,
    SINGLE_PRECISION,
    Batch,
    Body,
    Box,
    Capsule,
    CharacterController,
    Compound,
    Contact,
    ContactEvent,
    ContactPoint,
    ConvexHull,
    Cylinder,
    Diagnostics,
    ForceContext,
    HeightField,
    Joint,
    JointSpring,
    Model,
    Motor,
    Plane,
    Push,
    RayHit,
    SensorEvent,
    Servo,
    Shape,
    ShapeHit,
    SimulationError,
    SolverSettings,
    Sphere,
    Trajectory,
    TriMesh,
    World,
    __version__,
)


def sweep(scene, grid, metrics, duration=None, address=None, **options):
    """Runs every combination of a grid of scene parameters (on Ray, or serially) and returns
    the table of results: see tumble.sweep's module documentation (tumble/sweep.py)."""
    from .sweep import sweep as run

    return run(scene, grid, metrics, duration, address, **options)


__all__ = [
    "INTEGRATORS",
    "SCENES",
    "SINGLE_PRECISION",
    "Batch",
    "Body",
    "Box",
    "Capsule",
    "CharacterController",
    "Compound",
    "Contact",
    "ContactEvent",
    "ContactPoint",
    "ConvexHull",
    "Cylinder",
    "Diagnostics",
    "ForceContext",
    "HeightField",
    "Joint",
    "JointSpring",
    "Model",
    "Motor",
    "Plane",
    "Push",
    "RayHit",
    "SensorEvent",
    "Servo",
    "Shape",
    "ShapeHit",
    "SimulationError",
    "SolverSettings",
    "Sphere",
    "Trajectory",
    "TriMesh",
    "World",
    "__version__",
    "sweep",
]
