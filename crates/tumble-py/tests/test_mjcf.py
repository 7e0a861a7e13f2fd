"""MJCF import against MuJoCo (the `mujoco` package): the same passive models in both,
joint angles compared over 1 s at a fine time step; dm_control suite models loaded and
run, their total masses equal to MuJoCo's; bad files as ValueError naming file:line."""

import importlib.util
import math
import pathlib

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


def difference(ours, reference, hinges):
    """Largest difference; hinge angles compared modulo 2 pi (Tumble reads them in
    (-pi, pi], MuJoCo's qpos counts whole turns)."""
    d = ours - reference
    d[:, hinges] = (d[:, hinges] + np.pi) % (2 * np.pi) - np.pi
    return np.abs(d).max()


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
    worst = difference(ours, reference, [n != "slider" for n in names])
    print(f"{path.name}: largest joint difference {worst:.2e} over 1 s")
    # Both integrate the same equations at dt = 1e-4 s; what differs is MuJoCo's
    # generalized coordinates against Tumble's constraints (their drift and softness).
    assert worst < 1e-2, f"largest joint difference {worst} rad or m"
    # The motion is real: every joint moves by 5 times the tolerance or more.
    assert np.ptp(reference, axis=0).min() > 0.05


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
# mass) per extra joint, so their totals come out up to 0.3% heavier; dog reads no meshes.
HEAVIER = ["ball_in_cup", "cheetah", "fish", "hopper", "humanoid", "humanoid_CMU",
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
    assert ours - sum(light) == pytest.approx(moving, rel=1e-9)
    assert 0 < sum(light) <= 3e-3 * moving
    world.step(float(model.opt.timestep), steps=int(round(1.0 / model.opt.timestep)))
    assert all(np.isfinite(b.position).all() for b in world.bodies)


def test_a_damped_suite_pendulum_matches_mujoco():
    """dm_control's pendulum: joint damping 0.1 N·m·s/rad (Tumble's servo damper)."""
    path = SUITE / "pendulum.xml"
    names, reference = mujoco_run(path, [1.0])
    ours = tumble_run(path, names, [1.0])
    worst = difference(ours, reference, [True])
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
