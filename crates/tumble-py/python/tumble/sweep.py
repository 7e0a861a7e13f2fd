"""Parameter sweeps: every combination of a grid of scene values, run on Ray or serially.

>>> import tumble
>>> table = tumble.sweep(
...     "free_fall",
...     grid={"bodies[ball].restitution": [0.0, 0.5], "dt": [0.01, 0.005]},
...     metrics=lambda w: {"y": float(w.body("ball").position[1])},
...     duration=0.5, address="local-serial")

A parameter is named by the path the scene loader's errors use (docs/scene-format.md,
"Errors"): ``gravity``, ``dt``, ``duration``, ``substeps``, ``bodies[3].restitution``,
``bodies[0].shape.radius``, ``gravity[1]``; a body (or force or joint) may be named by its
``name`` in place of its index, ``bodies[ball].restitution``. ``dt`` and ``duration`` are
the scene's own keys: the run takes steps of the scene's ``dt`` for ``duration`` seconds
(the argument, else the scene's ``duration``), cut as ``tumble run`` cuts it.

Each combination patches a copy of the scene's document, loads it (a bad value fails that
run with the loader's one-line error), steps it, and calls ``metrics(world)``, which
returns a dict of numbers. The table has a column per parameter (its path), per metric and
``error`` (None, or the run's error text; a failed run keeps its parameters). Rows come in
the grid's order: the first parameter varies slowest. Every run is independent and
deterministic, so the table is the same serially and on any number of Ray workers.

``metrics`` may also be a list of names from the command line's menu (see METRICS).

Command line (what ``tumble sweep --ray ADDRESS`` runs; needs this package and ray)::

    python -m tumble.sweep SCENE --set PATH=V1,V2 [--set ...] --metric NAME [...]
        [--duration T] [--ray ADDRESS] [--out table.csv] [--quiet]
"""

from __future__ import annotations

import argparse
import csv
import io
import itertools
import json
import math
import os
import re
import sys
import time
import types
from typing import Any, Callable, Iterable, Mapping, Optional, Sequence, Union

# The command line's menu of metrics, "BODY.QUANTITY" (BODY a name or an index) or a
# world-wide name; what each means is in docs/envs.md, "Parameter sweeps".
BODY_METRICS = ("x", "y", "z", "vx", "vy", "vz", "speed", "max_y")
WORLD_METRICS = ("kinetic_energy", "asleep", "time")
METRICS = tuple(f"BODY.{m}" for m in BODY_METRICS) + WORLD_METRICS

SERIAL = "local-serial"

Scene = Union[str, "os.PathLike[str]", Mapping[str, Any]]
Progress = Union[bool, Callable[[int, int, dict], None]]

_STEP = re.compile(r"([^.\[\]]+)|\[([^\[\]]*)\]|(\.)")


class PathError(ValueError):
    """A parameter path that does not name a field of the scene (loader-style message)."""


def load_document(scene: Scene) -> dict:
    """The scene's JSON document: a dict (copied), a built-in scene's name or a file path."""
    import tumble

    if isinstance(scene, Mapping):
        return json.loads(json.dumps(scene))
    name = os.fspath(scene)
    if name in tumble.SCENES:
        return json.loads(tumble._tumble.builtin_scene(name))
    try:
        with open(name, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise ValueError(
            f"scene: '{name}' is neither a built-in scene ({', '.join(tumble.SCENES)}) "
            f"nor a readable file ({e.strerror})"
        ) from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as e:
        raise ValueError(f"scene: invalid JSON at line {e.lineno} column {e.colno}: {e.msg}") from None


def scene_folder(scene: Scene) -> Optional[str]:
    """The folder a scene file's relative paths (its ``models`` files) are read from: the
    file's own, as the CLI reads them; None for a dict or a built-in scene."""
    import tumble

    if isinstance(scene, Mapping) or os.fspath(scene) in tumble.SCENES:
        return None
    return os.path.dirname(os.path.abspath(os.fspath(scene)))


def parse_path(path: str) -> list:
    """``bodies[ball].shape.radius`` -> ["bodies", "[ball]", "shape", "radius"]."""
    steps, pos, expect_key = [], 0, True
    for m in _STEP.finditer(path):
        if m.start() != pos:
            break
        pos = m.end()
        if m.group(1) is not None:
            if not expect_key:
                break
            steps.append(m.group(1))
            expect_key = False
        elif m.group(2) is not None:
            if not steps:
                break
            steps.append("[" + m.group(2) + "]")
        else:
            if expect_key:
                break
            expect_key = True
    if pos != len(path) or expect_key or not steps:
        raise PathError(f"{path}: not a parameter path (write it as bodies[ball].restitution)")
    return steps


def _index(items: list, where: str, token: str) -> int:
    """The element of `items` that `token` ([3] or [name]) names."""
    if re.fullmatch(r"-?\d+", token):
        i = int(token)
        if not 0 <= i < len(items):
            n = len(items)
            raise PathError(
                f"{where}[{i}]: index out of range ({where} has {n} {'entry' if n == 1 else 'entries'})"
            )
        return i
    for i, item in enumerate(items):
        if isinstance(item, dict) and item.get("name") == token:
            return i
    field = where.rsplit(".", 1)[-1]
    kind = {"bodies": "body", "forces": "force", "joints": "joint", "models": "model"}.get(field, "entry")
    raise PathError(f"{where}[{token}]: no {kind} named '{token}'")


def resolve(doc: dict, path: str) -> tuple:
    """(container, key, canonical path) of the field `path` names in `doc`.

    The canonical path uses indices, as the loader's errors do. Objects missing on the
    way are created (a body without "shape" options is given them); a step into
    something that is neither an object nor an array is a PathError.
    """
    steps = parse_path(path)
    node: Any = doc
    where = ""
    for n, step in enumerate(steps):
        last = n == len(steps) - 1
        if step.startswith("["):
            if not isinstance(node, list):
                raise PathError(f"{where or 'scene'}: not an array, cannot take {step}")
            i = _index(node, where, step[1:-1])
            here = f"{where}[{i}]"
            if last:
                return node, i, here
            node, where = node[i], here
        else:
            if not isinstance(node, dict):
                raise PathError(f"{where or 'scene'}: not an object, cannot take .{step}")
            here = f"{where}.{step}" if where else step
            if last:
                return node, step, here
            if step not in node:
                node[step] = [] if steps[n + 1].startswith("[") else {}
            node, where = node[step], here
    raise PathError(f"{path}: not a parameter path")  # pragma: no cover - steps is non-empty


def patched(doc: dict, params: Mapping[str, Any]) -> dict:
    """A copy of `doc` with each path of `params` set to its value."""
    out = json.loads(json.dumps(doc))
    for path, value in params.items():
        container, key, _ = resolve(out, path)
        container[key] = value
    return out


def _split_metric(name: str) -> tuple:
    body, _, what = name.rpartition(".")
    return body, what


def menu_metrics(names: Sequence[str]) -> Callable:
    """The metrics function of the command line's menu (see METRICS)."""
    for name in names:
        body, what = _split_metric(name)
        ok = (not body and what in WORLD_METRICS) or (body and what in BODY_METRICS)
        if not ok:
            raise ValueError(
                f"metric: unknown metric '{name}' (expected BODY.QUANTITY with QUANTITY one of "
                f"{', '.join(BODY_METRICS)}, or one of {', '.join(WORLD_METRICS)})"
            )

    def measure(world, heights=None) -> dict:
        out = {}
        for name in names:
            body, what = _split_metric(name)
            if not body:
                if what == "kinetic_energy":
                    out[name] = float(world.diagnostics().kinetic)
                elif what == "asleep":
                    out[name] = sum(1 for b in world.bodies if b.kind == "dynamic" and not b.awake)
                else:
                    out[name] = float(world.time)
                continue
            b = _body(world, body)
            if what == "max_y":
                out[name] = float(heights[b]) if heights is not None else float("nan")
                continue
            p, v = b.position.tolist(), b.velocity.tolist()
            value = {
                "x": p[0], "y": p[1], "z": p[2], "vx": v[0], "vy": v[1], "vz": v[2],
                "speed": math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]),
            }[what]
            out[name] = float(value)
        return out

    measure.menu = tuple(names)  # type: ignore[attr-defined]
    return measure


def _body(world, body: str):
    if re.fullmatch(r"\d+", body):
        bodies = world.bodies
        i = int(body)
        if i >= len(bodies):
            raise ValueError(f"metric: bodies[{i}]: index out of range ({len(bodies)} bodies)")
        return bodies[i]
    try:
        return world.body(body)
    except KeyError:
        raise ValueError(f"metric: no body named '{body}'") from None


def run_one(
    doc: dict,
    params: Mapping[str, Any],
    metrics: Any,
    duration: Optional[float],
    folder: Optional[str] = None,
) -> dict:
    """One combination: patch, load (relative paths from `folder`), step for `duration`,
    measure. Never raises: a failure is the row's ``error`` (the loader's or engine's one
    line, or the metric's exception)."""
    import numpy as np

    import tumble

    row: dict = {"params": dict(params), "metrics": {}, "error": None}
    try:
        world = tumble.World.from_json(json.dumps(patched(doc, params)), folder=folder)
        menu = getattr(metrics, "menu", None)
        wants_max = menu is not None and any(m.endswith(".max_y") for m in menu)
        if wants_max:
            # Every step's pose, step 0 included: the highest y each body's origin reached.
            traj = world.simulate(duration=duration, every=1)
            heights = {b: np.max(traj.position[:, i, 1]) for i, b in enumerate(world.bodies)}
            row["metrics"] = metrics(world, heights)
        else:
            n = _steps(world, duration)
            world.simulate(duration=duration, every=max(n, 1))
            row["metrics"] = metrics(world)
        if not isinstance(row["metrics"], Mapping):
            raise TypeError(f"metrics: must return a dict of numbers, got {type(row['metrics']).__name__}")
        row["metrics"] = dict(row["metrics"])
    except Exception as e:  # noqa: BLE001 - every failure is reported in the table
        row["metrics"] = {}
        row["error"] = str(e) if isinstance(e, (ValueError, TypeError, RuntimeError)) else repr(e)
    return row


def _steps(world, duration: Optional[float]) -> int:
    d = world.duration if duration is None else duration
    return int(math.ceil(d / world.dt)) if d > 0 and world.dt > 0 else 1


def combinations(grid: Mapping[str, Iterable[Any]]) -> list:
    """Every combination of the grid's values, the first parameter varying slowest."""
    if not isinstance(grid, Mapping):
        raise TypeError(f"grid: must be a dict of path -> list of values, got {type(grid).__name__}")
    for p in grid:
        if not isinstance(p, str):
            raise TypeError(f"grid: keys must be paths (str), got {type(p).__name__}")
    paths = list(grid)
    values = []
    for p in paths:
        v = grid[p]
        if isinstance(v, (str, bytes)) or not isinstance(v, Iterable):
            raise TypeError(f"grid[{p!r}]: must be a list of values, got {type(v).__name__}")
        v = list(v)
        if not v:
            raise ValueError(f"grid[{p!r}]: must hold at least one value")
        values.append(v)
    return [dict(zip(paths, combo)) for combo in itertools.product(*values)]


def _report(progress: Progress, done: int, total: int, row: dict) -> None:
    if callable(progress):
        progress(done, total, row)
    elif progress:
        params = ", ".join(f"{k}={v!r}" for k, v in row["params"].items())
        status = f"error: {row['error']}" if row["error"] else "ok"
        print(f"[{done}/{total}] {params}: {status}", file=sys.stderr, flush=True)


def _serial(doc, combos, metrics, duration, progress, folder) -> list:
    rows = []
    for combo in combos:
        rows.append(run_one(doc, combo, metrics, duration, folder))
        _report(progress, len(rows), len(combos), rows[-1])
    return rows


def _by_value(ray, metrics) -> None:
    """Sends the metrics function's module by value: a function from a script, a notebook
    or a test module is pickled with its code, so workers need not import that module."""
    mod = sys.modules.get(getattr(metrics, "__module__", None) or "")
    if mod is None or mod.__name__ in ("__main__", "builtins") or mod.__name__.startswith("tumble"):
        return
    try:
        ray.cloudpickle.register_pickle_by_value(mod)
    except (AttributeError, ValueError):  # pragma: no cover - an old cloudpickle, or a package
        pass


def _on_ray(doc, combos, metrics, duration, progress, address, num_cpus, folder) -> list:
    try:
        import ray
    except ImportError:
        raise ImportError("tumble.sweep on Ray needs ray: pip install 'tumble[sweep]'") from None
    started = not ray.is_initialized()
    if started:
        if address is None:
            ray.init(num_cpus=num_cpus, include_dashboard=False, log_to_driver=False)
        else:
            ray.init(address=address, log_to_driver=False)
    try:
        _by_value(ray, metrics)
        task = ray.remote(num_cpus=1)(run_one)
        doc_ref, metrics_ref = ray.put(doc), ray.put(metrics)
        pending = {
            task.remote(doc_ref, combo, metrics_ref, duration, folder): i for i, combo in enumerate(combos)
        }
        rows: list = [None] * len(combos)
        done = 0
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                i = pending.pop(ref)
                rows[i] = ray.get(ref)
                done += 1
                _report(progress, done, len(combos), rows[i])
        return rows
    finally:
        if started:
            ray.shutdown()


def table(rows: list, paths: Sequence[str]):
    """The rows as a pandas DataFrame (if pandas imports) or a list of dicts: the parameter
    paths, then the metric names in order of first appearance, then ``error``."""
    names: list = []
    for r in rows:
        for k in r["metrics"]:
            if k not in names and k not in paths and k != "error":
                names.append(k)
    flat = []
    for r in rows:
        d = {p: r["params"][p] for p in paths}
        for k in names:
            d[k] = r["metrics"].get(k)
        d["error"] = r["error"]
        flat.append(d)
    try:
        import pandas as pd
    except ImportError:
        return flat
    return pd.DataFrame(flat, columns=[*paths, *names, "error"])


def sweep(
    scene: Scene,
    grid: Mapping[str, Iterable[Any]],
    metrics: Union[Callable, Sequence[str]],
    duration: Optional[float] = None,
    address: Optional[str] = None,
    *,
    use_ray: Optional[bool] = None,
    num_cpus: int = 2,
    progress: Progress = True,
):
    """Runs every combination of `grid` on `scene` and returns the table of results.

    scene: a dict in the scene format, a scene file's path or a built-in scene's name.
    grid: {path: [values]}; paths as the loader's errors name fields (module notes).
    metrics: metrics(world) -> {name: number}, called at the end of each run (it travels
        to Ray's workers by pickling), or a list of the menu's names (METRICS).
    duration: seconds per run (None: the scene's ``duration``).
    address: a Ray cluster's address; None starts a local one with `num_cpus` workers
        (and shuts it down after), unless Ray is already initialised (then that is used);
        ``"local-serial"`` runs everything in this process without Ray (as use_ray=False).
    progress: True prints a line per finished run on stderr, False nothing; a callable
        is called as progress(done, total, row) with row = {"params", "metrics", "error"}.

    A path that names nothing in the scene (an unknown body, an index out of range) is a
    ValueError before anything runs; a bad value fails only its runs.
    """
    doc, folder = load_document(scene), scene_folder(scene)
    combos = combinations(grid)
    for path in grid:
        resolve(json.loads(json.dumps(doc)), path)
    if not callable(metrics):
        metrics = menu_metrics(list(metrics))
    if duration is not None and not (isinstance(duration, (int, float)) and math.isfinite(duration) and duration >= 0):
        raise ValueError(f"duration: must be a finite number >= 0, got {duration!r}")
    serial = use_ray is False or address == SERIAL
    if serial:
        rows = _serial(doc, combos, metrics, duration, progress, folder)
    else:
        rows = _on_ray(doc, combos, metrics, duration, progress, address, num_cpus, folder)
    return table(rows, list(grid))


def split_values(text: str) -> list:
    """``0.1,0.5,[0,-9.8,0]`` -> [0.1, 0.5, [0, -9.8, 0]]: commas outside brackets split;
    each piece is JSON if it parses, else a string."""
    pieces, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        if ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == "," and depth == 0:
            pieces.append(text[start:i])
            start = i + 1
    pieces.append(text[start:])
    out = []
    for p in pieces:
        p = p.strip()
        try:
            out.append(json.loads(p))
        except json.JSONDecodeError:
            out.append(p)
    return out


def _cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("nan" if math.isnan(v) else ("inf" if v > 0 else "-inf"))
    if isinstance(v, (list, dict)):
        return json.dumps(v, separators=(",", ":"))
    return str(v)


def to_csv(result, paths: Sequence[str], names: Sequence[str]) -> str:
    """The table as CSV, the same layout as ``tumble sweep --out``."""
    rows = result.to_dict("records") if hasattr(result, "to_dict") else result
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow([*paths, *names, "error"])
    for r in rows:
        err = r.get("error")
        err = None if err is None or (isinstance(err, float) and math.isnan(err)) else err
        cells = [r.get(k) for k in [*paths, *names]]
        cells = [None if err is not None and k in names else c for k, c in zip([*paths, *names], cells)]
        w.writerow([*map(_cell, cells), _cell(err)])
    return buf.getvalue()


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``python -m tumble.sweep``: the command line (exit 0; 2 on bad input)."""
    ap = argparse.ArgumentParser(prog="python -m tumble.sweep", description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--set", action="append", default=[], metavar="PATH=V1,V2,...")
    ap.add_argument("--metric", action="append", default=[], metavar="NAME")
    ap.add_argument("--duration", type=float, default=None)
    ap.add_argument("--ray", default=None, metavar="ADDRESS", help="'local' starts a local cluster")
    ap.add_argument("--out", default=None)
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)
    try:
        grid = {}
        for s in args.set:
            path, eq, values = s.partition("=")
            if not eq or not path or not values:
                raise ValueError(f"set: expected PATH=V1,V2,..., got '{s}'")
            grid[path] = split_values(values)
        if not grid:
            raise ValueError("set: give at least one --set PATH=V1,V2,...")
        if not args.metric:
            raise ValueError("metric: give at least one --metric NAME")
        address = None if args.ray in (None, "local") else args.ray
        t0 = time.perf_counter()
        result = sweep(
            args.scene, grid, list(args.metric), args.duration, address,
            use_ray=args.ray is not None, progress=not args.quiet,
        )
    except (ValueError, TypeError, ImportError) as e:
        print(str(e), file=sys.stderr)
        return 2
    text = to_csv(result, list(grid), list(args.metric))
    if args.out:
        tmp = args.out + ".partial"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, args.out)
    else:
        sys.stdout.write(text)
    if not args.quiet:
        print(f"{len(text.splitlines()) - 1} runs in {time.perf_counter() - t0:.2f} s", file=sys.stderr)
    return 0


class _CallableModule(types.ModuleType):
    """`tumble.sweep(...)` calls the function whether `tumble.sweep` is this module (after
    `import tumble.sweep`) or the package's lazy wrapper."""

    def __call__(self, *args, **kwargs):
        return sweep(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule

if __name__ == "__main__":
    sys.exit(main())
