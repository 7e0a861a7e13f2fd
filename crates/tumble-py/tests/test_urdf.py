"""URDF models from Python: World.from_urdf and World.add_urdf, joint coordinates in the
file's convention, bad files as ValueError, and differential tests against PyBullet (a
passive double pendulum joint by joint; pybullet_data robots' total masses)."""

import math
import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import tumble

G = 9.81


def rod(name, mass, length, w=0.05):
    long = mass * (length * length + w * w) / 12.0
    thin = mass * 2.0 * w * w / 12.0
    c = -0.5 * length
    return f"""<link name="{name}">
    <inertial><origin xyz="0 0 {c}"/><mass value="{mass}"/>
      <inertia ixx="{long}" iyy="{long}" izz="{thin}" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 {c}"/><geometry><box size="{w} {w} {length}"/></geometry></collision>
  </link>"""


def double_pendulum(m1=1.0, l1=1.0, m2=1.0, l2=1.0):
    return f"""<?xml version="1.0"?>
<robot name="double_pendulum">
  <link name="base"/>
  {rod("upper", m1, l1)}
  {rod("lower", m2, l2)}
  <joint name="shoulder" type="continuous">
    <parent link="base"/><child link="upper"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="elbow" type="continuous">
    <parent link="upper"/><child link="lower"/><origin xyz="0 0 {-l1}"/><axis xyz="0 1 0"/>
  </joint>
</robot>
"""


@pytest.fixture
def pendulum(tmp_path):
    path = tmp_path / "double.urdf"
    path.write_text(double_pendulum(1.0, 1.0, 2.0, 0.8))
    return path


def test_from_urdf_is_z_up_and_names_bodies_and_joints_as_the_file(pendulum):
    w = tumble.World.from_urdf(pendulum)
    np.testing.assert_array_equal(w.gravity, [0.0, 0.0, -9.81])
    lower = w.body("lower")
    assert lower.mass == pytest.approx(2.0, rel=1e-12)
    np.testing.assert_allclose(lower.center_of_mass, [0, 0, -1.4], atol=1e-12)
    assert w.body("base").kind == "static"
    assert w.joint("elbow").kind == "hinge"
    free = tumble.World.from_urdf(pendulum, fixed_base=False, gravity=(0, -9.8, 0), position=(1, 2, 3))
    # The base has no mass: a massless root stays static even on a free base (PyBullet's
    # convention); the rods move.
    assert free.body("base").kind == "static"
    assert free.body("upper").kind == "dynamic"
    np.testing.assert_array_equal(free.gravity, [0.0, -9.8, 0.0])
    np.testing.assert_allclose(free.body("upper").position, [1, 2, 3], atol=1e-12)
    # from_scene takes a model file too, by its extension (as `tumble run` does).
    scene = tumble.World.from_scene(pendulum)
    np.testing.assert_array_equal(scene.gravity, [0.0, 0.0, -9.81])
    assert scene.joint("elbow").kind == "hinge"


def test_joint_positions_are_the_files_coordinates_readable_and_settable(pendulum):
    # A turn of +q about +y (the child relative to the parent, URDF's sense) takes the
    # upper rod's centre (0, 0, -0.5) to (-0.5 sin q, 0, -0.5 cos q).
    w = tumble.World.from_urdf(pendulum)
    shoulder = w.joint("shoulder")
    assert shoulder.position == pytest.approx(0.0, abs=1e-12)
    shoulder.position = 0.4
    assert shoulder.position == pytest.approx(0.4, abs=1e-9)
    np.testing.assert_allclose(
        w.body("upper").center_of_mass, [-0.5 * math.sin(0.4), 0, -0.5 * math.cos(0.4)], atol=1e-9
    )


def test_add_urdf_returns_the_model_by_name_and_is_all_or_nothing(pendulum):
    w = tumble.World(gravity=(0, 0, -9.81))
    a = w.add_urdf(pendulum)
    assert isinstance(a, tumble.Model)
    assert a.name == "double_pendulum"
    assert list(a.bodies) == ["base", "upper", "lower"]
    assert list(a.joints) == ["shoulder", "elbow"]
    assert a.warnings == []
    b = w.add_urdf(pendulum, prefix="right_", position=(2, 0, 0), orientation=(0, 0, 1, 0))
    assert b.bodies["upper"].name == "right_upper"
    assert b.joints["elbow"].name == "right_elbow"
    # Turned half a turn about z, at x = 2: the lower rod's centre is still 1.4 m down.
    np.testing.assert_allclose(b.bodies["lower"].center_of_mass, [2, 0, -1.4], atol=1e-12)
    before = len(w.bodies)
    with pytest.raises(ValueError, match="a body named 'base' already exists"):
        w.add_urdf(pendulum)
    assert len(w.bodies) == before and len(w.joints) == 4


BAD = [
    ("<robot name='r'><link name='a'></robot>", r"bad\.urdf:1: malformed XML"),
    (
        "<robot name='r'>\n<link name='a'><inertial><mass value='-1'/></inertial></link></robot>",
        r"bad\.urdf:2: <link name=\"a\">: inertial\.mass: must be >= 0, got -1",
    ),
    (
        "<robot name='r'>\n<link name='a'>\n<collision><geometry>\n<mesh filename='no.stl'/>"
        "</geometry></collision></link></robot>",
        r"bad\.urdf:4: <mesh>: filename: mesh file 'no\.stl' not found",
    ),
]


@pytest.mark.parametrize("text,message", BAD)
def test_bad_files_raise_value_error_naming_file_line_and_element(tmp_path, text, message):
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    with pytest.raises(ValueError, match=message):
        tumble.World.from_urdf(path)
    w = tumble.World()
    with pytest.raises(ValueError, match=message):
        w.add_urdf(path)
    assert len(w.bodies) == 0


def test_an_impossible_inertia_is_a_warning_as_pybullet_loads_it(tmp_path):
    # PyBullet's random_urdfs give every object ixx = iyy = 1, izz = 0.
    path = tmp_path / "flat.urdf"
    path.write_text(
        "<robot name='r'>\n<link name='a'><inertial><mass value='1'/>"
        "<inertia ixx='1' iyy='1' izz='0'/></inertial></link></robot>"
    )
    m = tumble.World().add_urdf(path)
    assert len(m.warnings) == 1
    assert "inertial.inertia: is not positive definite" in m.warnings[0]
    assert "not used (the link does not move)" in m.warnings[0]
    # from_urdf has no model to return: the same text comes out as a UserWarning.
    with pytest.warns(UserWarning, match="is not positive definite") as caught:
        tumble.World.from_urdf(path)
    assert [str(w.message) for w in caught] == m.warnings


# --- against PyBullet -------------------------------------------------------------------

# Only the tests that take the `bullet` fixture need PyBullet: the others run without it
# (a module-level importorskip would have skipped them all).
try:
    import pybullet
    import pybullet_data  # ships inside the pybullet wheel
except ImportError:
    pybullet = pybullet_data = None


@pytest.fixture
def bullet():
    if pybullet is None:
        pytest.skip("pybullet is not installed")
    client = pybullet.connect(pybullet.DIRECT)
    yield client
    pybullet.disconnect(client)


def bullet_pendulum(client, path, q0, dt):
    pybullet.setGravity(0, 0, -G, physicsClientId=client)
    pybullet.setTimeStep(dt, physicsClientId=client)
    body = pybullet.loadURDF(
        str(path), useFixedBase=True, flags=pybullet.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client
    )
    n = pybullet.getNumJoints(body, physicsClientId=client)
    # Motors off (PyBullet holds every joint with a velocity motor by default), and no
    # link damping (its default is 0.04): a passive pendulum, as the file says.
    pybullet.setJointMotorControlArray(
        body, list(range(n)), pybullet.VELOCITY_CONTROL, forces=[0.0] * n, physicsClientId=client
    )
    for j in range(-1, n):
        pybullet.changeDynamics(body, j, linearDamping=0, angularDamping=0, physicsClientId=client)
    for j, q in enumerate(q0):
        pybullet.resetJointState(body, j, q, physicsClientId=client)
    return body


@pytest.mark.parametrize("q0,masses", [((0.5, -0.3), (1.0, 1.0, 1.0, 1.0)), ((0.3, 0.4), (0.5, 0.6, 2.0, 0.9))])
def test_a_passive_double_pendulum_matches_pybullet_joint_by_joint(tmp_path, bullet, q0, masses):
    # Released from rest at moderate angles (not chaotic over 1 s), both engines at a
    # fine step, 1 ms: joint angles agree within 1e-2 rad throughout. The two integrate
    # differently (Tumble: maximal coordinates with soft joints; Bullet: reduced
    # coordinates), each with an O(dt) error of about 1e-3 rad at this step.
    path = tmp_path / "double.urdf"
    path.write_text(double_pendulum(*masses))
    dt = 1e-3
    body = bullet_pendulum(bullet, path, q0, dt)
    w = tumble.World.from_urdf(path, fixed_base=True)
    joints = [w.joint("shoulder"), w.joint("elbow")]
    for j, q in zip(joints, q0):
        j.position = q
    worst = 0.0
    for _ in range(1000):
        pybullet.stepSimulation(physicsClientId=bullet)
        w.step(dt)
        theirs = [pybullet.getJointState(body, j, physicsClientId=bullet)[0] for j in range(2)]
        ours = [j.position for j in joints]
        worst = max(worst, *(abs(a - b) for a, b in zip(ours, theirs)))
    print(f"double pendulum {q0} {masses}: worst joint-angle difference {worst:.2e} rad")
    assert worst < 1e-2, f"joint angles differ by up to {worst} rad"


def file_mass(path):
    return sum(float(m.get("value")) for m in ET.parse(path).getroot().iter("mass"))


@pytest.mark.parametrize("name", ["r2d2.urdf", "kuka_iiwa/model.urdf", "racecar/racecar.urdf"])
def test_pybullet_data_models_load_and_run_with_the_files_total_mass(bullet, name):
    # Free bases, so that every link with mass is a dynamic body; the total must be the
    # sum of the file's <mass> values, and PyBullet's own (links and base) the same.
    path = os.path.join(pybullet_data.getDataPath(), name)
    w = tumble.World.from_urdf(path, fixed_base=False)
    model = tumble.World(gravity=(0, 0, -G)).add_urdf(path, fixed_base=False)
    bodies = {b.name: b for b in model.bodies.values()}
    ours = sum(b.mass for b in bodies.values() if b.kind == "dynamic")
    expected = file_mass(path)
    assert ours == pytest.approx(expected, rel=1e-12)
    body = pybullet.loadURDF(path, physicsClientId=bullet)
    n = pybullet.getNumJoints(body, physicsClientId=bullet)
    theirs = sum(pybullet.getDynamicsInfo(body, j, physicsClientId=bullet)[0] for j in range(-1, n))
    assert ours == pytest.approx(theirs, rel=1e-6)
    w.step(0.005, steps=100)
    assert all(np.isfinite(b.position).all() for b in w.bodies)


def folded(overlap):
    """A base, a middle link hinged above it and a tip hinged below the middle: base and
    tip overlap by `overlap` (m) and no joint connects them."""

    def link(name, size):
        return f"""<link name="{name}"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="{size} {size} {size}"/></geometry></collision></link>"""

    lim = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    return f"""<robot name="folded">{link("base", 0.2)}{link("mid", 0.1)}{link("tip", 0.1)}
  <joint name="up" type="revolute"><parent link="base"/><child link="mid"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>{lim}</joint>
  <joint name="down" type="revolute"><parent link="mid"/><child link="tip"/>
    <origin xyz="0 0 {-0.35 - overlap}"/><axis xyz="0 1 0"/>{lim}</joint>
</robot>"""


def touching(w):
    return sorted({tuple(sorted((c.body_a.name, c.body_b.name))) for c in w.update_contacts()})


@pytest.mark.parametrize("overlap", [0.005, 0.03])
def test_a_models_links_collide_with_each_other_only_with_self_collision(tmp_path, overlap):
    path = tmp_path / "folded.urdf"
    path.write_text(folded(overlap))
    # PyBullet's default: a model's own links pass through each other.
    assert touching(tumble.World.from_urdf(path)) == []
    assert touching(tumble.World.from_urdf(path, self_collision=True)) == [("base", "tip")]
    # A second copy collides with the first, which still does not collide with itself.
    w = tumble.World.from_urdf(path)
    w.add_urdf(path, prefix="b_", position=(0.05, 0, 0), self_collision=True)
    assert touching(w) == sorted(
        [("b_base", "tip"), ("b_mid", "mid"), ("b_tip", "base"), ("b_tip", "tip"), ("b_base", "b_tip")]
    )
    # The owner is a body property: giving the tip another owner brings its contact back;
    # the links' groups and masks are untouched.
    w = tumble.World.from_urdf(path)
    tip = w.body("tip")
    assert tip.collision_owner == w.body("base").collision_owner != 0
    assert (tip.collision_group, tip.collision_mask) == (1, 0xFFFFFFFF)
    tip.collision_owner = 0
    assert touching(w) == [("base", "tip")]
    with pytest.raises(ValueError, match=r"collision_owner: must be a whole number in \[0, 2\*\*32\)"):
        tip.collision_owner = -1
    assert tip.collision_owner == 0
