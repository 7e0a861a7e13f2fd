"""MJCF import against MuJoCo (the `mujoco` package): the same passive models in both,
joint angles compared over 1 s at a fine time step; dm_control suite models loaded and
run, their total masses equal to MuJoCo's; bad files as ValueError naming file:line."""

import importlib.util
import math
import pathlib
import warnings

import mujoco
import numpy as np
import pytest

import tumble

HERE = pathlib.Path(__file__).resolve().parent
SCENE_MODELS = HERE.parents[1] / "tumble-scene" / "tests" / "mjcf"
# The suite's XML files ship inside dm_control; found without importing it.
SUITE = pathlib.Path(importlib.util.find_spec("dm_control").origin).parent / "suite"

DT = 1e-4
DURATION = 1.0
SAMPLE = 100  # compare every 100 steps (0.01 s)


def mujoco_run(path, qpos0):
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.timestep = DT
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    data = mujoco.MjData(model)
    data.qpos[:] = qpos0
    mujoco.mj_forward(model, data)
    names = [model.joint(i).name for i in range(model.njnt)]
    out = []
    for k in range(1, int(round(DURATION / DT)) + 1):
        mujoco.mj_step(model, data)
        if k % SAMPLE == 0:
            out.append([data.qpos[model.jnt_qposadr[i]] for i in range(model.njnt)])
    return names, np.array(out)


def difference(ours, reference):
    """Largest difference, hinge angles as they are: Tumble's, as MuJoCo's qpos, count
    whole turns."""
    return np.abs(ours - reference).max()


def tumble_run(path, names, qpos0):
    world = tumble.World.from_mjcf(path)
    # MuJoCo's qpos joint by joint (ref is 0 in these files): parents first.
    for name, q in zip(names, qpos0):
        world.joint(name).position = float(q)
    joints = [world.joint(n) for n in names]
    out = []
    for k in range(1, int(round(DURATION / DT)) + 1):
        world.step(DT)
        if k % SAMPLE == 0:
            out.append([j.position for j in joints])
    return np.array(out)


@pytest.mark.parametrize(
    "path, qpos0",
    [
        # Hanging is +pi/2 at the shoulder (the links lie along x at qpos 0): 0.5 rad
        # from hanging, elbow bent 0.3 rad; not chaotic over 1 s at this energy.
        (SCENE_MODELS / "double_pendulum.xml", [math.pi / 2 - 0.5, 0.3]),
        (HERE / "mjcf" / "cartpole_hanging.xml", [0.0, 0.8]),
    ],
    ids=["double_pendulum", "cartpole"],
)
def test_passive_motion_matches_mujoco(path, qpos0):
    names, reference = mujoco_run(path, qpos0)
    ours = tumble_run(path, names, qpos0)
    worst = difference(ours, reference)
    print(f"{path.name}: largest joint difference {worst:.2e} over 1 s")
    # Both integrate the same equations at dt = 1e-4 s; what differs is MuJoCo's
    # generalized coordinates against Tumble's constraints (their drift and softness).
    assert worst < 1e-2, f"largest joint difference {worst} rad or m"
    # The motion is real: every joint moves by 5 times the tolerance or more.
    assert np.ptp(reference, axis=0).min() > 0.05


def test_a_body_with_several_joints_moves_as_in_mujoco():
    # A planar root (slide, slide, hinge) chained through light bodies, a sprung knee
    # swinging from 0.5 rad, gravity partly across the plane: the joints as MuJoCo's
    # and the bodies in their plane. Before the chain's hard rows were solved as one
    # block (solver/joint_chain.rs) the body left its plane by 2 cm in this second.
    path = HERE / "mjcf" / "planar_chain.xml"
    qpos0 = [0.0, 0.0, 0.3, 0.5]
    names, reference = mujoco_run(path, qpos0)
    with pytest.warns(UserWarning, match="several joints in one body"):
        world = tumble.World.from_mjcf(path)
    for name, q in zip(names, qpos0):
        world.joint(name).position = float(q)
    joints = [world.joint(n) for n in names]
    ours, off_plane = [], 0.0
    for k in range(1, int(round(DURATION / DT)) + 1):
        world.step(DT)
        off_plane = max(off_plane, *(abs(b.position[1]) for b in world.bodies))
        if k % SAMPLE == 0:
            ours.append([j.position for j in joints])
    worst = difference(np.array(ours), reference)
    print(f"planar_chain: largest joint difference {worst:.2e}, off the plane {off_plane:.1e} m")
    assert worst < 1e-2, f"largest joint difference {worst} rad or m"
    assert off_plane < 1e-4, f"left the plane by {off_plane} m"
    # The knee swings and the root turns and falls with it.
    assert np.ptp(reference[:, 3]) > 0.5 and np.ptp(reference[:, 2]) > 0.05


def test_a_sprung_limited_hip_of_three_hinges_swings_as_in_mujoco():
    # Three hinges in one body (dm_control's humanoid hips), with springs, ranges and a
    # damper: chained through light bodies, their drives solved within the chain's block
    # (solver/joint_chain.rs). Measured: within 1.8e-3 rad of MuJoCo over the second.
    path = HERE / "mjcf" / "hip_chain.xml"
    qpos0 = [0.4, -0.3, 0.2]
    names, reference = mujoco_run(path, qpos0)
    with pytest.warns(UserWarning, match="several joints in one body"):
        ours = tumble_run(path, names, qpos0)
    worst = difference(ours, reference)
    print(f"hip_chain: largest joint difference {worst:.2e} over 1 s")
    assert worst < 1e-2, f"largest joint difference {worst} rad"
    # Every hinge swings, by far more than the tolerance.
    assert np.ptp(reference, axis=0).min() > 0.2


@pytest.mark.parametrize(
    "path, qpos0, armature",
    [
        (SCENE_MODELS / "double_pendulum.xml", [math.pi / 2 - 0.5, 0.3], 0.05),
        (HERE / "mjcf" / "cartpole_hanging.xml", [0.0, 0.8], 0.5),
        (HERE / "mjcf" / "planar_chain.xml", [0.0, 0.0, 0.3, 0.5], 0.02),
        (HERE / "mjcf" / "hip_chain.xml", [0.4, -0.3, 0.2], 0.01),
    ],
    ids=["double_pendulum", "cartpole", "planar_chain", "hip_chain"],
)
def test_joint_armature_moves_as_in_mujoco(tmp_path, path, qpos0, armature):
    # Every joint of the model given MuJoCo's armature (rotor inertia on the coordinate):
    # the joints of one body, of a chain of bodies and of a world-held body, hinges and
    # slides, with limits and springs. Measured within 0.8e-3 to 3.4e-3 rad or m of
    # MuJoCo; without the armature MuJoCo's own runs differ from these by 0.22 to 1.4.
    text = path.read_text().replace("<joint ", f'<joint armature="{armature}" ')
    armed = tmp_path / path.name
    armed.write_text(text)
    names, reference = mujoco_run(armed, qpos0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # several joints in one body
        ours = tumble_run(armed, names, qpos0)
    worst = difference(ours, reference)
    print(f"{path.name} with armature {armature}: largest joint difference {worst:.2e}")
    assert worst < 1e-2, f"largest joint difference {worst} rad or m"
    # The armature matters here: MuJoCo without it ends far from MuJoCo with it.
    _, plain = mujoco_run(path, qpos0)
    assert difference(plain, reference) > 5e-2


def welded_to_world(model):
    return [model.body_weldid[i] == 0 for i in range(model.nbody)]


@pytest.mark.parametrize("name", ["pendulum", "cartpole", "acrobot", "finger", "reacher"])
def test_suite_models_load_run_and_weigh_what_mujoco_says(name):
    path = SUITE / f"{name}.xml"
    model = mujoco.MjModel.from_xml_path(str(path))
    moving = [
        model.body_mass[i] for i, w in enumerate(welded_to_world(model)) if not w
    ]
    world = tumble.World.from_mjcf(path)
    ours = sum(b.mass for b in world.bodies if b.kind == "dynamic")
    assert ours == pytest.approx(sum(moving), rel=1e-12)
    gravity_off = model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_GRAVITY
    expected = [0.0, 0.0, 0.0] if gravity_off else list(model.opt.gravity)
    assert world.gravity.tolist() == pytest.approx(expected)
    for j in range(model.njnt):
        joint = world.joint(model.joint(j).name)
        if joint.kind == "hinge":
            joint.position = 0.2  # off the upright (unstable) balance
    start = [b.position.copy() for b in world.bodies]
    world.step(float(model.opt.timestep), steps=int(round(1.0 / model.opt.timestep)))
    end = [b.position for b in world.bodies]
    assert all(np.isfinite(p).all() for p in end)
    if not gravity_off:
        assert any(np.abs(a - b).max() > 1e-3 for a, b in zip(start, end)), "nothing fell"


# Models with several joints in one body: Tumble adds a light body (1/1000 of the body's
# mass, taken out of the body's) per extra joint, so the totals are still MuJoCo's. dog's
# bones are 163 STL meshes whose volumes (MuJoCo's legacy mesh inertia) make most of its mass.
HEAVIER = ["ball_in_cup", "cheetah", "dog", "fish", "hopper", "humanoid", "humanoid_CMU",
           "manipulator", "point_mass", "quadruped", "stacker", "swimmer", "walker"]


@pytest.mark.parametrize("name", HEAVIER)
def test_every_other_suite_model_loads_and_runs(name):
    path = SUITE / f"{name}.xml"
    model = mujoco.MjModel.from_xml_path(str(path))
    moving = sum(m for m, w in zip(model.body_mass, welded_to_world(model)) if not w)
    with pytest.warns(UserWarning, match="several joints in one body"):
        world = tumble.World.from_mjcf(path)
    light = [b.mass for b in world.bodies if b.kind == "dynamic" and b.name is None]
    ours = sum(b.mass for b in world.bodies if b.kind == "dynamic")
    assert ours == pytest.approx(moving, rel=1e-12)
    assert 0 < sum(light) <= 3e-3 * moving
    world.step(float(model.opt.timestep), steps=int(round(1.0 / model.opt.timestep)))
    assert all(np.isfinite(b.position).all() for b in world.bodies)


def test_a_damped_suite_pendulum_matches_mujoco():
    """dm_control's pendulum: joint damping 0.1 N·m·s/rad (Tumble's servo damper)."""
    path = SUITE / "pendulum.xml"
    names, reference = mujoco_run(path, [1.0])
    ours = tumble_run(path, names, [1.0])
    worst = difference(ours, reference)
    print(f"suite pendulum: largest joint difference {worst:.2e} rad over 1 s")
    assert worst < 1e-2


def test_bad_files_raise_value_error_naming_file_and_line(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text('<mujoco>\n<worldbody>\n<geom size="-1"/>\n</worldbody>\n</mujoco>')
    with pytest.raises(ValueError, match=r"^bad\.xml:3: <geom>: size: must be > 0"):
        tumble.World.from_mjcf(bad)
    with pytest.raises(ValueError, match=r"^missing\.xml: cannot read"):
        tumble.World.from_mjcf(tmp_path / "missing.xml")


def test_unread_parts_come_out_as_warnings(tmp_path):
    f = tmp_path / "tendon.xml"
    f.write_text(
        '<mujoco>\n<worldbody><body><joint/><geom size="0.1"/></body></worldbody>\n'
        "<tendon/>\n</mujoco>"
    )
    with pytest.warns(UserWarning, match=r"tendon\.xml:3: <tendon>: <tendon>: not read"):
        tumble.World.from_mjcf(f)


# --- mesh geoms -----------------------------------------------------------------------

BOX_FACES = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4),
             (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6), (3, 0, 4), (3, 4, 7)]


def box_vertices(lo, hi):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    return [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
            (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]


def write_obj(path, vertices, faces):
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")


def write_binary_stl(path, vertices, faces):
    import struct
    out = bytearray(b"written by test_mjcf".ljust(80))
    out += struct.pack("<I", len(faces))
    for f in faces:
        out += struct.pack("<3f", 0, 0, 0)
        for i in f:
            out += struct.pack("<3f", *vertices[i])
        out += b"\0\0"
    path.write_bytes(bytes(out))


def prism(polygon, triangles, height):
    """A polygon (counter-clockwise) with its triangulation, extruded along z."""
    n = len(polygon)
    vertices = [(x, y, 0.0) for x, y in polygon] + [(x, y, height) for x, y in polygon]
    faces = [(a, c, b) for a, b, c in triangles]
    faces += [(n + a, n + b, n + c) for a, b, c in triangles]
    for k in range(n):
        a, b = k, (k + 1) % n
        faces += [(a, b, n + b), (a, n + b, n + a)]
    return vertices, faces


# A U-shaped channel: not star-shaped about its faces' centroid, so MuJoCo's default
# (legacy) inertia overcounts its volume, and its hull (convex) is a full block.
U_POLYGON = [(0, 0), (3, 0), (3, 2), (2, 2), (2, 1), (1, 1), (1, 2), (0, 2)]
U_TRIANGLES = [(0, 1, 4), (1, 2, 3), (1, 3, 4), (0, 4, 5), (0, 5, 6), (0, 6, 7)]


def mesh_model(tmp_path):
    meshes = tmp_path / "assets"
    meshes.mkdir()
    write_obj(meshes / "box.obj", box_vertices((1.0, 2.0, 3.0), (1.4, 2.2, 3.1)), BOX_FACES)
    tetra = [(0, 0, 0), (0.3, 0, 0), (0, 0.5, 0), (0, 0, 0.7)]
    write_binary_stl(meshes / "tetra.stl", tetra, [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)])
    u = prism([(0.1 * x, 0.1 * y) for x, y in U_POLYGON], U_TRIANGLES, 0.05)
    write_obj(meshes / "u.obj", *u)
    bodies = []
    for i, (mesh, extra) in enumerate([
        ("box", 'pos="0.1 0.2 0.3" euler="10 20 30" density="800"'),
        ("tetra", 'mass="2" quat="0.9 0.1 0.3 0.2"'),
        ("u_legacy", ""), ("u_exact", ""), ("u_convex", ""), ("mirrored", 'mass="3"'),
    ]):
        bodies.append(
            f'<body name="{mesh}" pos="{i} 0 1"><freejoint/>'
            f'<geom type="mesh" mesh="{mesh}" {extra}/></body>'
        )
    text = f"""<mujoco><compiler assetdir="assets"/>
      <asset><mesh file="box.obj" scale="1 2 3"/><mesh file="tetra.stl"/>
        <mesh name="mirrored" file="box.obj" scale="-1 2 0.5"/>
        <mesh name="u_legacy" file="u.obj"/><mesh name="u_exact" file="u.obj" inertia="exact"/>
        <mesh name="u_convex" file="u.obj" inertia="convex" refpos="0.1 0 0" refquat="0.9 0 0.3 0"/>
      </asset><worldbody>{"".join(bodies)}</worldbody></mujoco>"""
    path = tmp_path / "meshes.xml"
    path.write_text(text)
    return path


def test_mesh_bodies_weigh_and_balance_as_in_mujoco(tmp_path):
    """Mass, centre of mass (body_ipos) and principal moments (body_inertia) of mesh
    bodies in OBJ and binary STL, in MuJoCo's three mesh inertia modes, and the geom
    frame at the mesh's centre (MuJoCo's geom_pos, the Rust tests check Tumble's)."""
    path = mesh_model(tmp_path)
    model = mujoco.MjModel.from_xml_path(str(path))
    world = tumble.World.from_mjcf(path)
    masses = {}
    for name in ["box", "tetra", "u_legacy", "u_exact", "u_convex", "mirrored"]:
        i = model.body(name).id
        body = world.body(name)
        masses[name] = body.mass
        # MuJoCo keeps mesh vertices in single precision: 1e-6 relative.
        assert body.mass == pytest.approx(model.body_mass[i], rel=1e-6), name
        rot = quat_matrix(body.orientation)
        ipos = rot.T @ (body.center_of_mass - body.position)
        assert ipos == pytest.approx(model.body_ipos[i], abs=1e-6), name
        g = model.body_geomadr[i]
        assert model.geom_pos[g] == pytest.approx(ipos, abs=1e-6), name
        moments = np.linalg.eigvalsh(np.asarray(body.inertia))
        assert moments == pytest.approx(np.sort(model.body_inertia[i]), rel=1e-5), name
    # The three modes differ on the U: legacy > exact (0.05 · 0.05 m³ of water) < convex.
    assert masses["u_exact"] == pytest.approx(1000 * 0.05 * 0.05, rel=1e-9)
    assert masses["u_legacy"] > 1.01 * masses["u_exact"]
    assert masses["u_convex"] == pytest.approx(1000 * 0.06 * 0.05, rel=1e-9)


def quat_matrix(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def test_a_mesh_pendulum_swings_as_in_mujoco(tmp_path):
    """A tetrahedron (binary STL) on a hinge whose axis is none of its principal axes:
    the swing depends on the mesh's mass, centre and full inertia tensor."""
    tetra = [(0, 0, 0), (0.3, 0, 0), (0, 0.2, 0), (0, 0, 0.4)]
    write_binary_stl(tmp_path / "tetra.stl", tetra, [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)])
    path = tmp_path / "mesh_pendulum.xml"
    path.write_text("""<mujoco><compiler angle="radian"/><option integrator="RK4"/>
      <asset><mesh file="tetra.stl"/></asset><worldbody>
        <body name="bob" pos="0 0 1"><joint name="swing" axis="0.2 1 0.1"/>
          <geom type="mesh" mesh="tetra" pos="0.1 0 -0.3" euler="0.3 0.2 0.1" density="2000"/>
        </body></worldbody></mujoco>""")
    # It hangs at about 0.7 rad (its centre is off the hinge's plane): from -0.5 it swings.
    names, reference = mujoco_run(path, [-0.5])
    ours = tumble_run(path, names, [-0.5])
    worst = difference(ours, reference)
    print(f"mesh pendulum: largest joint difference {worst:.2e} rad over 1 s")
    assert worst < 1e-2
    assert np.ptp(reference) > 1.0  # it swings


def test_a_spinning_falling_mesh_body_moves_as_in_mujoco(tmp_path):
    """A free tetrahedron (binary STL, its geom turned and offset in the body) thrown
    spinning at 8 rad/s about a body axis that is none of its principal axes: torque-free
    rotation (Euler's equations with the mesh's full tensor) while it falls for 1 s."""
    tetra = [(0, 0, 0), (0.3, 0, 0), (0, 0.2, 0), (0, 0, 0.4)]
    write_binary_stl(tmp_path / "tetra.stl", tetra, [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)])
    path = tmp_path / "spin.xml"
    path.write_text("""<mujoco><compiler angle="radian"/><option integrator="RK4"/>
      <asset><mesh file="tetra.stl"/></asset><worldbody>
        <body name="bob" pos="0 0 1" euler="0.2 0.1 0"><freejoint/>
          <geom type="mesh" mesh="tetra" pos="0.05 0 -0.1" euler="0.3 0.2 0.1" density="2000"/>
        </body></worldbody></mujoco>""")
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.timestep = DT
    data = mujoco.MjData(model)
    spin = np.array([1.0, 8.0, 2.0])  # MuJoCo's free qvel: angular velocity in body axes
    data.qvel[3:6] = spin
    world = tumble.World.from_mjcf(path)
    body = world.body("bob")
    omega = quat_matrix(body.orientation) @ spin
    body.angular_velocity = omega
    # MuJoCo's body origin is at rest: the centre moves with omega x (centre - origin).
    body.velocity = np.cross(omega, body.center_of_mass - body.position)
    worst = 0.0
    for k in range(1, int(round(DURATION / DT)) + 1):
        mujoco.mj_step(model, data)
        world.step(DT)
        if k % SAMPLE == 0:
            w, x, y, z = data.qpos[3:]
            turn = 2 * np.arccos(min(1.0, abs(np.dot([x, y, z, w], body.orientation))))
            worst = max(worst, np.abs(body.position - data.qpos[:3]).max(), turn)
    print(f"spinning mesh: largest difference {worst:.2e} (m or rad) over 1 s")
    # Measured 9e-8: both integrate the same rigid-body equations at dt = 1e-4 s.
    assert worst < 1e-4


# --- actuators ------------------------------------------------------------------------

ACTUATED = """<mujoco><compiler angle="radian"/><option integrator="RK4"/>
  <worldbody>
    <body name="driven" pos="0 0 1"><joint name="motor_joint" axis="0 1 0" damping="0.05"/>
      <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03" mass="0.8"/></body>
    <body name="held" pos="0 1 1"><joint name="servo_joint" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.03" mass="1.2"/></body>
  </worldbody>
  <actuator>
    <motor name="motor" joint="motor_joint" gear="2" ctrlrange="-1.5 1.5"/>
    <position name="servo" joint="servo_joint" kp="40" kv="2"/>
  </actuator></mujoco>"""


def test_actuator_controls_move_joints_as_in_mujoco(tmp_path):
    """A motor (gear 2, control 3 clamped to 1.5: 3 N·m against a 0.8 kg arm's weight)
    and a position servo (kp 40, kv 2) sent to 0.5 rad: the same controls in both."""
    path = tmp_path / "actuated.xml"
    path.write_text(ACTUATED)
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.timestep = DT
    data = mujoco.MjData(model)
    world = tumble.World.from_mjcf(path)
    assert world.actuators == ["motor", "servo"]
    controls = {"motor": 3.0, "servo": 0.5}
    for name, value in controls.items():
        data.ctrl[model.actuator(name).id] = value
        world.set_control(name, value)
    assert world.control("motor") == 1.5  # clamped to ctrlrange, as MuJoCo does
    joints = [world.joint("motor_joint"), world.joint("servo_joint")]
    worst = 0.0
    for k in range(1, int(round(DURATION / DT)) + 1):
        mujoco.mj_step(model, data)
        world.step(DT)
        if k % SAMPLE == 0:
            ours = np.array([j.position for j in joints])
            d = ours - data.qpos[:2]
            worst = max(worst, np.abs((d + np.pi) % (2 * np.pi) - np.pi).max())
    print(f"actuated: largest joint difference {worst:.2e} rad over 1 s; qpos {data.qpos}")
    assert worst < 1e-2
    assert abs(data.qpos[0]) > 1.0  # the motor turned its arm over the top
    assert abs(data.qpos[1] - 0.5) < 0.2  # the servo holds near its target, sagging


def test_bad_controls_raise_value_error_naming_the_actuator(tmp_path):
    path = tmp_path / "actuated.xml"
    path.write_text(ACTUATED)
    world = tumble.World.from_mjcf(path)
    with pytest.raises(ValueError, match=r"^actuator 'nope': no such actuator"):
        world.set_control("nope", 1.0)
    with pytest.raises(ValueError, match=r"^actuator 'servo': control: must be a finite"):
        world.set_control("servo", float("nan"))
    assert world.control("servo") == 0.0  # nothing changed
    with pytest.raises(ValueError, match=r"^actuator 'x': no such actuator"):
        tumble.World().set_control("x", 0.0)


# --- condim: torsional and rolling friction ---------------------------------------------

G = 9.81


def ball_file(tmp_path, radius, condim, friction):
    """A ball of `radius` resting on a plane, both with `condim` and `friction`."""
    path = tmp_path / f"ball_{condim}.xml"
    path.write_text(f"""<mujoco><option timestep="0.002"/>
<default><geom condim="{condim}" friction="{friction}"/></default>
<worldbody><geom type="plane" size="5 5 .1"/>
<body pos="0 0 {radius}"><freejoint/><geom type="sphere" size="{radius}" density="500"/></body>
</worldbody></mujoco>""")
    return path


def run_ball(path, qvel, duration):
    """The ball's (v_x, ω_y, ω_z) after `duration` in MuJoCo and in Tumble, both started
    at `qvel` (v, ω) on the plane."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.qvel[:] = qvel
    world = tumble.World.from_mjcf(path)
    (ball,) = [b for b in world.bodies if b.kind == "dynamic"]
    ball.velocity, ball.angular_velocity = qvel[:3], qvel[3:]
    steps = int(round(duration / 0.002))
    for _ in range(steps):
        mujoco.mj_step(model, data)
    world.step(0.002, steps=steps)
    theirs = (data.qvel[0], data.qvel[4], data.qvel[5])
    ours = (ball.velocity[0], ball.angular_velocity[1], ball.angular_velocity[2])
    return theirs, ours


@pytest.mark.parametrize("radius, rolling, speed", [(0.05, 0.001, 0.5), (0.1, 0.002, 1.0),
                                                    (0.1, 0.01, 2.0), (0.25, 0.02, 3.0)])
def test_condim_6_rolling_friction_slows_a_rolling_ball(tmp_path, radius, rolling, speed):
    """MuJoCo's rolling friction caps the rolling torque at μ_roll N: a ball rolling
    without slip slows at (5/7) μ_roll g / R. Tumble's rolling resistance is μ_roll / R
    and gives that to 2 %; MuJoCo's soft friction rows give 50–100 % of it on these
    balls (its regularised cone), so it is only checked to slow down too."""
    path = ball_file(tmp_path, radius, 6, f"0.8 0.005 {rolling}")
    duration = 0.5
    theirs, ours = run_ball(path, [speed, 0, 0, 0, speed / radius, 0], duration)
    expected = 5.0 / 7.0 * rolling * G / radius * duration
    assert speed - ours[0] == pytest.approx(expected, rel=0.02)
    assert ours[1] * radius == pytest.approx(ours[0], rel=1e-3)  # still rolling
    assert 0.4 * expected < speed - theirs[0] < 1.1 * expected


@pytest.mark.parametrize("radius, torsional", [(0.05, 0.002), (0.1, 0.01), (0.2, 0.02)])
def test_condim_4_torsional_friction_stops_a_spinning_ball_as_in_mujoco(tmp_path, radius,
                                                                        torsional):
    """Spin about the normal slows at μ_t m g / I = μ_t g / (0.4 R²) in both."""
    spin = 0.5 * torsional * G / (0.4 * radius**2)  # rad/s left after 0.5 s: half of it
    path = ball_file(tmp_path, radius, 4, f"0.8 {torsional} 0.0001")
    theirs, ours = run_ball(path, [0, 0, 0, 0, 0, 2 * spin], 0.5)
    assert ours[2] == pytest.approx(spin, rel=0.02)
    assert theirs[2] == pytest.approx(spin, rel=0.05)


def test_condim_3_has_neither(tmp_path):
    """The default condim: sliding friction only, so a rolling ball keeps rolling and a
    spinning one keeps spinning, in both."""
    path = ball_file(tmp_path, 0.1, 3, "0.8 0.05 0.05")
    theirs, ours = run_ball(path, [1.0, 0, 0, 0, 10.0, 5.0], 0.5)
    assert ours == pytest.approx((1.0, 10.0, 5.0), abs=1e-3)
    assert theirs == pytest.approx((1.0, 10.0, 5.0), abs=2e-2)


def test_condim_is_checked_and_condim_1_is_a_warning(tmp_path):
    path = ball_file(tmp_path, 0.1, 2, "1")
    with pytest.raises(ValueError, match=r"condim: must be 1, 3, 4 or 6, got 2"):
        tumble.World.from_mjcf(path)
    path = ball_file(tmp_path, 0.1, 1, "1")
    with pytest.warns(UserWarning, match=r"condim 1 \(frictionless\): not read"):
        tumble.World.from_mjcf(path)


def test_a_model_with_excluded_pairs_is_batched_and_snapshotted():
    # dm_control's humanoid excludes its multi-joint bodies from their parents (and its
    # file lists <exclude> pairs): as data, these travel with copies, so a Batch of it
    # steps each copy as the world alone, bit for bit (it was refused: a contact filter).
    with pytest.warns(UserWarning):
        world = tumble.World.from_mjcf(SUITE / "humanoid.xml")
    assert len(world.excluded_contacts) > 0
    batch = tumble.Batch(world, copies=2, threads=1)
    twin = tumble.World.from_snapshot(world.snapshot())
    assert [(a.name, b.name) for a, b in twin.excluded_contacts] == [
        (a.name, b.name) for a, b in world.excluded_contacts
    ]
    batch.step(0.005, steps=100)
    world.step(0.005, steps=100)
    assert np.array_equal(batch.positions[1], world.positions)


def test_excluded_pairs_from_python():
    # A small ball dropped on a big one passes through it onto the floor once the pair is
    # excluded (its centre 0.1 m up, to 5 mm); bad pairs raise ValueError by field.
    world = tumble.World(gravity=(0, -9.8, 0), sleep=False)
    world.add_body(tumble.Plane((0, 1, 0)), kind="static")
    big = world.add_body(tumble.Sphere(0.5), position=(0, 0.5, 0), name="big")
    small = world.add_body(tumble.Sphere(0.1), position=(0, 2, 0), name="small")
    world.exclude_contacts("small", big)
    assert [(a.name, b.name) for a, b in world.excluded_contacts] == [("big", "small")]
    world.step(0.01, steps=150)
    assert small.position[1] == pytest.approx(0.1, abs=5e-3)
    with pytest.raises(ValueError, match="^exclude: a body cannot be excluded from itself$"):
        world.exclude_contacts(big, big)
    with pytest.raises(ValueError, match="^b: no body named 'mug'$"):
        world.exclude_contacts(big, "mug")
    assert world.allow_contacts(big, small) and not world.allow_contacts(big, small)
