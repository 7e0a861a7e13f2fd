"""tumble.Batch (issue 20): W copies of a world stepped together equal W worlds stepped
alone, bit for bit, on 1 and 2 threads; per-world forces, joint targets and resets go to
the world named; arrays have the documented shapes and dtypes; bad input is refused with
the field named and nothing changed. Small W and short runs: this runs in CI."""

import numpy as np
import pytest

import tumble

CART_POLE = {
    "gravity": [0, 0, -9.81],
    "dt": 0.01,
    "sleep": False,
    "bodies": [
        {"name": "cart", "shape": {"type": "box", "half_extents": [0.2, 0.1, 0.05]}, "mass": 1.0},
        {
            "name": "pole",
            "shape": {"type": "box", "half_extents": [0.02, 0.02, 0.5]},
            "mass": 0.1,
            "position": [0, 0, 0.5],
        },
    ],
    "joints": [
        {
            "type": "slider",
            "name": "track",
            "body": "cart",
            "axis": [1, 0, 0],
            "motor": {"speed": 0.0, "max_force": 20.0},
        },
        {
            "type": "hinge",
            "name": "pivot",
            "body": "pole",
            "other": "cart",
            "anchor": [0, 0, -0.5],
            "axis": [0, 1, 0],
            "servo": {"target": 0.0, "stiffness": 5.0, "damping": 0.5, "max_torque": 10.0},
        },
    ],
}


def contact_scene():
    """Boxes and balls dropped, spinning, on the ground and on each other."""
    bodies = [{"kind": "static", "shape": {"type": "plane", "normal": [0, 1, 0], "offset": 0}}]
    for k in range(5):
        shape = (
            {"type": "box", "half_extents": [0.2, 0.1, 0.15]}
            if k % 2 == 0
            else {"type": "sphere", "radius": 0.12}
        )
        bodies.append(
            {
                "shape": shape,
                "position": [0.05 * k, 0.3 + 0.25 * k, 0],
                "angular_velocity": [0.5, 1.0 * k, 0.2],
            }
        )
    return {"dt": 1 / 60, "bodies": bodies}


SCENES = [
    (contact_scene(), 40),
    (CART_POLE, 50),
    (dict(CART_POLE, joint_trees="reduced"), 50),
    ("pendulum_chain", 40),
    ("ragdoll", 30),
]


def kicks(w, n, dynamic):
    """A different velocity for each world's dynamic bodies."""
    v = np.zeros((w, n, 3))
    for i in range(w):
        v[i, dynamic] = [0.1 * i, 0.05, -0.07 * i]
    return v


def world_of(scene):
    if isinstance(scene, dict):
        import json

        return tumble.World.from_json(json.dumps(scene))
    return tumble.World.from_scene(scene)


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize(
    "scene,steps", SCENES, ids=["contacts", "cart_pole", "cart_pole_reduced", "chain", "ragdoll"]
)
def test_copies_equal_separate_worlds_bit_for_bit(scene, steps, threads):
    w = 3
    batch = tumble.Batch(scene, copies=w, threads=threads)
    alone = [world_of(scene) for _ in range(w)]
    dynamic = [b.kind == "dynamic" for b in alone[0].bodies]
    v = kicks(w, len(alone[0]), dynamic) + batch.velocities
    batch.velocities = v
    for i, world in enumerate(alone):
        world.velocities = v[i]
        world.step(batch.dt, steps=steps)
    batch.step(steps=steps // 2)
    batch.step(steps=steps - steps // 2)
    for i, world in enumerate(alone):
        # == on every number: the batch's step is the world's own, not an approximation.
        assert np.array_equal(batch.positions[i], world.positions), i
        assert np.array_equal(batch.orientations[i], world.orientations), i
        assert np.array_equal(batch.velocities[i], world.velocities), i
        assert np.array_equal(batch.angular_velocities[i], world.angular_velocities), i
        assert batch.world(i).state_hash() == world.state_hash()
    # The kicks differ, so the worlds do: not W copies of one run.
    assert not np.array_equal(batch.positions[0], batch.positions[1])
    assert batch.step_counts == [steps] * w


def test_shapes_and_dtypes():
    batch = tumble.Batch(CART_POLE, copies=4, threads=1)
    assert len(batch) == batch.copies == 4
    assert batch.body_names == ["cart", "pole"]
    assert batch.body_index("pole") == 1
    for name, width in [
        ("positions", 3),
        ("orientations", 4),
        ("velocities", 3),
        ("angular_velocities", 3),
    ]:
        a = getattr(batch, name)
        assert a.shape == (4, 2, width) and a.dtype == np.float64, name
    np.testing.assert_array_equal(batch.orientations[:, :, 3], 1.0)
    assert batch.time.shape == (4,) and batch.dt == 0.01
    traj = batch.simulate(steps=10, every=4)
    # Step 0, 4, 8 and the last (10), as World.simulate records.
    assert traj.position.shape == (4, 4, 2, 3)
    assert traj.orientation.shape == (4, 4, 2, 4)
    assert traj.velocity.shape == traj.angular_velocity.shape == (4, 4, 2, 3)
    np.testing.assert_allclose(traj.time, [0, 0.04, 0.08, 0.1])
    np.testing.assert_array_equal(traj.position[-1], batch.positions)
    assert traj.names == ["cart", "pole"]
    np.testing.assert_allclose(batch.time, 0.1)


def test_simulate_records_what_a_world_records():
    batch = tumble.Batch("pendulum_chain", copies=2, threads=2)
    world = tumble.World.from_scene("pendulum_chain")
    a = batch.simulate(duration=0.105, dt=0.01, every=3)
    b = world.simulate(duration=0.105, dt=0.01, every=3)
    np.testing.assert_array_equal(a.time, b.time)
    for i in range(2):
        assert np.array_equal(a.position[:, i], b.position)
        assert np.array_equal(a.angular_velocity[:, i], b.angular_velocity)


@pytest.mark.parametrize("threads", [1, 2])
def test_many_worlds_recorded_in_blocks_equal_worlds_recorded_alone(threads):
    # More worlds than one block (8 a thread) and a run long enough for the loop's chunk
    # of steps to grow: each world takes a chunk's steps in a row, and its frames must
    # land in the right (frame, world) rows, the cut last step included.
    w, every, duration = 37, 7, 2.005
    batch = tumble.Batch(CART_POLE, copies=w, threads=threads)
    v = batch.velocities
    v[:, :, 0] += np.linspace(-0.5, 0.5, w)[:, None]
    batch.velocities = v
    traj = batch.simulate(duration=duration, dt=0.01, every=every)
    assert traj.position.shape == (201 // every + 2, w, 2, 3)
    for i in [0, 1, 15, 16, 17, 31, 32, 36]:
        world = world_of(CART_POLE)
        world.velocities = v[i]
        alone = world.simulate(duration=duration, dt=0.01, every=every)
        np.testing.assert_array_equal(traj.time, alone.time)
        assert np.array_equal(traj.position[:, i], alone.position), i
        assert np.array_equal(traj.orientation[:, i], alone.orientation), i
        assert np.array_equal(traj.velocity[:, i], alone.velocity), i
        assert np.array_equal(traj.angular_velocity[:, i], alone.angular_velocity), i
        assert np.array_equal(batch.positions[i], world.positions), i
    assert batch.step_counts == [201] * w


@pytest.mark.parametrize("mass,dt,steps", [(2.0, 0.01, 50), (0.3, 1 / 240, 120)])
def test_a_force_on_world_two_moves_world_two_only(mass, dt, steps):
    # Constant F on a free body, no gravity: Δv = F t / m exactly up to one rounding per
    # step (1e-12 relative); the other worlds stay exactly at rest.
    world = tumble.World(gravity=(0, 0, 0))
    world.add_body(tumble.Sphere(0.1), mass=mass, name="ball")
    batch = tumble.Batch(world, copies=4, threads=2)
    forces = np.zeros((4, 1, 3))
    forces[2, 0] = [3.0, -1.0, 0.5]
    batch.apply_forces(forces)
    batch.step(dt, steps=steps)
    v = batch.velocities
    np.testing.assert_allclose(v[2, 0], forces[2, 0] * dt * steps / mass, rtol=1e-12)
    assert not v[[0, 1, 3]].any()
    # The forces persist until cleared (as World.add_force's): another run doubles Δv.
    batch.step(dt, steps=steps)
    np.testing.assert_allclose(batch.velocities[2, 0], 2 * v[2, 0], rtol=1e-12)
    batch.clear_forces()
    before = batch.velocities
    batch.step(dt, steps=5)
    np.testing.assert_array_equal(batch.velocities, before)


def test_joint_targets_go_to_their_worlds():
    batch = tumble.Batch(CART_POLE, copies=3, threads=2)
    # The track's motor drives the cart at its speed (max_force 20 N is ample for 1.1 kg
    # brought to 1 m/s in 0.5 s); each world's cart at its own speed, to 1 %: the motor
    # row is soft and the pole swinging on the cart pulls at it.
    speeds = np.array([0.5, -1.0, 0.0])
    batch.set_joint_targets("track", speeds)
    batch.set_joint_targets("pivot", np.array([0.0, 0.2, -0.2]))
    batch.step(steps=50)
    np.testing.assert_allclose(batch.velocities[:, 0, 0], speeds, atol=0.01)
    # Same targets in a lone world through its own Joint API: the same bits.
    world = world_of(CART_POLE)
    world.joint("track").motor = tumble.Motor(speed=-1.0, max_force=20.0)
    world.joint("pivot").servo = tumble.Servo(target=0.2, stiffness=5.0, damping=0.5, max_force=10.0)
    world.step(0.01, steps=50)
    assert np.array_equal(batch.positions[1], world.positions)


def test_reset_world_one_mid_run_matches_a_fresh_world():
    scene = contact_scene()
    batch = tumble.Batch(scene, copies=3, threads=2)
    batch.step(steps=25)
    keep = batch.positions
    batch.reset(worlds=[1])
    assert batch.step_counts == [25, 0, 25]
    assert np.array_equal(batch.positions[[0, 2]], keep[[0, 2]])
    batch.step(steps=15)
    fresh = world_of(scene)
    fresh.step(1 / 60, steps=15)
    assert np.array_equal(batch.positions[1], fresh.positions)
    assert np.array_equal(batch.velocities[1], fresh.velocities)
    # From a snapshot: world 2 continues as world 0.
    batch.reset(worlds=[2], snapshot=batch.snapshot(0))
    batch.step(steps=5)
    assert np.array_equal(batch.positions[2], batch.positions[0])
    # With states: the given velocities in the worlds reset, the others untouched.
    others = batch.velocities[0]
    v = np.zeros((2, 6, 3))
    v[:, 1:] = [1.0, 2.0, 0.0]
    batch.reset(worlds=[1, 2], velocities=v)
    np.testing.assert_array_equal(batch.velocities[1:], v)
    np.testing.assert_array_equal(batch.velocities[0], others)


def test_randomize_is_reproducible_and_perturbs_dynamic_bodies_only():
    scene = contact_scene()
    a = tumble.Batch(scene, copies=4, threads=1)
    b = tumble.Batch(scene, copies=4, threads=2)
    a.randomize(np.random.default_rng(7), positions=0.01, velocities=0.5)
    b.randomize(np.random.default_rng(7), positions=0.01, velocities=0.5)
    assert np.array_equal(a.positions, b.positions)
    start = world_of(scene).positions
    moved = a.positions - start
    assert not moved[:, 0].any(), "the static ground was moved"
    assert 0 < np.abs(moved[:, 1:]).max() <= 0.01
    assert not np.array_equal(a.velocities[0], a.velocities[1])
    a.step(steps=20)
    b.step(steps=20)
    assert np.array_equal(a.positions, b.positions)
    c = tumble.Batch(scene, copies=4, threads=1)
    c.randomize(np.random.default_rng(8), positions=0.01, velocities=0.5)
    assert not np.array_equal(c.velocities, b.velocities)


@pytest.mark.parametrize("kick", [0.01, 0.3])
def test_randomised_ragdolls_fall_down_the_stairs_without_blowing_up(kick):
    # Eight copies of the built-in ragdoll, each body kicked by up to `kick` m/s: before the
    # solver turned its bodies' inertia with them, most such runs reached the 10,000 m/s
    # speed limit within a second (the step raised). A 3.75 m fall gives 8.6 m/s; 25 m/s
    # leaves room for a whipped limb (see the Rust test of the same scene).
    batch = tumble.Batch("ragdoll", copies=8, threads=2)
    batch.randomize(np.random.default_rng(1), velocities=kick)
    for _ in range(30):
        batch.step(steps=10)
        speeds = np.linalg.norm(batch.velocities, axis=-1)
        assert np.isfinite(batch.positions).all()
        assert speeds.max() < 25.0, f"a body reached {speeds.max():.1f} m/s"


def test_setting_arrays_wakes_and_moves_the_bodies():
    scene = contact_scene()
    batch = tumble.Batch(scene, copies=2, threads=1)
    batch.step(steps=300)  # landed; most bodies resting
    p = batch.positions
    p[1, 3, 1] += 1.0
    batch.positions = p
    batch.step(steps=10)
    assert batch.positions[1, 3, 1] < p[1, 3, 1], "world 1's lifted body did not fall"
    # World 0 was given its own positions back: as a lone world given them.
    world = world_of(scene)
    world.step(1 / 60, steps=300)
    world.positions = p[0]
    world.step(1 / 60, steps=10)
    assert np.array_equal(batch.positions[0], world.positions)


def test_bad_input_is_refused_naming_the_field_and_changes_nothing():
    batch = tumble.Batch(CART_POLE, copies=2, threads=1)
    start = (batch.positions, batch.velocities)
    cases = [
        (TypeError, "copies: expected an int", lambda: tumble.Batch(CART_POLE, copies=2.0)),
        (TypeError, "copies: expected an int", lambda: tumble.Batch(CART_POLE, copies=True)),
        (ValueError, "copies: must be >= 1, got 0", lambda: tumble.Batch(CART_POLE, copies=0)),
        (ValueError, "threads: must be between 1 and", lambda: tumble.Batch(CART_POLE, 2, threads=0)),
        (ValueError, "is neither a built-in scene", lambda: tumble.Batch("no_such_scene", 2)),
        (TypeError, "scene: expected a tumble.World", lambda: tumble.Batch(3, 2)),
        (ValueError, "positions: expected an array of shape (2, 2, 3)", lambda: setattr(batch, "positions", np.zeros((2, 3)))),
        (ValueError, "orientations: expected an array of shape (2, 2, 4)", lambda: setattr(batch, "orientations", np.zeros((2, 2, 3)))),
        (ValueError, "worlds[1].velocities[0]: must be", lambda: setattr(batch, "velocities", np.array([[[0, 0, 0]] * 2, [[np.nan, 0, 0], [0, 0, 0]]]))),
        (TypeError, "positions: expected an array of shape (2, 2, 3) of real numbers, got complex", lambda: setattr(batch, "positions", np.zeros((2, 2, 3), complex))),
        (ValueError, "forces: expected an array of shape (2, 2, 3)", lambda: batch.apply_forces(np.zeros((2, 3)))),
        (ValueError, "worlds[0].forces[1]: ", lambda: batch.apply_forces(np.array([[[0, 0, 0], [np.inf, 0, 0]]] * 2))),
        (ValueError, "name: no joint named 'hinge'", lambda: batch.set_joint_targets("hinge", [0.0, 0.0])),
        (ValueError, "values: expected an array of shape (2,)", lambda: batch.set_joint_targets("track", [0.0])),
        (ValueError, "values[1]: must be a finite number", lambda: batch.set_joint_targets("track", [0.0, np.nan])),
        (ValueError, "kind: expected 'velocity'", lambda: batch.set_joint_targets("track", [0, 0], kind="force")),
        (ValueError, "worlds[0]: index 2 out of range for a batch of 2 worlds", lambda: batch.reset(worlds=[2])),
        (ValueError, "worlds[0]: must be >= 0", lambda: batch.reset(worlds=[-1])),
        (ValueError, "velocities: expected an array of shape (1, 2, 3)", lambda: batch.reset(worlds=[0], velocities=np.zeros((2, 2, 3)))),
        (ValueError, "snapshot: holds 0 bodies, not the 2", lambda: batch.reset(snapshot=tumble.World().snapshot())),
        (ValueError, "snapshot:", lambda: batch.reset(snapshot=b"garbage")),
        (ValueError, "dt:", lambda: batch.step(-0.01)),
        (TypeError, "steps: expected an int", lambda: batch.step(steps=1.5)),
        (ValueError, "every: must be >= 1", lambda: batch.simulate(steps=3, every=0)),
        (ValueError, "world: index 5 out of range", lambda: batch.world(5)),
        (ValueError, "world: index -1 out of range", lambda: batch.snapshot(-1)),
        (TypeError, "rng: expected a numpy.random.Generator", lambda: batch.randomize(7)),
        (ValueError, "velocities: must be a finite number >= 0", lambda: batch.randomize(np.random.default_rng(), velocities=-1.0)),
    ]
    for kind, text, call in cases:
        with pytest.raises(kind) as e:
            call()
        assert str(e.value).startswith(text) or text in str(e.value), (text, str(e.value))
    with pytest.raises(KeyError):
        batch.body_index("nobody")
    assert np.array_equal(batch.positions, start[0])
    assert np.array_equal(batch.velocities, start[1])
    assert batch.step_counts == [0, 0]


def test_a_world_with_a_callback_is_refused_and_a_failed_world_is_named():
    world = tumble.World(gravity=(0, 0, 0))
    world.add_body(tumble.Sphere(0.1), mass=1.0)
    world.add_force_callback(lambda ctx: None)
    with pytest.raises(ValueError, match="force callbacks"):
        tumble.Batch(world, copies=2)
    world = tumble.World(gravity=(0, 0, 0))
    world.add_body(tumble.Sphere(0.1), mass=1.0)
    batch = tumble.Batch(world, copies=3, threads=2)
    forces = np.zeros((3, 1, 3))
    forces[1, 0, 0] = 1e9  # past the speed limit within a few steps
    batch.apply_forces(forces)
    with pytest.raises(tumble.SimulationError) as e:
        batch.simulate(steps=20, dt=0.01, every=1)
    assert str(e.value).startswith("worlds[1]: step ")
    assert e.value.world == 1 and e.value.quantity == "velocity"
    traj = e.value.trajectory
    assert traj.position.shape[1:] == (3, 1, 3)
    # The frames kept are whole: every world's row written (no zero quaternion), up to
    # a step every world reached.
    frames = len(traj.time)
    assert traj.orientation.shape[0] == frames >= 1
    assert np.all(np.abs(np.linalg.norm(traj.orientation, axis=-1) - 1) < 1e-12)
    assert np.all(traj.position[:, 1, 0, 0] >= 0)
    counts = batch.step_counts
    assert counts[0] == counts[2] and counts[1] < counts[0]


def test_step_releases_the_interpreter():
    # Another Python thread runs while the batch steps: if the interpreter's lock were
    # held for the call, the loop below could not count during it.
    import threading

    batch = tumble.Batch("ragdoll", copies=4, threads=1)
    done = threading.Event()

    def run():
        batch.step(steps=300)
        done.set()

    thread = threading.Thread(target=run)
    thread.start()
    count = 0
    while not done.is_set():
        count += 1
    thread.join()
    assert count > 1000
    assert batch.step_counts == [300] * 4


@pytest.mark.parametrize("steps,every", [(5, 10), (10, 5), (0, 1), (7, 7)])
def test_recording_edges_empty_worlds_and_runs_shorter_than_every(steps, every):
    # A world without bodies records its (empty) rows; a run shorter than `every` keeps
    # step 0 and the last; a run of 0 steps keeps step 0 only.
    empty = tumble.Batch(tumble.World(), copies=3, threads=2)
    traj = empty.simulate(steps=steps, dt=0.01, every=every)
    frames = steps // every + 1 + (steps % every != 0)
    assert traj.position.shape == (frames, 3, 0, 3)
    assert traj.orientation.shape == (frames, 3, 0, 4)
    batch = tumble.Batch(CART_POLE, copies=3, threads=2)
    world = world_of(CART_POLE)
    a = batch.simulate(steps=steps, dt=0.01, every=every)
    b = world.simulate(steps=steps, dt=0.01, every=every)
    assert a.position.shape == (frames, 3, 2, 3)
    np.testing.assert_array_equal(a.time, b.time)
    for i in range(3):
        assert np.array_equal(a.position[:, i], b.position)
        assert np.array_equal(a.orientation[:, i], b.orientation)
        assert np.array_equal(a.velocity[:, i], b.velocity)


@pytest.mark.parametrize("threads,every", [(1, 1), (2, 3)])
def test_simulate_into_out_overwrites_its_arrays_with_the_same_frames(threads, every):
    # A recording into an earlier run's arrays equals a fresh one bit for bit, and is
    # that trajectory (the same array objects), so a loop of rollouts allocates nothing.
    def batch():
        b = tumble.Batch(CART_POLE, copies=19, threads=threads)
        b.randomize(np.random.default_rng(4), velocities=0.3)
        return b

    fresh = batch().simulate(steps=41, dt=0.01, every=every)
    out = batch().simulate(steps=41, dt=0.005, every=every)  # other numbers, same shapes
    arrays = [out.time, out.position, out.orientation, out.velocity, out.angular_velocity]
    again = batch().simulate(steps=41, dt=0.01, every=every, out=out)
    assert again is out
    # Stored world by world (each world's frames one run of memory), seen as (T, W, ...).
    assert fresh.position.shape == (41 // every + 1 + (41 % every != 0), 19, 2, 3)
    assert fresh.position.swapaxes(0, 1).flags.c_contiguous
    for name, a in zip(["time", "position", "orientation", "velocity"], arrays):
        assert getattr(again, name) is a
        assert np.array_equal(a, getattr(fresh, name)), name
    assert np.array_equal(again.angular_velocity, fresh.angular_velocity)


def test_simulate_into_out_refuses_arrays_of_another_run():
    batch = tumble.Batch(CART_POLE, copies=3)
    out = batch.simulate(steps=10, dt=0.01)
    world = world_of(CART_POLE)
    for kwargs, error, text in [
        ({"steps": 5}, ValueError, "out.time: must be a writable float64 array of shape "
         "(6,), laid out as Batch.simulate makes it, for the frames this run records; got "
         "shape (11,)"),
        ({"steps": 10, "every": 2}, ValueError, "out.time: must be a writable"),
        ({"steps": 10, "out": world.simulate(steps=10, dt=0.01)}, ValueError,
         "out.position: must be a writable float64 array of shape (11, 3, 2, 3), laid "
         "out as Batch.simulate makes it, for the frames this run records; got shape "
         "(11, 2, 3)"),
        ({"steps": 10, "out": {"time": 1}}, TypeError,
         "out: expected a tumble.Trajectory from Batch.simulate, got dict"),
    ]:
        kwargs.setdefault("out", out)
        with pytest.raises(error) as e:
            batch.simulate(dt=0.01, **kwargs)
        assert str(e.value).startswith(text), str(e.value)
    assert batch.step_counts == [10] * 3  # nothing ran
    out.velocity.flags.writeable = False
    with pytest.raises(ValueError, match="out.velocity: .* got an array that is read-only"):
        batch.simulate(steps=10, dt=0.01, out=out)
    assert batch.step_counts == [10] * 3


def test_a_failed_run_into_out_reports_the_frames_before_it():
    world = tumble.World(gravity=(0, 0, 0))
    world.add_body(tumble.Sphere(0.1), mass=1.0)
    batch = tumble.Batch(world, copies=3, threads=2)
    out = batch.simulate(steps=20, dt=0.01)
    forces = np.zeros((3, 1, 3))
    forces[1, 0, 0] = 1e9  # past the speed limit within a few steps
    batch.apply_forces(forces)
    with pytest.raises(tumble.SimulationError) as fresh:
        batch.simulate(steps=20, dt=0.01)
    batch.reset()
    batch.simulate(steps=20, dt=0.01, out=out)
    batch.reset()
    batch.apply_forces(forces)
    with pytest.raises(tumble.SimulationError) as into:
        batch.simulate(steps=20, dt=0.01, out=out)
    a, b = fresh.value.trajectory, into.value.trajectory
    assert 1 <= len(b.time) < 21 and b.position.shape == a.position.shape
    assert np.shares_memory(b.position, out.position)
    # The failed run's frames are views of part of out: not a layout a run writes into.
    batch.reset()
    with pytest.raises(ValueError, match=r"out.position: .* got an array laid out otherwise"):
        batch.simulate(steps=len(b.time) - 1, dt=0.01, out=b)
    for name in ["time", "position", "orientation", "velocity", "angular_velocity"]:
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
