"""tumble.sweep: serial and on a local Ray cluster of 2 workers give the same table; failed
runs keep their parameters and the loader's error; bad paths are refused up front; and the
command line's `tumble sweep` table equals the serial Python sweep's."""

import csv
import importlib
import io
import json
import math
import os
import subprocess
import sys

import pytest

import tumble

sweep_module = importlib.import_module("tumble.sweep")  # the module (tumble.sweep is also callable)

# Two balls dropped on the ground: bounces (restitution), contacts and sleeping.
SCENE = {
    "dt": 0.01,
    "duration": 0.6,
    "bodies": [
        {"name": "ground", "kind": "static", "shape": {"type": "plane", "normal": [0, 1, 0]}},
        {"name": "ball", "shape": {"type": "sphere", "radius": 0.1}, "mass": 1.0, "position": [0, 1, 0]},
        {"name": "box", "shape": {"type": "box", "half_extents": [0.1, 0.1, 0.1]}, "mass": 2.0,
         "position": [1, 0.5, 0], "angular_velocity": [0, 0, 3]},
    ],
}
GRID = {
    "bodies[ball].restitution": [0.0, 0.5, 0.9],
    "dt": [0.01, 0.005],
    "bodies[2].friction": [0.2, 0.8],
}


def metrics(world):
    ball, box = world.body("ball"), world.body("box")
    return {
        "ball_y": float(ball.position[1]),
        "ball_vy": float(ball.velocity[1]),
        "box_x": float(box.position[0]),
        "kinetic": float(world.diagnostics().kinetic),
    }


def records(table):
    """Rows as dicts with NaN and None both as None, for exact comparison."""
    rows = table.to_dict("records") if hasattr(table, "to_dict") else table
    clean = lambda v: None if v is None or (isinstance(v, float) and math.isnan(v)) else v  # noqa: E731
    return [{k: clean(v) for k, v in r.items()} for r in rows]


@pytest.fixture(scope="module")
def ray_cluster():
    """One local Ray cluster with 2 worker CPUs for the whole module (start-up is slow)."""
    ray = pytest.importorskip("ray")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield ray
    ray.shutdown()


def test_serial_equals_each_run_alone():
    table = tumble.sweep(SCENE, GRID, metrics, address="local-serial", progress=False)
    rows = records(table)
    assert len(rows) == 12
    assert list(rows[0]) == [*GRID, "ball_y", "ball_vy", "box_x", "kinetic", "error"]
    # Grid order: the first parameter varies slowest.
    assert [r["bodies[ball].restitution"] for r in rows] == [0.0] * 4 + [0.5] * 4 + [0.9] * 4
    assert [r["bodies[2].friction"] for r in rows[:4]] == [0.2, 0.8, 0.2, 0.8]
    for r in rows:
        doc = json.loads(json.dumps(SCENE))
        doc["bodies"][1]["restitution"] = r["bodies[ball].restitution"]
        doc["dt"] = r["dt"]
        doc["bodies"][2]["friction"] = r["bodies[2].friction"]
        w = tumble.World.from_json(json.dumps(doc))
        w.simulate()  # the scene's 0.6 s
        assert r == {**{p: r[p] for p in GRID}, **metrics(w), "error": None}
    # The parameters matter: the ball has bounced (at 0.43 s), each restitution elsewhere.
    assert len({r["ball_y"] for r in rows}) >= 6


def test_ray_equals_serial(ray_cluster):
    seen = []
    serial = tumble.sweep(SCENE, GRID, metrics, address="local-serial", progress=False)
    on_ray = tumble.sweep(SCENE, GRID, metrics, progress=lambda d, n, row: seen.append((d, n)))
    assert records(on_ray) == records(serial)  # bit for bit, in the grid's order
    assert sorted(seen) == [(k, 12) for k in range(1, 13)]


def test_failed_combination_is_reported(ray_cluster):
    grid = {"bodies[ball].shape.radius": [0.1, -0.5], "bodies[box].mass": [2.0, 0.0]}
    for address in (None, "local-serial"):
        rows = records(tumble.sweep(SCENE, grid, metrics, duration=0.1, address=address, progress=False))
        assert [(r["bodies[ball].shape.radius"], r["bodies[box].mass"]) for r in rows] == [
            (0.1, 2.0), (0.1, 0.0), (-0.5, 2.0), (-0.5, 0.0)]
        assert rows[0]["error"] is None and rows[0]["ball_y"] is not None
        assert rows[1]["error"].startswith("bodies[2].mass: ")
        assert rows[2]["error"] == "bodies[1].shape.radius: must be > 0"
        assert rows[2]["ball_y"] is None and rows[2]["kinetic"] is None


def test_bad_paths_give_loader_style_errors():
    run = lambda grid: tumble.sweep(SCENE, grid, metrics, use_ray=False, progress=False)  # noqa: E731
    with pytest.raises(ValueError, match=r"^bodies\[bal\]: no body named 'bal'$"):
        run({"bodies[bal].restitution": [0.1]})
    with pytest.raises(ValueError, match=r"^bodies\[7\]: index out of range \(bodies has 3 entries\)$"):
        run({"bodies[7].restitution": [0.1]})
    with pytest.raises(ValueError, match=r"^gravity\[3\]: index out of range"):
        run({"gravity[3]": [0.1]})
    with pytest.raises(ValueError, match=r"^bodies\.\.x: not a parameter path"):
        run({"bodies..x": [1]})
    with pytest.raises(ValueError, match=r"^dt: not an object, cannot take \.x$"):
        run({"dt.x": [1]})
    with pytest.raises(ValueError, match=r"^scene: 'nope' is neither a built-in scene"):
        tumble.sweep("nope", {"dt": [0.1]}, metrics, use_ray=False)
    with pytest.raises(ValueError, match=r"^metric: unknown metric 'ball.height'"):
        tumble.sweep(SCENE, {"dt": [0.1]}, ["ball.height"], use_ray=False)
    # The grid's own shape: a dict of path -> list of values.
    with pytest.raises(TypeError, match=r"^grid: must be a dict of path -> list of values, got list$"):
        run([("dt", [0.1])])
    with pytest.raises(TypeError, match=r"^grid: keys must be paths \(str\), got int$"):
        run({3: [0.1]})
    with pytest.raises(TypeError, match=r"^grid\['dt'\]: must be a list of values, got str$"):
        run({"dt": "0.1"})
    with pytest.raises(ValueError, match=r"^grid\['dt'\]: must hold at least one value$"):
        run({"dt": []})
    # An unknown key is the loader's error, for that run only.
    rows = records(tumble.sweep(SCENE, {"bodies[ball].bounce": [1]}, metrics, use_ray=False, progress=False))
    assert rows[0]["error"].startswith("bodies[1].bounce: unknown key")


def test_built_in_scene_and_file(tmp_path):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(SCENE))
    a = records(tumble.sweep(str(path), {"dt": [0.01]}, metrics, use_ray=False, progress=False))
    b = records(tumble.sweep(SCENE, {"dt": [0.01]}, metrics, use_ray=False, progress=False))
    assert a == b
    c = records(tumble.sweep("free_fall", {"gravity": [[0, -9.8, 0], [0, -1.6, 0]]}, ["ball.y"],
                             duration=1.0, use_ray=False, progress=False))
    # Symplectic Euler from rest: y(n h) = y0 - g h² n (n + 1) / 2, n = 100 steps of 0.01 s.
    for r, g in zip(c, (9.8, 1.6)):
        assert r["ball.y"] == pytest.approx(5 - g * 0.01**2 * 100 * 101 / 2, abs=1e-9)


BLOCK_URDF = (
    "<robot name='r'><link name='block'><inertial><mass value='2'/>"
    "<inertia ixx='0.1' iyy='0.1' izz='0.1' ixy='0' ixz='0' iyz='0'/></inertial>"
    "<collision><geometry><box size='0.2 0.2 0.2'/></geometry></collision></link></robot>"
)


def test_a_scene_files_models_are_read_from_its_folder(tmp_path, monkeypatch):
    # A scene file placing a URDF by a relative path, swept from another working directory:
    # the model is read next to the scene (as `tumble run` and `tumble sweep` read it), and
    # falls freely: y = 3 - g h² n (n + 1) / 2 after n = 50 symplectic Euler steps of 0.01 s.
    folder = tmp_path / "models"
    folder.mkdir()
    (folder / "block.urdf").write_text(BLOCK_URDF)
    scene = {"gravity": [0, -9.8, 0], "dt": 0.01, "bodies": [],
             "models": [{"file": "block.urdf", "position": [0, 3, 0], "fixed_base": False}]}
    (folder / "scene.json").write_text(json.dumps(scene))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    rows = records(tumble.sweep(str(folder / "scene.json"), {"dt": [0.01]}, ["block.y"],
                                duration=0.5, use_ray=False, progress=False))
    assert rows[0]["error"] is None, rows[0]["error"]
    assert rows[0]["block.y"] == pytest.approx(3 - 9.8 * 0.01**2 * 50 * 51 / 2, abs=1e-9)


CLI_SETS = ["bodies[ball].restitution=0,0.5,0.9", "bodies[0].friction=0.3,1", "gravity=[0,-9.8,0],[0,-3,0]"]
CLI_METRICS = ["ball.y", "ball.vy", "ball.max_y", "box.speed", "kinetic_energy", "asleep", "time"]


def cli_table(binary, scene, extra=(), env=None):
    args = [binary, "sweep", str(scene), "--duration", "0.5", "--quiet"]
    for s in CLI_SETS:
        args += ["--set", s]
    for m in CLI_METRICS:
        args += ["--metric", m]
    out = subprocess.run([*args, *extra], capture_output=True, text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stderr
    return list(csv.reader(io.StringIO(out.stdout)))


def as_numbers(rows):
    def num(cell):
        try:
            return float(cell)
        except ValueError:
            return cell
    return [[num(c) for c in r] for r in rows]


def test_cli_table_equals_serial_python(binary, tmp_path):
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(SCENE))
    table = cli_table(binary, scene)
    grid = {}
    for s in CLI_SETS:
        path, _, values = s.partition("=")
        grid[path] = sweep_module.split_values(values)
    py = tumble.sweep(SCENE, grid, CLI_METRICS, duration=0.5, use_ray=False, progress=False)
    want = list(csv.reader(io.StringIO(sweep_module.to_csv(py, list(grid), CLI_METRICS))))
    assert table[0] == [*grid, *CLI_METRICS, "error"]
    assert len(table) == 1 + 12
    assert as_numbers(table) == as_numbers(want)  # every number equal, bit for bit


def test_cli_errors(binary):
    def one_line(*args):
        out = subprocess.run([binary, "sweep", *args], capture_output=True, text=True)
        assert out.returncode == 2, out.stderr
        return out.stderr.strip()

    assert one_line("free_fall", "--set", "bodies[bal].mass=1", "--metric", "time") == (
        "bodies[bal]: no body named 'bal'")
    assert one_line("free_fall", "--set", "bodies[4].mass=1", "--metric", "time") == (
        "bodies[4]: index out of range (bodies has 1 entry)")
    assert one_line("free_fall", "--set", "dt", "--metric", "time") == (
        "set: expected PATH=V1,V2,..., got 'dt'")
    assert one_line("free_fall", "--set", "dt=0.1", "--metric", "ball.height").startswith(
        "metric: unknown metric 'ball.height'")
    # A bad value is that run's error; the others run.
    out = subprocess.run([binary, "sweep", "free_fall", "--set", "bodies[0].shape.radius=0.2,-1",
                          "--metric", "ball.y", "--quiet"], capture_output=True, text=True)
    rows = list(csv.reader(io.StringIO(out.stdout)))
    assert out.returncode == 0 and rows[2] == ["-1", "", "bodies[0].shape.radius: must be > 0"]
    assert rows[1][2] == "" and float(rows[1][1]) < 5


def test_cli_on_ray_equals_local(binary, ray_cluster, tmp_path):
    """`tumble sweep --ray ADDRESS` runs python -m tumble.sweep on the cluster (this
    module's, by its address) and writes the same table as the local run."""
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(SCENE))
    address = ray_cluster.get_runtime_context().gcs_address
    env = dict(os.environ, TUMBLE_PYTHON=sys.executable)
    on_ray = cli_table(binary, scene, ["--ray", address], env=env)
    assert as_numbers(on_ray) == as_numbers(cli_table(binary, scene))
