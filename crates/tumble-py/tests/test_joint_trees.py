"""Joint trees in reduced coordinates (`joint_trees="reduced"`) against MuJoCo: the same
MJCF models stepped by MuJoCo's Euler integrator and by Tumble at 1 substep are the same
scheme on the same equations, so their joint coordinates agree to rounding; at n
substeps Tumble equals MuJoCo at dt / n. And the setting as Python sees it."""

import math
import pathlib

import mujoco
import numpy as np
import pytest

import tumble

HERE = pathlib.Path(__file__).resolve().parent
SCENE_MODELS = HERE.parents[1] / "tumble-scene" / "tests" / "mjcf"

MODELS = [
    (SCENE_MODELS / "double_pendulum.xml", [math.pi / 2 - 0.5, 0.3]),
    (HERE / "mjcf" / "cartpole_hanging.xml", [0.0, 0.8]),
]


def mujoco_euler(path, qpos0, dt, steps, every):
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.timestep = dt / every
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    data = mujoco.MjData(model)
    data.qpos[:] = qpos0
    names = [model.joint(i).name for i in range(model.njnt)]
    out = []
    for _ in range(steps):
        for _ in range(every):
            mujoco.mj_step(model, data)
        out.append([data.qpos[model.jnt_qposadr[i]] for i in range(model.njnt)])
    return names, np.array(out)


def tumble_reduced(path, names, qpos0, dt, steps, substeps):
    world = tumble.World.from_mjcf(path)
    settings = world.solver_settings
    settings.joint_trees = "reduced"
    settings.substeps = substeps
    world.solver_settings = settings
    for name, q in zip(names, qpos0):
        world.joint(name).position = float(q)
    joints = [world.joint(n) for n in names]
    out = []
    for _ in range(steps):
        world.step(dt)
        out.append([j.position for j in joints])
    return np.array(out)


@pytest.mark.parametrize("path, qpos0", MODELS, ids=["double_pendulum", "cartpole"])
@pytest.mark.parametrize("dt, substeps", [(0.01, 1), (0.002, 1), (0.01, 4)])
def test_reduced_trees_step_as_mujoco_euler(path, qpos0, dt, substeps):
    steps = round(1.0 / dt)
    names, reference = mujoco_euler(path, qpos0, dt, steps, substeps)
    ours = tumble_reduced(path, names, qpos0, dt, steps, substeps)
    worst = np.abs(ours - reference).max()
    print(f"{path.name}, dt {dt}, {substeps} substeps: largest difference {worst:.1e}")
    # Rounding only: the soft step differs from MuJoCo here by 1e-2 rad and more.
    assert worst < 1e-9, f"largest joint difference {worst} rad or m"
    moved = np.abs(reference - reference[0]).max(axis=0)
    assert (moved > 0.05).all(), moved


def test_the_setting_reads_writes_and_refuses_unknown_ways():
    world = tumble.World(joint_trees="reduced")
    assert world.solver_settings.joint_trees == "reduced"
    settings = world.solver_settings
    settings.joint_trees = "maximal"
    world.solver_settings = settings
    assert world.solver_settings.joint_trees == "maximal"
    assert tumble.SolverSettings().joint_trees == "maximal"
    message = r"^joint_trees: unknown way 'featherstone' \(expected one of: maximal, reduced\)$"
    with pytest.raises(ValueError, match=message):
        tumble.World(joint_trees="featherstone")
    with pytest.raises(ValueError, match=message):
        tumble.SolverSettings(joint_trees="featherstone")
    with pytest.raises(ValueError, match=message):
        tumble.World.from_json('{"joint_trees": "featherstone", "bodies": []}')


@pytest.mark.parametrize("substeps", [1, 3])
def test_ball_joints_step_as_mujoco_euler(substeps):
    # Two ball joints (MuJoCo's qvel: the angular velocity in the body's frame, the
    # quaternion turned by it) and a hinge, bent out of plane: every body's orientation
    # as MuJoCo's to rounding over a second.
    path = HERE / "mjcf" / "ball_chain.xml"
    dt = 0.005
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.timestep = dt / substeps
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    data = mujoco.MjData(model)
    world = tumble.World.from_mjcf(path)
    settings = world.solver_settings
    settings.joint_trees = "reduced"
    settings.substeps = substeps
    world.solver_settings = settings
    names = [b.name for b in world.bodies]
    order = [names.index(n) for n in ("a", "b", "c")]
    worst = 0.0
    start = None
    for _ in range(round(1.0 / dt)):
        for _ in range(substeps):
            mujoco.mj_step(model, data)
        world.step(dt)
        # mj_step leaves the poses of the step's start: made again for the new qpos.
        mujoco.mj_kinematics(model, data)
        ours = np.asarray(world.orientations)[order]
        theirs = data.xquat[1:4][:, [1, 2, 3, 0]]
        theirs = theirs * np.sign((theirs * ours).sum(axis=1))[:, None]
        worst = max(worst, np.abs(ours - theirs).max())
        start = theirs if start is None else start
    print(f"ball chain, {substeps} substeps: largest difference {worst:.1e}")
    assert worst < 1e-9, worst
    assert np.abs(theirs - start).max() > 0.1
