"""Array shapes and dtypes, bulk round trips, handles, names, scenes, queries, joints."""

import threading
import time

import numpy as np
import pytest

import tumble


def grid_world(n=4):
    world = tumble.World(gravity=(0, 0, 0))
    for i in range(n):
        world.add_body(tumble.Sphere(0.1), mass=1.0 + i, position=(i, 0, 0), name=f"b{i}")
    return world


def test_issue_example_runs():
    world = tumble.World(gravity=(0, -9.8, 0), integrator="velocity_verlet")
    ball = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(0, 5, 0))
    world.add_spring(ball, world_point=(0, 6, 0), stiffness=100.0, rest_length=0.5)
    world.step(0.01)
    for value, shape in [
        (ball.position, (3,)),
        (ball.orientation, (4,)),
        (ball.velocity, (3,)),
        (ball.angular_velocity, (3,)),
        (ball.angular_momentum, (3,)),
    ]:
        assert value.shape == shape and value.dtype == np.float64
    assert world.time == pytest.approx(0.01) and world.step_count == 1
    d = world.diagnostics()
    assert d.total == pytest.approx(d.kinetic + d.potential)
    assert d.linear_momentum.shape == (3,) and d.angular_momentum.shape == (3,)


def test_trajectory_shapes_and_every():
    world = grid_world(3)
    traj = world.simulate(duration=0.1, dt=0.01, every=3)
    # Steps 0, 3, 6, 9 and the last, 10.
    np.testing.assert_allclose(traj.time, [0, 0.03, 0.06, 0.09, 0.1])
    assert traj.position.shape == (5, 3, 3) and traj.orientation.shape == (5, 3, 4)
    assert traj.velocity.shape == (5, 3, 3) and traj.angular_velocity.shape == (5, 3, 3)
    for a in (traj.time, traj.position, traj.orientation):
        assert a.dtype == np.float64 and a.flags["C_CONTIGUOUS"]
    assert traj.kinetic is None and len(traj) == 5
    assert traj.names == ["b0", "b1", "b2"]
    d = world.simulate(steps=4, dt=0.01, diagnostics=True)
    assert d.kinetic.shape == (5,) and d.angular_momentum.shape == (5, 3)
    np.testing.assert_allclose(d.time, 0.1 + 0.01 * np.arange(5))


def test_simulate_cuts_the_last_step_like_the_cli():
    world = grid_world(1)
    traj = world.simulate(duration=0.055, dt=0.01)
    assert len(traj.time) == 7 and traj.time[-1] == pytest.approx(0.055)
    assert world.time == pytest.approx(0.055)


def test_bulk_round_trips():
    world = grid_world(4)
    rng = np.random.default_rng(1)
    p = rng.normal(size=(4, 3))
    world.positions = p
    np.testing.assert_array_equal(world.positions, p)
    q = rng.normal(size=(4, 4))
    world.orientations = q
    np.testing.assert_allclose(world.orientations, q / np.linalg.norm(q, axis=1, keepdims=True), atol=1e-15)
    # Turning keeps each frame's origin where it was.
    np.testing.assert_allclose(world.positions, p, atol=1e-15)
    v = rng.normal(size=(4, 3))
    w = rng.normal(size=(4, 3))
    world.set_state(velocities=v, angular_velocities=w)
    np.testing.assert_array_equal(world.velocities, v)
    # omega goes in, L = I omega is stored, omega = I^-1 L comes out: equal to rounding.
    np.testing.assert_allclose(world.angular_velocities, w, atol=1e-14)
    assert world.positions.dtype == np.float64 and world.orientations.shape == (4, 4)
    assert world.angular_momenta.shape == (4, 3)
    # Lists and integer arrays are converted.
    world.positions = [[0, 0, 0]] * 4
    assert np.all(world.positions == 0)


def test_body_handles_and_names():
    world = grid_world(3)
    b1 = world.body("b1")
    assert b1 == world.bodies[1] and hash(b1) == hash(world.bodies[1])
    assert b1.name == "b1" and b1.mass == pytest.approx(2.0) and b1.kind == "dynamic"
    assert world.body_names == ["b0", "b1", "b2"] and len(world) == 3
    b1.position = (0, 1, 2)
    b1.velocity = (1, 0, 0)
    np.testing.assert_array_equal(b1.position, [0, 1, 2])
    np.testing.assert_array_equal(world.velocities[1], [1, 0, 0])
    b1.apply_impulse((0, 2, 0))
    assert b1.velocity[1] == pytest.approx(1.0)
    world.remove_body("b0")
    assert len(world) == 2 and world.bodies[0] == b1
    assert b1.alive
    world.remove_body(b1)
    assert not b1.alive
    with pytest.raises(ValueError, match="body"):
        _ = b1.position


def test_every_shape_and_mass():
    world = tumble.World()
    hull = tumble.ConvexHull([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    shapes = [
        tumble.Sphere(0.5),
        tumble.Box((0.5, 0.5, 0.5)),
        tumble.Capsule(0.2, 0.5),
        tumble.Cylinder(0.2, 0.5),
        hull,
        tumble.Compound([tumble.Sphere(0.1), (tumble.Box((0.1, 0.1, 0.1)), (1, 0, 0)), (hull, (0, 1, 0), (0, 0, 0, 1))]),
    ]
    for i, s in enumerate(shapes):
        b = world.add_body(s, density=1000.0, position=(3 * i, 5, 0))
        assert b.mass == pytest.approx(1000.0 * s.volume)
        assert b.shape_kind == s.kind
    assert tumble.Box((0.5, 0.5, 0.5)).volume == pytest.approx(1.0)
    assert shapes[0].volume == pytest.approx(4 / 3 * np.pi * 0.125)
    for s in (
        tumble.Plane((0, 1, 0), -1.0),
        tumble.TriMesh([[0, 0, 0], [1, 0, 0], [0, 0, -1]], [[0, 1, 2]]),
        tumble.HeightField(np.zeros((3, 4)), scale=(1, 1, 1)),
    ):
        world.add_body(s, kind="static")
    assert isinstance(shapes[0], tumble.Shape) and repr(shapes[0]) == "tumble.Sphere(0.5)"
    inertia = world.add_body(tumble.Sphere(1), mass=1.0, inertia=(1, 2, 2.5)).inertia
    np.testing.assert_allclose(inertia, np.diag([1, 2, 2.5]))


def test_from_scene_and_json(root):
    world = tumble.World.from_scene(str(root / "scenes" / "spring.json"))
    assert world.dt == pytest.approx(0.01)
    builtin = tumble.World.from_scene("dzhanibekov")
    assert builtin.body_names and "dzhanibekov" in tumble.SCENES
    assert builtin.gravity.tolist() == [0, 0, 0]
    j = tumble.World.from_json('{"dt": 0.5, "duration": 2, "bodies": [{"name": "a", "shape": {"type": "sphere", "radius": 1}}]}')
    traj = j.simulate()
    assert len(traj.time) == 5 and j.body("a").name == "a"
    joints = tumble.World.from_scene("door")
    assert joints.joints and joints.joints[0].kind in ("hinge", "ball", "slider", "fixed", "distance")


def test_settings_properties():
    world = tumble.World(integrator="rk4", solver="pgs", substeps=2, sleep=False)
    assert world.integrator == "rk4" and not world.sleep
    s = world.solver_settings
    assert s.kind == "pgs" and s.substeps == 2
    s.substeps = 8
    world.solver_settings = s
    assert world.solver_settings.substeps == 8
    world.integrator = "midpoint"
    world.gravity = (0, 0, -1)
    assert world.integrator == "midpoint" and world.gravity.tolist() == [0, 0, -1]
    assert set(tumble.INTEGRATORS) == {
        "explicit_euler", "symplectic_euler", "implicit_euler", "midpoint", "rk4", "verlet", "velocity_verlet",
    }
    assert world.state_hash() == tumble.World().state_hash()


def test_queries():
    world = tumble.World(gravity=(0, 0, 0))
    a = world.add_body(tumble.Sphere(0.5), position=(0, 0, 0), name="a")
    b = world.add_body(tumble.Box((0.5, 0.5, 0.5)), position=(3, 0, 0), name="b", collision_group=2)
    hit = world.cast_ray((-5, 0, 0), (1, 0, 0))
    assert hit.body == a and hit.t == pytest.approx(4.5) and hit.normal.tolist() == pytest.approx([-1, 0, 0])
    np.testing.assert_allclose(hit.point, [-0.5, 0, 0], atol=1e-12)
    hits = world.cast_ray_all((-5, 0, 0), (1, 0, 0))
    assert [h.body for h in hits] == [a, b] and hits[1].t == pytest.approx(7.5)
    assert world.cast_ray((-5, 0, 0), (1, 0, 0), 4.0) is None
    assert world.cast_ray((-5, 0, 0), (1, 0, 0), exclude="a").body == b
    assert world.cast_ray((-5, 0, 0), (1, 0, 0), mask=2).body == b
    sh = world.cast_shape(tumble.Sphere(0.5), (-5, 0, 0), (10, 0, 0))
    assert sh.body == a and sh.t == pytest.approx(0.4, abs=1e-6)
    assert world.query_point((3.2, 0.1, 0)) == [b]
    assert world.query_aabb((-1, -1, -1), (10, 1, 1)) == [a, b]


def test_contacts_and_events():
    world = tumble.World()
    ground = world.add_body(tumble.Plane((0, 1, 0)), kind="static")
    box = world.add_body(tumble.Box((0.5, 0.5, 0.5)), mass=1.0, position=(0, 0.6, 0))
    begun = []
    for _ in range(60):
        world.step(1 / 60)
        begun += [(e.kind, e.body_a, e.body_b) for e in world.contact_events()]
    assert begun[0] == ("begin", ground, box)
    contacts = world.contacts()
    assert len(contacts) == 1 and len(contacts[0].points) == 4
    np.testing.assert_allclose(contacts[0].normal, [0, 1, 0], atol=1e-9)
    assert contacts[0].points[0].position.shape == (3,)
    assert world.update_contacts()[0].body_b == box


def test_joint_handles():
    world = tumble.World()
    a = world.add_body(tumble.Box((0.1, 0.1, 0.1)), mass=1.0, name="a")
    b = world.add_body(tumble.Box((0.1, 0.1, 0.1)), mass=1.0, position=(1, 0, 0), name="b")
    j = world.add_joint("ball", a, "b", anchor=(0.5, 0, 0), cone=0.5, name="j")
    world.add_joint("slider", b, axis=(0, 1, 0), limits=(-1, 1), spring=tumble.JointSpring(2.0))
    assert world.joint("j") == j and j.kind == "ball" and j.body == a and j.other == b
    world.step(0.01)
    assert j.reaction_force.shape == (3,) and not j.broken
    assert len(world.joints) == 2
    assert world.remove_joint(j) and not j.alive and len(world.joints) == 1
    # The handle stays dead when a new joint takes its slot.
    k = world.add_joint("fixed", a)
    assert not world.remove_joint(j) and not j.alive and k.alive and k != j


def test_simulate_releases_the_interpreter():
    # While simulate runs in another thread this thread keeps counting: with the lock held
    # for the whole run it could not run at all until the run ends.
    world = tumble.World()
    for i in range(300):
        world.add_body(tumble.Sphere(0.1), mass=1.0, position=(i, 0, 0))
    done = threading.Event()
    started = threading.Event()

    def run():
        started.set()
        try:
            world.simulate(steps=3000, dt=0.001)
        finally:
            done.set()

    thread = threading.Thread(target=run)
    t0 = time.perf_counter()
    thread.start()
    started.wait()
    count = 0
    busy = False
    while not done.is_set():
        count += 1
        if not busy:
            # A read holds the world only while holding the interpreter, so it can never
            # make the run itself find the world busy.
            try:
                _ = world.time
            except RuntimeError as e:
                busy = "busy" in str(e)
    thread.join()
    assert time.perf_counter() - t0 > 0.05
    assert count > 1000
    assert busy


def test_every_public_name_has_a_docstring_and_a_stub(root):
    stub = (root / "crates/tumble-py/python/tumble/_tumble.pyi").read_text()
    for name in tumble.__all__:
        obj = getattr(tumble, name)
        if isinstance(obj, type):
            assert obj.__doc__, name
            assert f"class {name}" in stub, name
            for attr, value in vars(obj).items():
                if not attr.startswith("_"):
                    assert value.__doc__, f"{name}.{attr}"
                    assert f" {attr}" in stub, f"{name}.{attr}"
    assert (root / "crates/tumble-py/python/tumble/py.typed").exists()
