"""World-steps per second of tumble.Batch against MuJoCo's own batched stepping,
mujoco.rollout, on 1 and 2 threads (issue 20). Not run by CI: run it on a quiet machine.

    target/venv/bin/python crates/tumble-py/bench/batch_throughput.py [--quick]

Cases:
- 1,024 cart-poles (a 1 kg cart on a slider along x, a 0.1 kg, 1 m pole on a hinge about
  y; no contacts; dt = 0.01 s, gravity 9.81 m/s² along -z), 500 steps, each world's cart
  and pole kicked by a different small velocity so that the poles fall and swing;
- 64 ragdolls (the built-in `ragdoll` scene: eleven bodies, limited ball joints and
  hinges, tumbling down a flight of stairs: contacts on jointed bodies), 300 steps, each
  world's bodies kicked by up to 0.05 m/s (before the solver turned its bodies' inertia
  with them, kicks of 0.01 m/s blew some ragdolls up near 0.85 s).

The cart-poles run four ways in Tumble: with its default solver (4 substeps a step, what
every figure of the README uses) and with 1 substep (`"substeps": 1`, closer to MuJoCo's
one solve per step; the joints are then softer); and as a joint tree in reduced
coordinates (`"joint_trees": "reduced"`) at 1 and 4 substeps, which is MuJoCo's own
Euler scheme (the same trajectory to rounding) at dt and at dt / 4.

MuJoCo runs the same cart-pole as MJCF (the same masses, box sizes, dt and gravity; its
geoms collide with nothing) through mujoco.rollout.Rollout (a persistent thread pool of
`nthread` threads; nthread = 0 steps on the calling thread) with zero control.
rollout writes every step's state into the output array it is given (allocated once,
outside the timing), so Tumble is timed three ways: `step` (nothing recorded),
`simulate(every=1)` (every step's positions, orientations, velocities and angular
velocities recorded into new arrays) and `simulate(every=1, out=...)` (recorded into the
arrays of an earlier run, as rollout does). The figures are the best of `--repeat` runs
(default 3), as world-steps per second = W × steps / seconds; every case of a thread
count takes its turn in each round (`interleaved`), so that the machine's slow spells
fall on Tumble and MuJoCo alike.

Same dt is not same accuracy, so the script also measures each run's error on a pole let
go 1 rad from upright (`accuracy`: RMS error over 2 s against MuJoCo's RK4 at 1e-5 s) and
times MuJoCo where it matches Tumble: its Euler at dt / 4 (as close as Tumble's 1
substep) and its RK4 at dt (closer than Tumble's 4 substeps), counted per 0.01 s
simulated.
"""

import argparse
import json
import os
import time

import numpy as np

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
        {"type": "slider", "name": "track", "body": "cart", "axis": [1, 0, 0]},
        {
            "type": "hinge",
            "name": "pivot",
            "body": "pole",
            "other": "cart",
            "anchor": [0, 0, -0.5],
            "axis": [0, 1, 0],
        },
    ],
}

CART_POLE_1 = dict(CART_POLE, substeps=1)
# The joints' own coordinates (see `solver/articulation.rs`): MuJoCo's scheme, Euler on the
# hinge angle and the slider's travel, at 1 and at 4 substeps.
REDUCED_1 = dict(CART_POLE, substeps=1, joint_trees="reduced")
REDUCED_4 = dict(CART_POLE, joint_trees="reduced")

CART_POLE_MJCF = """
<mujoco model="cart_pole">
  <option timestep="0.01" gravity="0 0 -9.81"/>
  <worldbody>
    <body name="cart">
      <joint name="track" type="slide" axis="1 0 0"/>
      <geom type="box" size="0.2 0.1 0.05" mass="1.0" contype="0" conaffinity="0"/>
      <body name="pole">
        <joint name="pivot" type="hinge" axis="0 1 0"/>
        <geom type="box" size="0.02 0.02 0.5" pos="0 0 0.5" mass="0.1"
              contype="0" conaffinity="0"/>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="track"/></actuator>
</mujoco>
"""


def interleaved(cases, repeat):
    """World-steps per second of each case, the best of `repeat` timed calls. A case is
    (world-steps a call, setup) where setup() returns the call (untimed). The cases take
    turns, round after round, so that a slow spell of the machine (this 2-core VM's speed
    wanders by half from minute to minute) falls on all of them alike rather than on
    whichever ran then."""
    times = [[] for _ in cases]
    for _ in range(repeat):
        for (_, setup), t in zip(cases, times):
            run = setup()
            t0 = time.perf_counter()
            run()
            t.append(time.perf_counter() - t0)
    return [work / min(t) for (work, _), t in zip(cases, times)]


def tumble_case(scene, copies, steps, threads, record, kick=0.05):
    """Tumble's batch as a case of `interleaved`: `record` None (`step`), "new"
    (`simulate` into new arrays) or "out" (`simulate` into an earlier run's arrays)."""

    def batch():
        b = tumble.Batch(scene, copies=copies, threads=threads)
        if kick:
            b.randomize(np.random.default_rng(1), velocities=kick)
        return b

    def setup():
        b = batch()
        if record == "out":
            out = batch().simulate(steps=steps, every=1)
            return lambda: b.simulate(steps=steps, every=1, out=out)
        if record == "new":
            return lambda: b.simulate(steps=steps, every=1)
        return lambda: b.step(steps=steps)

    return copies * steps, setup


def tumble_cases(scene, copies, steps, threads):
    """`tumble_case` for each way of recording: step, simulate, simulate into out."""
    return [tumble_case(scene, copies, steps, threads, r) for r in (None, "new", "out")]


def mujoco_case(pools, copies, steps, threads, integrator="EULER", split=1):
    """MuJoCo's rollout as a case of `interleaved`, counted in world-steps of 0.01 s,
    each 0.01 s taken as `split` steps of 0.01 / split with `integrator` (mjINT_ + its
    name). Its thread pool is added to `pools` (to be closed by the caller)."""
    import mujoco
    from mujoco import rollout

    model = mujoco.MjModel.from_xml_string(CART_POLE_MJCF)
    model.opt.timestep = 0.01 / split
    model.opt.integrator = getattr(mujoco.mjtIntegrator, "mjINT_" + integrator)
    nstep = steps * split
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    data = mujoco.MjData(model)
    size = mujoco.mj_stateSize(model, spec)
    rng = np.random.default_rng(1)
    initial = np.zeros((copies, size))
    for i in range(copies):
        mujoco.mj_resetData(model, data)
        data.qvel[:] = rng.uniform(-0.05, 0.05, model.nv)
        mujoco.mj_getState(model, data, initial[i], spec)
    control = np.zeros((copies, nstep, model.nu))
    state = np.empty((copies, nstep, size))
    sensordata = np.empty((copies, nstep, model.nsensordata))
    datas = [mujoco.MjData(model) for _ in range(max(threads, 1))]
    # nthread = 0: the calling thread steps every world (MuJoCo's own 1-thread case).
    pool = rollout.Rollout(nthread=0 if threads == 1 else threads)
    pools.append(pool)

    def setup():
        return lambda: pool.rollout(
            model,
            datas,
            initial,
            control,
            nstep=nstep,
            state=state,
            sensordata=sensordata,
        )

    return copies * steps, setup


def swinging(theta, substeps):
    """The bench's cart-pole with its pole let go at `theta` (rad) from upright."""
    scene = json.loads(json.dumps(CART_POLE))
    scene["substeps"] = substeps
    pole = scene["bodies"][1]
    pole["position"] = [0.5 * np.sin(theta), 0.0, 0.5 * np.cos(theta)]
    pole["orientation"] = [0.0, np.sin(theta / 2), 0.0, np.cos(theta / 2)]
    return scene


def accuracy(theta=1.0, duration=2.0):
    """RMS error of the pole's angle and the cart's position over `duration`, each engine
    at dt = 0.01 s against MuJoCo's RK4 at dt = 1e-5 s: whether Tumble at 1 substep is as
    close to the cart-pole's true motion as MuJoCo's Euler step it is timed against."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(CART_POLE_MJCF)
    steps = round(duration / 0.01)

    def mujoco_run(dt, integrator):
        model.opt.timestep = dt
        model.opt.integrator = integrator
        data = mujoco.MjData(model)
        data.qpos[:] = [0.0, theta]
        every = round(0.01 / dt)
        out = []
        for _ in range(steps):
            for _ in range(every):
                mujoco.mj_step(model, data)
            out.append(data.qpos.copy())
        return np.array(out)

    truth = mujoco_run(1e-5, mujoco.mjtIntegrator.mjINT_RK4)
    rows = {"MuJoCo Euler": mujoco_run(0.01, mujoco.mjtIntegrator.mjINT_EULER)}
    for substeps, trees in ((1, "maximal"), (4, "maximal"), (1, "reduced"), (4, "reduced")):
        scene = dict(swinging(theta, substeps), joint_trees=trees)
        world = tumble.World.from_json(json.dumps(scene))
        out = []
        for _ in range(steps):
            world.step(0.01, 1)
            q = world.orientations[1]
            out.append([world.positions[0][0], 2.0 * np.arctan2(q[1], q[3])])
        name = f"Tumble {trees}, {substeps} substep{'s' * (substeps > 1)}"
        rows[name] = np.array(out)
    print(f"\naccuracy: pole let go {theta} rad from upright, {duration} s at dt = 0.01 s,")
    print("RMS error against MuJoCo RK4 at dt = 1e-5 s")
    for name, run in rows.items():
        err = np.sqrt(np.mean((run - truth) ** 2, axis=0))
        print(f"  {name:30s} cart {err[0] * 1e3:8.3f} mm   pole {err[1] * 1e3:8.3f} mrad")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small sizes, to try the script")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument(
        "--reduced-only",
        action="store_true",
        help="only the reduced 1-substep cart-poles and MuJoCo's rollout (the issue's goal)",
    )
    args = parser.parse_args()
    scale = 8 if args.quick else 1
    cart, ragdoll = (1024 // scale, 500 // scale), (64 // scale, 300 // scale)
    load = os.getloadavg()
    print(f"load average before: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}; cores: {os.cpu_count()}")
    rows = []
    for threads in (1, 2):
        w, n = cart
        pools = []
        cases = {
            "four": tumble_cases(CART_POLE, w, n, threads),
            "one": tumble_cases(CART_POLE_1, w, n, threads),
            # Reduced trees: the same scheme as MuJoCo's Euler, so the same dt is the
            # same accuracy: at dt (1 substep) and at dt / 4 (4 substeps).
            "r1": tumble_cases(REDUCED_1, w, n, threads),
            "r4": tumble_cases(REDUCED_4, w, n, threads),
            "mj": [mujoco_case(pools, w, n, threads)],
            # At matched accuracy (see `accuracy`): MuJoCo's Euler needs dt / 4 to come
            # as close as Tumble's 1 substep; its RK4 at dt beats Tumble's 4 substeps.
            "mj4": [mujoco_case(pools, w, n, threads, split=4)],
            "rk4": [mujoco_case(pools, w, n, threads, integrator="RK4")],
            "ragdoll": tumble_cases("ragdoll", *ragdoll, threads),
        }
        if args.reduced_only:
            cases = {k: cases[k] for k in ("r1", "mj")}
        flat = [c for group in cases.values() for c in group]
        rates = iter(interleaved(flat, args.repeat))
        got = {k: [next(rates) for _ in group] for k, group in cases.items()}
        for pool in pools:
            pool.close()
        (mj,) = got["mj"]
        if args.reduced_only:
            rows.append((f"{w} cart-poles, reduced, 1 substep", threads, *got["r1"], mj))
            continue
        (mj4,), (rk4,) = got["mj4"], got["rk4"]
        rows.append((f"{w} cart-poles", threads, *got["four"], mj))
        rows.append((f"{w} cart-poles, 1 substep", threads, *got["one"], mj))
        rows.append((f"{w} cart-poles, 1 substep; MuJoCo Euler at dt/4", threads, *got["one"], mj4))
        rows.append((f"{w} cart-poles; MuJoCo RK4", threads, *got["four"], rk4))
        rows.append((f"{w} cart-poles, reduced, 1 substep", threads, *got["r1"], mj))
        rows.append((f"{w} cart-poles, reduced, 4 substeps; MuJoCo at dt/4", threads, *got["r4"], mj4))
        rows.append((f"{ragdoll[0]} ragdolls", threads, *got["ragdoll"], None))
    print()
    head = (
        "case", "threads", "tumble step", "simulate", "simulate into out", "mujoco rollout",
        "step / rollout", "simulate / rollout", "into out / rollout",
    )
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for case, threads, step, rec, out, mj in rows:
        ratios = " | ".join(f"{x / mj:.2f}" if mj else "-" for x in (step, rec, out))
        mjs = f"{mj:,.0f}" if mj else "-"
        print(f"| {case} | {threads} | {step:,.0f} | {rec:,.0f} | {out:,.0f} | {mjs} | {ratios} |")
    print("\nworld-steps per second (W × steps / s), best of", args.repeat, "(interleaved)")
    load = os.getloadavg()
    print(f"load average after: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print(json.dumps({r[0] + f" x{r[1]}": r[2:] for r in rows}))
    accuracy()


if __name__ == "__main__":
    main()
