"""Every refusal is a ValueError or TypeError whose message starts with the field, as the
CLI prints it; none crashes the interpreter or leaves the world half-changed."""

import numpy as np
import pytest

import tumble


@pytest.fixture
def world():
    w = tumble.World()
    w.add_body(tumble.Sphere(0.1), mass=1.0, name="ball")
    return w


@pytest.mark.parametrize(
    "make, error, message",
    [
        (lambda: tumble.Sphere(0), ValueError, "radius: must be > 0"),
        (lambda: tumble.Sphere(float("nan")), ValueError, "radius: "),
        # Plain number arguments are converted by PyO3, whose message names the argument
        # at its end ("must be real number, not str while processing 'radius'").
        (lambda: tumble.Sphere("big"), TypeError, r"[\s\S]*'radius'"),
        (lambda: tumble.Box((1, 0, 1)), ValueError, "half_extents: "),
        (lambda: tumble.Box((1, 1)), ValueError, "half_extents: expected 3 numbers"),
        (lambda: tumble.Box("abc"), TypeError, "half_extents: expected 3 numbers"),
        (lambda: tumble.Capsule(0.1, -1), ValueError, "half_height: "),
        (lambda: tumble.Cylinder(0.1, 0), ValueError, "half_height: "),
        (lambda: tumble.ConvexHull([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), ValueError, "points"),
        (lambda: tumble.ConvexHull([[0, 0, 0], [1, 0], [0, 1, 0], [0, 0, 1]]), ValueError, r"points\[1\]: expected 3 numbers"),
        (lambda: tumble.Compound([]), ValueError, "children"),
        (lambda: tumble.Compound([tumble.Plane((0, 1, 0))]), ValueError, "children"),
        (lambda: tumble.Compound([(tumble.Sphere(1), (0, 0))]), ValueError, r"children\[0\].position"),
        (lambda: tumble.Compound([3]), TypeError, r"children\[0\]: expected a tumble shape"),
        (lambda: tumble.Plane((0, 0, 0)), ValueError, "normal: "),
        (lambda: tumble.TriMesh([[0, 0, 0], [1, 0, 0], [0, 0, 1]], [[0, 1, 5]]), ValueError, "indices"),
        (lambda: tumble.TriMesh([[0, 0, 0], [1, 0, 0], [0, 0, 1]], [[0, 1, -1]]), TypeError, r"indices\[0\]"),
        (lambda: tumble.HeightField([[0, 0], [0]]), ValueError, r"heights\[1\]: every row"),
        (lambda: tumble.HeightField([[0, 0], [0, 0]], scale=(1, 0, 1)), ValueError, "scale"),
        (lambda: tumble.World(gravity=(0, float("inf"), 0)), ValueError, "gravity: "),
        (lambda: tumble.World(integrator="rk5"), ValueError, "integrator: unknown integrator 'rk5'"),
        (lambda: tumble.World(solver="magic"), ValueError, "solver: unknown solver 'magic'"),
        (lambda: tumble.World(substeps=0), ValueError, "substeps: must be >= 1"),
        (lambda: tumble.World(contact_hertz=-1), ValueError, "contact_hertz: "),
        (lambda: tumble.World(length_unit=0), ValueError, "length_unit: "),
        (lambda: tumble.SolverSettings(iterations=-3), ValueError, "iterations: must be >= 1"),
        (lambda: tumble.World.from_scene("no/such/file.json"), ValueError, "scene: 'no/such/file.json' is neither"),
        (lambda: tumble.World.from_json('{"bodies": [{"shape": {"type": "sphere", "radius": -1}}]}'), ValueError, r"bodies\[0\].shape.radius: must be > 0"),
        (lambda: tumble.World.from_json('{"dt": 0}'), ValueError, "dt: must be > 0"),
        (lambda: tumble.World.from_json("{"), ValueError, "scene: invalid JSON"),
    ],
)
def test_construction_errors(make, error, message):
    with pytest.raises(error, match=f"^{message}"):
        make()


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        (dict(shape=tumble.Sphere(1), mass=-1.0), ValueError, "mass: must be > 0"),
        (dict(shape=tumble.Sphere(1), mass=1.0, density=2.0), ValueError, "density: cannot be given together with mass"),
        (dict(shape=tumble.Sphere(1), density=0.0), ValueError, "density: must be > 0"),
        (dict(shape="sphere"), TypeError, "shape: expected a tumble shape"),
        (dict(shape=tumble.Sphere(1), position=(0, 1)), ValueError, "position: expected 3 numbers"),
        (dict(shape=tumble.Sphere(1), position=(0, float("nan"), 0)), ValueError, "position: "),
        (dict(shape=tumble.Sphere(1), position="up"), TypeError, "position: expected 3 numbers"),
        (dict(shape=tumble.Sphere(1), orientation=(0, 0, 0, 0)), ValueError, "orientation: must be a non-zero quaternion"),
        (dict(shape=tumble.Sphere(1), orientation=(0, 0, 1)), ValueError, "orientation: expected a quaternion"),
        (dict(shape=tumble.Sphere(1), velocity=(0, float("inf"), 0)), ValueError, "velocity: "),
        (dict(shape=tumble.Sphere(1), angular_velocity=None, kind="flying"), ValueError, "kind: unknown body kind 'flying'"),
        (dict(shape=tumble.Sphere(1), name="ball"), ValueError, "name: a body named 'ball' already exists"),
        (dict(shape=tumble.Plane((0, 1, 0))), ValueError, "kind: a plane shape needs a static body"),
        (dict(shape=tumble.Sphere(1), inertia=(1, 1, 5)), ValueError, "inertia: "),
        (dict(shape=tumble.Sphere(1), inertia=[[1, 0, 0], [0, 1, 0]]), ValueError, "inertia: "),
        (dict(shape=tumble.Sphere(1), friction=-0.1), ValueError, "friction: "),
        (dict(shape=tumble.Sphere(1), restitution=2.0), ValueError, "restitution: must be <= 1"),
        (dict(shape=tumble.Sphere(1), rolling_resistance=-0.1), ValueError, "rolling_resistance: must be >= 0"),
        (dict(shape=tumble.Sphere(1), torsional_friction=float("nan")), ValueError, "torsional_friction: must be a finite number"),
        (dict(shape=tumble.Sphere(1), collision_group=-1), ValueError, "collision_group: "),
        (dict(shape=tumble.Sphere(1), collision_mask=2**40), ValueError, "collision_mask: "),
    ],
)
def test_add_body_errors(world, kwargs, error, message):
    shape = kwargs.pop("shape")
    with pytest.raises(error, match=f"^{message}"):
        world.add_body(shape, **kwargs)
    assert len(world) == 1


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda w: w.add_spring("ball", stiffness=1.0), ValueError, "world_point: a spring needs world_point or other"),
        (lambda w: w.add_spring("ball", stiffness=1.0, world_point=(0, 0, 0), other="ball"), ValueError, "other: cannot be given together"),
        (lambda w: w.add_spring("ball", stiffness=1.0, other="ball"), ValueError, "other: must be a different body"),
        (lambda w: w.add_spring("ball", stiffness=-1.0, world_point=(0, 0, 0)), ValueError, "stiffness: "),
        (lambda w: w.add_spring("bal", stiffness=1.0, world_point=(0, 0, 0)), ValueError, "body: no body named 'bal'"),
        (lambda w: w.add_spring(3, stiffness=1.0, world_point=(0, 0, 0)), TypeError, "body: expected a tumble.Body"),
        (lambda w: w.add_spring(tumble.World().add_body(tumble.Sphere(1)), stiffness=1.0, world_point=(0, 0, 0)), ValueError, "body: this body belongs to another world"),
        (lambda w: w.add_drag("ball", linear=-1.0), ValueError, "linear: "),
        (lambda w: w.add_force("ball", force=(1, 2)), ValueError, "force: expected 3 numbers"),
        (lambda w: w.add_force("ball", torque=(0, float("nan"), 0)), ValueError, "torque: "),
        (lambda w: w.step(0), ValueError, "dt: must be > 0"),
        (lambda w: w.step(-0.1), ValueError, "dt: must be > 0"),
        (lambda w: w.step(float("nan")), ValueError, "dt: "),
        (lambda w: w.simulate(1.0, 0.0), ValueError, "dt: must be > 0"),
        (lambda w: w.simulate(-1.0), ValueError, "duration: "),
        (lambda w: w.simulate(every=0), ValueError, "every: must be >= 1"),
        (lambda w: w.simulate(1.0, steps=3), ValueError, "steps: cannot be given together with duration"),
        (lambda w: w.simulate(1.0, 1e-12), ValueError, "duration: needs more than"),
        (lambda w: setattr(w, "positions", np.zeros((2, 3))), ValueError, r"positions: expected an array of shape \(1, 3\)"),
        (lambda w: setattr(w, "positions", [[0, float("nan"), 0]]), ValueError, r"positions\[0\]: must be finite"),
        (lambda w: setattr(w, "orientations", np.zeros((1, 4))), ValueError, r"orientations\[0\]: must be a non-zero quaternion"),
        (lambda w: setattr(w, "velocities", "fast"), TypeError, "velocities: expected an array"),
        (lambda w: setattr(w, "integrator", "leapfrog"), ValueError, "integrator: unknown integrator"),
        (lambda w: setattr(w, "gravity", (0, 1)), ValueError, "gravity: expected 3 numbers"),
        (lambda w: w.body("nobody"), KeyError, "no body named"),
        (lambda w: w.remove_body("nobody"), ValueError, "body: no body named"),
        (lambda w: w.cast_ray((0, 0, 0), (0, 0, 0)), ValueError, "direction: must be a non-zero"),
        (lambda w: w.cast_ray((0, 0, 0), (1, 0, 0), -1.0), ValueError, "max_t: must be >= 0"),
        (lambda w: w.cast_shape(tumble.Plane((0, 1, 0)), (0, 0, 0), (1, 0, 0)), ValueError, "shape: must be a convex shape"),
        (lambda w: w.query_aabb((1, 1, 1), (0, 0, 0)), ValueError, "upper: must be >= lower"),
        (lambda w: w.add_joint("weld", "ball"), ValueError, "kind: unknown joint type 'weld'"),
        (lambda w: w.add_joint("hinge", "ball", cone=0.3), TypeError, "cone: not an option of a hinge joint"),
        (lambda w: w.add_joint("fixed", "ball", limits=(0, 1)), TypeError, r"limits: not an option of a fixed joint \(its options: none\)"),
        (lambda w: w.add_joint("ball", "ball", stiffness=1.0), TypeError, r"stiffness: not an option of a ball joint \(its options: cone, twist\)"),
        (lambda w: w.add_joint("distance", "ball", min="short"), TypeError, "min: expected a number"),
        (lambda w: w.add_joint("hinge", "ball", limits=(1, -1)), ValueError, "limits: "),
        (lambda w: w.add_joint("hinge", "ball", motor=(1, 2)), TypeError, "motor: expected a tumble.Motor"),
        (lambda w: w.add_joint("hinge", "ball", motor=tumble.Motor(1.0, -2.0)), ValueError, "motor.max_force: "),
        (lambda w: w.add_joint("ball", "ball", other="ball"), ValueError, "other: must differ from body"),
        (lambda w: w.add_joint("hinge", "ball", axis=(0, 0, 0)), ValueError, "axis: must be a non-zero direction"),
        (lambda w: w.add_joint("distance", "ball", break_force=0.0), ValueError, "break_force: "),
        (lambda w: w.joint("nothing"), KeyError, "no joint named"),
        (lambda w: w.body("ball").apply_impulse((1, 0)), ValueError, "impulse: expected 3 numbers"),
        (lambda w: setattr(w.body("ball"), "orientation", (0, 0, 0, 0)), ValueError, "orientation: must be a non-zero"),
        (lambda w: setattr(w, "solver_settings", tumble.SolverSettings(kind="soft_step", contact_hertz=1.0)) or setattr(w, "dt", 0.0), ValueError, "dt: must be > 0"),
    ],
)
def test_call_errors(world, call, error, message):
    before = world.state_hash()
    with pytest.raises(error, match=message if error is KeyError else f"^{message}"):
        call(world)
    assert world.state_hash() == before


def test_bulk_set_is_all_or_nothing():
    w = tumble.World()
    for i in range(3):
        w.add_body(tumble.Sphere(0.1), position=(i, 0, 0))
    before = w.positions
    with pytest.raises(ValueError, match=r"^positions\[2\]"):
        w.positions = [[9, 9, 9], [9, 9, 9], [0, np.inf, 0]]
    np.testing.assert_array_equal(w.positions, before)


def test_removed_body_handle_errors():
    w = tumble.World()
    b = w.add_body(tumble.Sphere(0.1))
    w.remove_body(b)
    with pytest.raises(ValueError, match="^body: "):
        b.velocity = (1, 0, 0)
    with pytest.raises(ValueError, match="^body: this body was removed"):
        w.add_drag(b, linear=1.0)
    assert repr(b) == "<tumble.Body (removed)>"
