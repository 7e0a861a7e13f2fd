"""Type stubs of the extension module behind `import tumble` (crates/tumble-py/src)."""

from os import PathLike
from typing import Any, Callable, Literal, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
INTEGRATORS: list[str]
"""The integrators' names: explicit_euler, symplectic_euler, implicit_euler, midpoint, rk4, verlet, velocity_verlet."""
SCENES: list[str]
"""The built-in scenes' names, for World.from_scene."""
SINGLE_PRECISION: bool
"""Whether the core was built with f32 numbers (arrays are float64 either way)."""

Vec3Like = Union[Sequence[float], npt.ArrayLike]
QuatLike = Union[Sequence[float], npt.ArrayLike]
F64Array = npt.NDArray[np.float64]
BodyLike = Union["Body", str]

class SimulationError(RuntimeError):
    """A step whose result was not finite or faster than the world's speed limits. The step
    was undone: the world is as it was after the last good step. The message is one line,
    ``step 41 (t = 0.683 s): bodies[7] "pelvis": velocity is not finite``."""

    step: int
    """The failed step's number (the world had taken ``step - 1``)."""
    time: float
    """The time the failed step would have reached (s)."""
    body: int
    """The body's index in creation order (the row of the bulk arrays)."""
    name: Optional[str]
    """The body's name, if it has one."""
    quantity: str
    """``position``, ``orientation``, ``velocity``, ``angular_velocity`` or ``angular_momentum``."""
    problem: str
    """``is not finite``, or the speed reached against the limit."""
    trajectory: Optional[Trajectory]
    """From ``simulate``: the run recorded up to the last good step; otherwise None."""
    world: int
    """From a Batch only: the index of the world whose step failed."""

class Shape:
    """A collision shape; make one with a subclass. Immutable, shareable between bodies."""

    @property
    def kind(self) -> str:
        """The kind as named in scene files: "sphere", "box", ..."""
    @property
    def volume(self) -> float:
        """Volume (m³); 0 for plane, mesh and height field."""

class Sphere(Shape):
    """A ball of `radius` (m) centred on the body's origin."""

    def __init__(self, radius: float) -> None: ...

class Box(Shape):
    """A box with half extents [x, y, z] (m), centred on the body's origin."""

    def __init__(self, half_extents: Vec3Like) -> None: ...

class Capsule(Shape):
    """A capsule along local y: shaft half length `half_height` (m), caps of `radius` (m)."""

    def __init__(self, radius: float, half_height: float) -> None: ...

class Cylinder(Shape):
    """A solid cylinder along local y, of `radius` and half length `half_height` (m)."""

    def __init__(self, radius: float, half_height: float) -> None: ...

class ConvexHull(Shape):
    """The convex hull of (N, 3) points (m, body frame): at least 4, not coplanar."""

    def __init__(self, points: npt.ArrayLike) -> None: ...

class Compound(Shape):
    """Shapes rigidly joined: shapes or (shape, position[, orientation]) tuples."""

    def __init__(
        self,
        children: Sequence[Union[Shape, Tuple[Shape, Vec3Like], Tuple[Shape, Vec3Like, QuatLike]]],
    ) -> None: ...

class Plane(Shape):
    """The half-space normal·x ≤ offset (body frame). Static bodies only."""

    def __init__(self, normal: Vec3Like, offset: float = 0.0) -> None: ...

class TriMesh(Shape):
    """A triangle mesh: vertices (N, 3) in m, indices (M, 3), counter-clockwise fronts. Static only."""

    def __init__(self, vertices: npt.ArrayLike, indices: npt.ArrayLike) -> None: ...

class HeightField(Shape):
    """Terrain from a 2-D array of heights (rows along z, columns along x), scaled by [sx, sy, sz]. Static only."""

    def __init__(self, heights: npt.ArrayLike, scale: Optional[Vec3Like] = None) -> None: ...

class ForceContext:
    """What a force callback (``World.add_force_callback``) is called with: the state of
    every body at the force evaluation being made, and where forces for it go. Bodies
    are ``Body`` handles (fastest) or names. Valid only inside the call it was passed to
    (RuntimeError after)."""

    @property
    def time(self) -> float:
        """Simulated time of the state being evaluated (s)."""
    def position(self, body: BodyLike) -> F64Array:
        """World position of the body frame's origin (m), (3,)."""
    def center_of_mass(self, body: BodyLike) -> F64Array:
        """World position of the centre of mass (m), (3,)."""
    def orientation(self, body: BodyLike) -> F64Array:
        """Orientation [x, y, z, w], body frame to world."""
    def velocity(self, body: BodyLike) -> F64Array:
        """Velocity of the centre of mass (m/s, world frame), (3,)."""
    def angular_velocity(self, body: BodyLike) -> F64Array:
        """Angular velocity (rad/s, world frame), (3,)."""
    def mass(self, body: BodyLike) -> float:
        """Mass (kg)."""
    def add_force(self, body: BodyLike, force: Vec3Like, point: Optional[Vec3Like] = None) -> None:
        """Adds `force` (N, world frame) at `point` (m, body frame; default the centre of
        mass) for this evaluation; off the centre it also adds r × F."""
    def add_torque(self, body: BodyLike, torque: Vec3Like) -> None:
        """Adds `torque` (N·m, world frame) for this evaluation."""

ForceCallback = Callable[[ForceContext], Any]
Controller = Callable[["World", float], Any]

class Body:
    """A handle on a body; properties read the live state, eleven are assignable."""

    @property
    def world(self) -> World:
        """The world this body is in."""
    @property
    def name(self) -> Optional[str]:
        """The body's name, or None."""
    @property
    def kind(self) -> Literal["dynamic", "kinematic", "static"]:
        """How the body moves."""
    @property
    def shape_kind(self) -> str:
        """The shape's kind ("sphere", "box", ...)."""
    @property
    def alive(self) -> bool:
        """Whether the body still exists."""
    @property
    def mass(self) -> float:
        """Mass (kg)."""
    @property
    def inertia(self) -> F64Array:
        """Inertia about the centre of mass, body axes (kg·m²), (3, 3)."""
    @property
    def inertia_world(self) -> F64Array:
        """Inertia about the centre of mass, world axes (kg·m²), (3, 3)."""
    @property
    def position(self) -> F64Array:
        """World position of the body frame's origin (m), (3,)."""
    @position.setter
    def position(self, value: Vec3Like) -> None: ...
    @property
    def center_of_mass(self) -> F64Array:
        """World position of the centre of mass (m), (3,)."""
    @property
    def orientation(self) -> F64Array:
        """Unit quaternion [x, y, z, w], body to world, (4,)."""
    @orientation.setter
    def orientation(self, value: QuatLike) -> None: ...
    @property
    def velocity(self) -> F64Array:
        """Centre-of-mass velocity (m/s, world), (3,)."""
    @velocity.setter
    def velocity(self, value: Vec3Like) -> None: ...
    @property
    def angular_velocity(self) -> F64Array:
        """Angular velocity (rad/s, world), (3,)."""
    @angular_velocity.setter
    def angular_velocity(self, value: Vec3Like) -> None: ...
    @property
    def linear_momentum(self) -> F64Array:
        """m v (kg·m/s), (3,)."""
    @property
    def angular_momentum(self) -> F64Array:
        """Angular momentum about the centre of mass (kg·m²/s, world), (3,)."""
    @property
    def kinetic_energy(self) -> float:
        """Translational plus rotational kinetic energy (J)."""
    @property
    def awake(self) -> bool:
        """False while the body's island sleeps."""
    @property
    def planar(self) -> bool:
        """Whether the body is confined to the xy plane."""
    @property
    def friction(self) -> float:
        """Coulomb friction coefficient (>= 0); assignable."""
    @friction.setter
    def friction(self, value: float) -> None: ...
    @property
    def restitution(self) -> float:
        """Coefficient of restitution (in [0, 1]); assignable."""
    @restitution.setter
    def restitution(self, value: float) -> None: ...
    @property
    def collision_group(self) -> int:
        """Collision layers the body is in (32-bit set); assignable."""
    @collision_group.setter
    def collision_group(self, value: int) -> None: ...
    @property
    def collision_mask(self) -> int:
        """Layers the body collides with (32-bit set); assignable."""
    @collision_mask.setter
    def collision_mask(self, value: int) -> None: ...
    @property
    def collision_owner(self) -> int:
        """Bodies with the same non-zero owner never collide with each other (0: none);
        an imported URDF model's links share one unless self_collision=True; assignable."""
    @collision_owner.setter
    def collision_owner(self, value: int) -> None: ...
    @property
    def linear_damping(self) -> float:
        """Linear damping (1/s): dv/dt = −c v besides the forces; assignable."""
    @linear_damping.setter
    def linear_damping(self, value: float) -> None: ...
    @property
    def angular_damping(self) -> float:
        """Angular damping (1/s): dL/dt = −c L besides the torques; assignable."""
    @angular_damping.setter
    def angular_damping(self, value: float) -> None: ...
    @property
    def gravity_scale(self) -> float:
        """Multiplier of the world's gravity for this body; assignable."""
    @gravity_scale.setter
    def gravity_scale(self, value: float) -> None: ...
    @property
    def sensor(self) -> bool:
        """Whether the body is a sensor (reports overlaps, no contact response); assignable."""
    @sensor.setter
    def sensor(self, value: bool) -> None: ...
    @property
    def one_way(self) -> Optional[F64Array]:
        """A one-way body's unit normal (body frame), or None; assignable (None: an ordinary body)."""
    @one_way.setter
    def one_way(self, value: Optional[Vec3Like]) -> None: ...
    def set_kinematic_target(
        self, position: Vec3Like, orientation: Optional[QuatLike] = None
    ) -> None:
        """A kinematic body arrives exactly at this pose at the end of the next step (then keeps its velocities)."""
    @property
    def rolling_resistance(self) -> float:
        """Rolling resistance coefficient (dimensionless): rolling torque at most μ_r r N."""
    @property
    def torsional_friction(self) -> float:
        """Torsional friction (m): spinning torque about the contact normal at most μ_t N."""
    def apply_impulse(self, impulse: Vec3Like, point: Optional[Vec3Like] = None) -> None:
        """Applies an impulse (N·s) at a world point (m; default the centre of mass)."""
    def wake(self) -> None:
        """Wakes the body's island and the islands touching it."""
    def __eq__(self, other: object) -> bool: ...
    def __hash__(self) -> int: ...

class SolverSettings:
    """Contact and joint solver settings; read world.solver_settings, change, assign back."""

    kind: str
    substeps: int
    iterations: int
    contact_hertz: float
    contact_damping_ratio: float
    baumgarte: float
    joint_hertz: float
    joint_damping_ratio: float
    joint_trees: str
    """"maximal" or "reduced": joint trees solved in reduced coordinates."""
    def __init__(
        self,
        *,
        kind: str = "soft_step",
        substeps: int = 4,
        iterations: int = 1,
        contact_hertz: float = 60.0,
        contact_damping_ratio: float = 10.0,
        baumgarte: float = 0.2,
        joint_hertz: float = 1000.0,
        joint_damping_ratio: float = 0.5,
        joint_trees: str = "maximal",
    ) -> None: ...

class Diagnostics:
    """Energies (J) and momenta of a state, over the dynamic bodies."""

    kinetic: float
    potential: float
    total: float
    linear_momentum: F64Array
    angular_momentum: F64Array
    """About the world origin (kg·m²/s)."""

class Trajectory:
    """A recorded run; arrays are float64, bodies in creation order."""

    time: F64Array
    """(T,) in s."""
    position: F64Array
    """(T, N, 3) in m."""
    orientation: F64Array
    """(T, N, 4) quaternions [x, y, z, w]."""
    velocity: F64Array
    """(T, N, 3) in m/s."""
    angular_velocity: F64Array
    """(T, N, 3) in rad/s."""
    kinetic: Optional[F64Array]
    potential: Optional[F64Array]
    total: Optional[F64Array]
    linear_momentum: Optional[F64Array]
    angular_momentum: Optional[F64Array]
    names: list[Optional[str]]
    def __len__(self) -> int: ...

class RayHit:
    """A ray's hit: body, parameter t, point and normal (world), subshape index."""

    body: Body
    t: float
    point: F64Array
    normal: F64Array
    subshape: int

class ShapeHit:
    """A shape cast's hit: body, fraction t of the translation, point and normal."""

    body: Body
    t: float
    point: F64Array
    normal: F64Array

class ContactPoint:
    """One contact point, with the impulses of the last step (N·s)."""

    position: F64Array
    point_a: F64Array
    point_b: F64Array
    separation: float
    normal_impulse: float
    tangent_impulse: F64Array

class Contact:
    """A contact manifold: the normal from body_a to body_b and up to four points."""

    body_a: Body
    body_b: Body
    normal: F64Array
    points: list[ContactPoint]

class ContactEvent:
    """Two bodies started ("begin") or stopped ("end") touching at the last step."""

    kind: Literal["begin", "end"]
    body_a: Body
    body_b: Body

class SensorEvent:
    """A body began or stopped overlapping a sensor at `time` (s)."""

    sensor: Body
    body: Body
    began: bool
    time: float

class Motor:
    """A velocity motor: `speed` (rad/s or m/s) with at most `max_force` (N·m or N)."""

    speed: float
    max_force: float
    def __init__(self, speed: float, max_force: float) -> None: ...

class JointSpring:
    """A spring on a joint's free coordinate: `hertz`, `damping_ratio`, `target`."""

    hertz: float
    damping_ratio: float
    target: float
    def __init__(self, hertz: float, damping_ratio: float = 1.0, target: float = 0.0) -> None: ...

class Servo:
    """A position servo: towards `target` (rad or m) with `stiffness` (N·m/rad or N/m),
    `damping` (N·m·s/rad or N·s/m) and at most `max_force` (N·m or N), solved implicitly."""

    target: float
    stiffness: float
    damping: float
    max_force: float
    def __init__(self, target: float, stiffness: float, damping: float, max_force: float) -> None: ...

JointCoordinate = Union[float, Tuple[float, float, float]]

class Joint:
    """A handle on a joint. `motor`, `servo`, `limits`, `spring`, `enabled`, `break_force`,
    `armature` and `position` are settable while the world runs (checked as `add_joint` checks them;
    a refused value changes nothing; both bodies are woken)."""

    @property
    def name(self) -> Optional[str]: ...
    @property
    def kind(self) -> Literal["ball", "hinge", "slider", "fixed", "distance"]: ...
    @property
    def body(self) -> Body: ...
    @property
    def other(self) -> Optional[Body]:
        """The second body, or None for the world."""
    @property
    def broken(self) -> bool: ...
    @property
    def reaction_force(self) -> F64Array:
        """Force applied to `other` over the last step (N), (3,); `body` felt the opposite."""
    @property
    def reaction_torque(self) -> F64Array:
        """Torque applied to `other` about its anchor over the last step (N·m), (3,)."""
    @property
    def alive(self) -> bool: ...
    @property
    def motor(self) -> Optional[Motor]:
        """The hinge's or slider's velocity motor; None switches it off."""
    @motor.setter
    def motor(self, value: Optional[Motor]) -> None: ...
    @property
    def servo(self) -> Optional[Servo]:
        """The hinge's or slider's position servo; None switches it off."""
    @servo.setter
    def servo(self, value: Optional[Servo]) -> None: ...
    @property
    def limits(self) -> Optional[Tuple[float, float]]:
        """The hinge's or slider's (lower, upper) limits (rad or m), or None."""
    @limits.setter
    def limits(self, value: Optional[Sequence[float]]) -> None: ...
    @property
    def spring(self) -> Optional[JointSpring]:
        """The spring of a hinge, slider or distance joint, or None."""
    @spring.setter
    def spring(self, value: Optional[JointSpring]) -> None: ...
    @property
    def enabled(self) -> bool:
        """Whether the joint acts; a disabled joint's bodies collide as unjoined ones."""
    @enabled.setter
    def enabled(self, value: bool) -> None: ...
    @property
    def break_force(self) -> Optional[float]:
        """Reaction force (N) beyond which the joint breaks, or None."""
    @break_force.setter
    def break_force(self, value: Optional[float]) -> None: ...
    @property
    def armature(self) -> float:
        """A hinge's or slider's armature, the coordinate's rotor inertia (kg m² or kg)."""
    @armature.setter
    def armature(self, value: float) -> None: ...
    @property
    def position(self) -> JointCoordinate:
        """Hinge angle (rad, counting whole turns as MuJoCo's qpos), slider offset or distance (m); a ball or fixed
        joint's rotation vector (rad, in `other`'s frame). Setting it (not on fixed joints)
        moves one side of the joint rigidly to that coordinate."""
    @position.setter
    def position(self, value: Union[float, Vec3Like]) -> None: ...
    @property
    def velocity(self) -> JointCoordinate:
        """The coordinate's rate (rad/s or m/s); ball and fixed: relative angular velocity."""

class Model:
    """What a model file became in a world (World.add_urdf)."""

    @property
    def name(self) -> str:
        """The file's model name (URDF's <robot name>)."""
    @property
    def bodies(self) -> dict[str, Body]:
        """Each link by its name in the file; links merged by fixed joints share a body."""
    @property
    def joints(self) -> dict[str, Joint]:
        """Each joint by its name in the file; `position` is the file's joint coordinate."""
    @property
    def warnings(self) -> list[str]:
        """What was read but not built as written, one line each."""

class World:
    """A simulated world: bodies, force elements, joints and the step."""

    def __init__(
        self,
        *,
        gravity: Optional[Vec3Like] = None,
        integrator: str = "symplectic_euler",
        solver: str = "soft_step",
        substeps: int = 4,
        iterations: int = 1,
        contact_hertz: float = 60.0,
        contact_damping_ratio: float = 10.0,
        joint_hertz: float = 1000.0,
        joint_damping_ratio: float = 0.5,
        baumgarte: float = 0.2,
        joint_trees: str = "maximal",
        length_unit: float = 1.0,
        sleep: bool = True,
        max_speed: Optional[float] = None,
        max_angular_speed: Optional[float] = None,
        max_contacts: Optional[int] = None,
        max_contacts_per_body: Optional[int] = None,
        max_push_speed: Optional[float] = None,
        threads: Optional[int] = None,
    ) -> None: ...
    @staticmethod
    def from_scene(path: Union[str, PathLike[str]]) -> World:
        """Loads a scene file, or a built-in scene by name (tumble.SCENES)."""
    @staticmethod
    def from_json(text: str, folder: Optional[Union[str, PathLike[str]]] = None) -> World:
        """Loads a scene from JSON text; relative `models` paths are read from `folder`
        (default: the working directory)."""
    @staticmethod
    def from_mjcf(path: Union[str, PathLike[str]]) -> World:
        """Loads an MJCF (MuJoCo XML) model: names, joints and gravity from the file;
        what is not read comes out as UserWarnings naming file, line and element."""
    @property
    def actuators(self) -> list[str]:
        """Names of the MJCF model's actuators (from_mjcf), in file order; else empty."""
    def set_control(self, name: str, value: float) -> None:
        """Sets MJCF actuator `name`'s control (MuJoCo's ctrl, clamped to ctrlrange)."""
    def control(self, name: str) -> float:
        """MJCF actuator `name`'s control as last set (0 until set)."""
    @staticmethod
    def from_urdf(
        path: Union[str, PathLike[str]],
        *,
        fixed_base: bool = True,
        gravity: Optional[Vec3Like] = None,
        position: Optional[Vec3Like] = None,
        orientation: Optional[QuatLike] = None,
        merge_fixed: bool = True,
        self_collision: bool = False,
    ) -> World:
        """A world holding a URDF model; gravity defaults to z-up (0, 0, -9.81).
        Bodies and joints are named as in the file. The model's links collide with each
        other only with self_collision=True. What is not built as written comes out as
        UserWarnings (add_urdf's `warnings`). ValueError names file:line and element."""
    def add_urdf(
        self,
        path: Union[str, PathLike[str]],
        *,
        position: Optional[Vec3Like] = None,
        orientation: Optional[QuatLike] = None,
        fixed_base: bool = True,
        merge_fixed: bool = True,
        prefix: Optional[str] = None,
        self_collision: bool = False,
    ) -> Model:
        """Adds a URDF model (all or nothing) and returns its bodies and joints by name.
        Its links collide with each other only with self_collision=True; with other
        models (another copy too) and bodies always."""
    def add_body(
        self,
        shape: Shape,
        *,
        mass: Optional[float] = None,
        density: Optional[float] = None,
        position: Optional[Vec3Like] = None,
        orientation: Optional[QuatLike] = None,
        velocity: Optional[Vec3Like] = None,
        angular_velocity: Optional[Vec3Like] = None,
        kind: Literal["dynamic", "kinematic", "static"] = "dynamic",
        name: Optional[str] = None,
        planar: bool = False,
        inertia: Optional[npt.ArrayLike] = None,
        center_of_mass: Optional[Vec3Like] = None,
        friction: float = 0.6,
        restitution: float = 0.0,
        rolling_resistance: float = 0.0,
        torsional_friction: float = 0.0,
        collision_group: int = 1,
        collision_mask: int = 0xFFFFFFFF,
        collision_owner: int = 0,
        bullet: bool = False,
        linear_damping: float = 0.0,
        angular_damping: float = 0.0,
        gravity_scale: float = 1.0,
        sensor: bool = False,
        one_way: Optional[Vec3Like] = None,
    ) -> Body:
        """Adds a body and returns its handle."""
    def remove_body(self, body: BodyLike) -> None:
        """Removes a body with its force elements and joints."""
    def body(self, name: str) -> Body:
        """The body called `name` (KeyError if none)."""
    @property
    def bodies(self) -> list[Body]:
        """Every body, in creation order."""
    @property
    def body_names(self) -> list[Optional[str]]: ...
    def __len__(self) -> int: ...
    def add_spring(
        self,
        body: BodyLike,
        *,
        stiffness: float,
        world_point: Optional[Vec3Like] = None,
        other: Optional[BodyLike] = None,
        anchor: Optional[Vec3Like] = None,
        other_anchor: Optional[Vec3Like] = None,
        rest_length: float = 0.0,
        damping: float = 0.0,
    ) -> int:
        """A spring and damper to a world point or another body; returns its id."""
    def add_drag(self, body: BodyLike, *, linear: float = 0.0, quadratic: float = 0.0) -> int:
        """Air drag F = −linear·v − quadratic·|v|·v; returns its id."""
    def add_force(
        self,
        body: BodyLike,
        *,
        force: Optional[Vec3Like] = None,
        point: Optional[Vec3Like] = None,
        torque: Optional[Vec3Like] = None,
    ) -> int:
        """A constant force at a body point and a constant torque; returns its id."""
    def remove_force(self, id: int) -> bool: ...
    def add_force_callback(self, callback: ForceCallback) -> None:
        """Calls `callback(ctx)` at every force evaluation (per step: once with the Euler
        methods and Störmer–Verlet, twice with midpoint and velocity Verlet, four times
        with RK4; once per solver substep for bodies in contact or joined, once more
        when a joined body touches nothing). An exception in it stops the step, leaves
        the world as before that step and is raised by step/simulate. Wakes every body."""
    def add_joint(
        self,
        kind: Literal["ball", "hinge", "slider", "fixed", "distance"],
        body: BodyLike,
        other: Optional[BodyLike] = None,
        *,
        anchor: Optional[Vec3Like] = None,
        axis: Optional[Vec3Like] = None,
        other_anchor: Optional[Vec3Like] = None,
        other_axis: Optional[Vec3Like] = None,
        name: Optional[str] = None,
        collide_connected: bool = False,
        break_force: Optional[float] = None,
        armature: float = 0.0,
        # The options each kind takes (tumble::joint::JOINT_KINDS); another kind's is a
        # TypeError, None counts as left out.
        cone: Optional[float] = None,
        twist: Optional[Sequence[float]] = None,
        limits: Optional[Sequence[float]] = None,
        motor: Optional[Motor] = None,
        spring: Optional[JointSpring] = None,
        servo: Optional[Servo] = None,
        length: Optional[float] = None,
        min: Optional[float] = None,
        max: Optional[float] = None,
    ) -> Joint:
        """Adds a joint between `body` and `other` (None: the world)."""
    def remove_joint(self, joint: Joint) -> bool: ...
    def joint(self, name: str) -> Joint:
        """The joint called `name` (KeyError if none)."""
    @property
    def joints(self) -> list[Joint]: ...
    def step(self, dt: float, steps: int = 1) -> None:
        """Advances by `dt` seconds, `steps` times; stops on Ctrl-C (KeyboardInterrupt) or
        an unstable step (SimulationError, that step undone) at the last step completed."""
    def simulate(
        self,
        duration: Optional[float] = None,
        dt: Optional[float] = None,
        *,
        steps: Optional[int] = None,
        every: int = 1,
        diagnostics: bool = False,
        controller: Optional[Controller] = None,
    ) -> Trajectory:
        """Runs in Rust with the interpreter released and returns the recorded trajectory.

        A recording larger than the machine's memory is refused (ValueError) before the run;
        Ctrl-C stops it between steps (KeyboardInterrupt); an unstable step raises
        SimulationError, whose ``trajectory`` is the run up to the last good step.
        ``controller(world, t)`` is called before every step with this world and the
        step's start time (s); its exception stops the run before that step, raised as is."""
    @property
    def positions(self) -> F64Array:
        """(N, 3) body-frame origins (m); assignable."""
    @positions.setter
    def positions(self, value: npt.ArrayLike) -> None: ...
    @property
    def orientations(self) -> F64Array:
        """(N, 4) quaternions [x, y, z, w]; assignable."""
    @orientations.setter
    def orientations(self, value: npt.ArrayLike) -> None: ...
    @property
    def velocities(self) -> F64Array:
        """(N, 3) centre-of-mass velocities (m/s); assignable."""
    @velocities.setter
    def velocities(self, value: npt.ArrayLike) -> None: ...
    @property
    def angular_velocities(self) -> F64Array:
        """(N, 3) angular velocities (rad/s); assignable."""
    @angular_velocities.setter
    def angular_velocities(self, value: npt.ArrayLike) -> None: ...
    @property
    def angular_momenta(self) -> F64Array:
        """(N, 3) angular momenta about each centre of mass (kg·m²/s)."""
    def set_state(
        self,
        *,
        positions: Optional[npt.ArrayLike] = None,
        orientations: Optional[npt.ArrayLike] = None,
        velocities: Optional[npt.ArrayLike] = None,
        angular_velocities: Optional[npt.ArrayLike] = None,
    ) -> None:
        """Sets any of the bulk arrays at once; all or nothing (every row is checked first)."""
    def cast_ray(
        self,
        origin: Vec3Like,
        direction: Vec3Like,
        max_t: float = ...,
        *,
        mask: int = 0xFFFFFFFF,
        exclude: Optional[BodyLike] = None,
    ) -> Optional[RayHit]:
        """The nearest hit of origin + t·direction, t in [0, max_t]."""
    def cast_ray_all(
        self,
        origin: Vec3Like,
        direction: Vec3Like,
        max_t: float = ...,
        *,
        mask: int = 0xFFFFFFFF,
        exclude: Optional[BodyLike] = None,
    ) -> list[RayHit]:
        """Every hit, nearest first."""
    def cast_shape(
        self,
        shape: Shape,
        position: Vec3Like,
        translation: Vec3Like,
        orientation: Optional[QuatLike] = None,
        *,
        mask: int = 0xFFFFFFFF,
        exclude: Optional[BodyLike] = None,
    ) -> Optional[ShapeHit]:
        """The first body a convex shape swept along `translation` touches."""
    def query_point(
        self, point: Vec3Like, *, mask: int = 0xFFFFFFFF, exclude: Optional[BodyLike] = None
    ) -> list[Body]: ...
    def query_aabb(
        self,
        lower: Vec3Like,
        upper: Vec3Like,
        *,
        mask: int = 0xFFFFFFFF,
        exclude: Optional[BodyLike] = None,
    ) -> list[Body]: ...
    def contacts(self) -> list[Contact]:
        """The contact manifolds of the last step."""
    def update_contacts(self) -> list[Contact]:
        """Collision detection on the current state, without a step."""
    def contact_events(self) -> list[ContactEvent]:
        """Pairs that began or ended touching at the last step."""
    def exclude_contacts(self, a: BodyLike, b: BodyLike) -> None:
        """Keeps two bodies from ever touching (as a joint between them does); kept by
        snapshots, batches and saved scenes (scene key `exclude`)."""
    def allow_contacts(self, a: BodyLike, b: BodyLike) -> bool:
        """Lets an excluded pair touch again; whether it was excluded."""
    @property
    def excluded_contacts(self) -> list[tuple[Body, Body]]: ...
    def sensor_events(self) -> list[SensorEvent]:
        """Bodies that began or stopped overlapping a sensor at the last step, in (sensor, body) order."""
    def sensor_overlaps(self, sensor: BodyLike) -> list[Body]:
        """The bodies overlapping `sensor` as of the last step (empty for a body that is not a sensor)."""
    @property
    def time(self) -> float: ...
    @property
    def step_count(self) -> int: ...
    @property
    def gravity(self) -> F64Array: ...
    @gravity.setter
    def gravity(self, value: Vec3Like) -> None: ...
    @property
    def integrator(self) -> str: ...
    @integrator.setter
    def integrator(self, name: str) -> None: ...
    @property
    def sleep(self) -> bool: ...
    @sleep.setter
    def sleep(self, on: bool) -> None: ...
    @property
    def dt(self) -> float: ...
    @dt.setter
    def dt(self, dt: float) -> None: ...
    @property
    def duration(self) -> float: ...
    @duration.setter
    def duration(self, duration: float) -> None: ...
    @property
    def solver_settings(self) -> SolverSettings: ...
    @solver_settings.setter
    def solver_settings(self, settings: SolverSettings) -> None: ...
    @property
    def max_speed(self) -> float:
        """The fastest a centre of mass may move (m/s; default 1e4·length_unit); assignable."""
    @max_speed.setter
    def max_speed(self, value: float) -> None: ...
    @property
    def max_angular_speed(self) -> float:
        """The fastest a body may turn (rad/s; default 1e5); assignable."""
    @max_angular_speed.setter
    def max_angular_speed(self, value: float) -> None: ...
    @property
    def max_contacts(self) -> int:
        """Contact manifolds a step may hold (default 1,048,576); a step needing more raises SimulationError."""
    @max_contacts.setter
    def max_contacts(self, value: int) -> None: ...
    @property
    def max_contacts_per_body(self) -> int:
        """Other bodies a body may be sunk into before it counts as crowded (default 16)."""
    @max_contacts_per_body.setter
    def max_contacts_per_body(self, value: int) -> None: ...
    @property
    def max_push_speed(self) -> float:
        """The fastest contacts push overlapping bodies apart (m/s; default 3·length_unit); assignable."""
    @max_push_speed.setter
    def max_push_speed(self, value: float) -> None: ...
    @property
    def threads(self) -> int: ...
    @threads.setter
    def threads(self, value: int) -> None: ...
    @property
    def contact_margin(self) -> float: ...
    def diagnostics(self) -> Diagnostics:
        """Energies, momentum and angular momentum of the current state."""
    def render(
        self,
        width: int = 320,
        height: int = 240,
        *,
        camera: Optional[Vec3Like] = None,
        target: Optional[Vec3Like] = None,
        contacts: bool = False,
        joints: bool = False,
        time: bool = False,
    ) -> npt.NDArray[np.uint8]:
        """The world now as an (height, width, 3) uint8 RGB array, drawn as `tumble render`
        draws a frame; the camera at `camera` looking at `target` (default: framing the
        moving bodies, from the front, a little right and above). Sides 1 to 4096."""
    def state_hash(self) -> int:
        """Equal hashes mean bit-identical states."""
    def snapshot(self) -> bytes:
        """The world's whole state as bytes; restore/from_snapshot continue it bit-identically.
        Force callbacks, the contact filter and modifier are code: not saved."""
    def restore(self, data: bytes) -> None:
        """Replaces the state with a snapshot; ValueError `snapshot: ...` changes nothing."""
    @staticmethod
    def from_snapshot(data: bytes) -> World:
        """A new world continuing a snapshot (one taken without force callbacks)."""
    def save_scene(self, path: Union[str, PathLike[str]], *, state: bool = True) -> None:
        """Writes the world as a scene file; with state, World.from_scene continues it
        bit-identically."""
    @staticmethod
    def _from_pickle(data: bytes, dt: float, duration: float) -> World: ...
    def __reduce__(self) -> tuple[object, tuple[bytes, float, float]]: ...
    def __copy__(self) -> World: ...
    def __deepcopy__(self, memo: object) -> World: ...

class Batch:
    """W independent copies of a world stepped together across threads (issue 20).

    ``Batch(scene, copies, threads=None)``: ``scene`` a World (copied as it is now), a scene
    dict, a scene or model file's path or a built-in scene's name; ``copies`` W, an int
    >= 1; ``threads`` how many threads step the worlds (default TUMBLE_THREADS, else every
    core). Each world steps on one thread, so it is bit-identical to the same world stepped
    alone, whatever ``threads``. A World with force callbacks or a contact filter or
    modifier is refused. Arrays are float64, shaped (W, N, 3) or (W, N, 4); settable ones are
    checked whole (``worlds[1].velocities[0]: ...``) before any world changes, and wake the
    bodies."""

    def __init__(
        self,
        scene: Union[World, dict[str, Any], str, PathLike[str]],
        copies: int,
        threads: Optional[int] = None,
    ) -> None: ...
    def __len__(self) -> int: ...
    copies: int
    """W, the number of worlds."""
    threads: int
    """Threads stepping the worlds (1 to 256); assignable."""
    body_names: list[Optional[str]]
    """The bodies' names along the arrays' second axis."""
    def body_index(self, name: str) -> int:
        """The index along the body axis of the body called name (KeyError if none)."""
    dt: float
    """The default step (s): the scene's dt, else 0.01."""
    time: F64Array
    """Each world's time (s), (W,)."""
    step_counts: list[int]
    """Each world's steps taken."""
    positions: F64Array
    """(W, N, 3) body frame origins (m); assignable."""
    orientations: F64Array
    """(W, N, 4) quaternions [x, y, z, w]; assignable."""
    velocities: F64Array
    """(W, N, 3) centre-of-mass velocities (m/s); assignable."""
    angular_velocities: F64Array
    """(W, N, 3) angular velocities (rad/s, world frame); assignable."""
    def step(self, dt: Optional[float] = None, steps: int = 1) -> None:
        """Steps every world ``steps`` times by dt (default the scene's), the interpreter's
        lock released; Ctrl-C stops it within a few ms (worlds may then stand at different
        steps: ``step_counts``). A world whose step fails stays at its last good step while
        the others finish the chunk of steps under way and stop together; SimulationError
        names it (``worlds[3]: step 41 ...``, ``.world``)."""
    def apply_forces(self, forces: npt.ArrayLike, torques: Optional[npt.ArrayLike] = None) -> None:
        """Constant forces (N, at each centre of mass) and torques (N·m), (W, N, 3), acting
        from now on at every step until the next apply_forces or clear_forces (they persist,
        as World.add_force's do). Resetting a world drops its forces."""
    def clear_forces(self) -> None:
        """Removes the forces of apply_forces from every world."""
    def set_joint_targets(
        self,
        name: str,
        values: npt.ArrayLike,
        *,
        kind: Optional[Literal["velocity", "position"]] = None,
    ) -> None:
        """The target of joint ``name`` in each world, values (W,): its motor's speed
        ("velocity") or its servo's target ("position"); by default what the joint has."""
    def reset(
        self,
        worlds: Optional[Sequence[int]] = None,
        snapshot: Optional[bytes] = None,
        *,
        positions: Optional[npt.ArrayLike] = None,
        orientations: Optional[npt.ArrayLike] = None,
        velocities: Optional[npt.ArrayLike] = None,
        angular_velocities: Optional[npt.ArrayLike] = None,
    ) -> None:
        """Returns the worlds listed (default all, K of them) to the initial state or to a
        snapshot's, then sets any (K, N, 3|4) arrays given. All or nothing."""
    def randomize(
        self,
        rng: np.random.Generator,
        *,
        worlds: Optional[Sequence[int]] = None,
        positions: float = 0.0,
        velocities: float = 0.0,
        angular_velocities: float = 0.0,
    ) -> None:
        """Resets worlds to the initial state with every dynamic body's position, velocity
        and angular velocity moved by uniform noise in [-s, s] per component, drawn from
        rng (reproducible for a seeded Generator)."""
    def snapshot(self, i: int) -> bytes:
        """World i's state as bytes (as World.snapshot)."""
    def world(self, i: int) -> World:
        """A new World continuing world i (a copy)."""
    def simulate(
        self,
        duration: Optional[float] = None,
        dt: Optional[float] = None,
        *,
        steps: Optional[int] = None,
        every: int = 1,
        out: Optional[Trajectory] = None,
    ) -> Trajectory:
        """Runs every world as World.simulate does; the Trajectory's arrays have a world
        axis: position (T, W, N, 3), orientation (T, W, N, 4), velocity and
        angular_velocity (T, W, N, 3), time (T,); the body arrays are stored world by
        world (views with the first two axes swapped). Given `out` (a Trajectory of an earlier
        Batch.simulate with the same T, W and N), its arrays are overwritten in place and
        it is returned, so a loop of rollouts allocates nothing."""

class Push:
    """An impulse a character's move gave a dynamic body in its way."""

    body: Body
    """The body pushed."""
    impulse: F64Array
    """The impulse (N·s, world), (3,); no longer than max_push_force·dt."""
    point: F64Array
    """Where it was applied (m, world), (3,)."""

class CharacterController:
    """A kinematic capsule that walks in a world: ``move(displacement, dt)`` slides along
    walls, climbs slopes up to ``max_slope`` (rad) and steps up to ``step_height`` (m),
    follows the ground down slopes and stairs, keeps ``skin`` from every surface, never
    tunnels, and pushes dynamic bodies with at most ``max_push_force``·dt per move. Gravity
    is the caller's (add it while ``on_ground`` is False). Not a body: other bodies do not
    collide with it. Bad values raise ValueError naming the field
    (``character.radius: must be > 0``)."""

    def __init__(
        self,
        world: World,
        *,
        radius: float = 0.3,
        half_height: float = 0.6,
        position: Optional[Vec3Like] = None,
        max_slope: float = 0.7853981633974483,
        step_height: float = 0.3,
        skin: float = 0.02,
        snap_distance: float = 0.3,
        max_push_force: float = 1000.0,
        up: Optional[Vec3Like] = None,
        collision_mask: int = 0xFFFFFFFF,
        exclude: Optional[BodyLike] = None,
    ) -> None: ...
    def move(self, displacement: Vec3Like, dt: float) -> None:
        """Moves the character by ``displacement`` (m) over ``dt`` (s)."""
    @property
    def world(self) -> World:
        """The world it walks in."""
    @property
    def position(self) -> F64Array:
        """The capsule's centre (m), (3,); assignable (placed there, not swept)."""
    @position.setter
    def position(self, value: Vec3Like) -> None: ...
    @property
    def on_ground(self) -> bool:
        """Whether the last move (or the start) left it on walkable ground."""
    @property
    def ground_normal(self) -> Optional[F64Array]:
        """The unit normal of the ground it stands on, or None in the air."""
    @property
    def ground_body(self) -> Optional[Body]:
        """The body it stands on, or None in the air."""
    @property
    def velocity(self) -> F64Array:
        """The last move's displacement over its dt (m/s)."""
    @property
    def pushes(self) -> list[Push]:
        """The impulses the last move gave dynamic bodies."""
    def state(self) -> dict[str, Any]:
        """What it carries between moves: ``position``, ``velocity`` and ``ground`` (None,
        or ``{"body": Body, "point": ..., "normal": ...}``). With World.snapshot, what a
        saved run needs: ``world.restore(snap); c.restore(state)``."""
    def restore(self, state: Mapping[str, Any]) -> None:
        """Puts it back to ``state`` (as ``state()`` returns; ``velocity`` and ``ground``
        optional). Bad values raise ValueError/TypeError naming the key, nothing changed."""
    @property
    def radius(self) -> float: ...
    @property
    def half_height(self) -> float: ...
    @property
    def max_slope(self) -> float: ...
    @property
    def step_height(self) -> float: ...
    @property
    def skin(self) -> float: ...
    @property
    def snap_distance(self) -> float: ...
    @property
    def max_push_force(self) -> float: ...
    @property
    def up(self) -> F64Array: ...

def builtin_scene(name: str) -> str:
    """The JSON text of the built-in scene `name` (one of SCENES); ValueError if none."""
