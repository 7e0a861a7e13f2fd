"""`tumble export-gltf` files load in trimesh (a glTF reader that is not Tumble's), with a
mesh per body of the shape's size and colour placed where `tumble run --out` starts it;
the keyframes, read with numpy from the GLB's chunks, are that CSV's rows in float32.

The binary is found as TUMBLE_BIN, else the newer of target/release/tumble and
target/debug/tumble (scripts/test.sh runs `cargo test`, which builds the latter, first),
else built with cargo."""

import csv
import json
import struct
import subprocess

import numpy as np
import pytest
import trimesh

SCENE = {
    "name": "gltf from python",
    "dt": 0.01,
    "duration": 0.25,
    "bodies": [
        {"name": "ground", "kind": "static", "shape": {"type": "plane", "normal": [0, 1, 0]}},
        {
            "name": "crate",
            "shape": {"type": "box", "half_extents": [0.5, 0.2, 0.3]},
            "position": [0, 1, 0],
            "orientation": [0, 0.3826834323650898, 0, 0.9238795325112867],
            "angular_velocity": [1, 2, 0],
            "color": "#ff0000",
        },
        {
            "name": "ball",
            "shape": {"type": "sphere", "radius": 0.25},
            "position": [1.5, 2, 0.5],
            "velocity": [0, 1, -1],
        },
        {
            "name": "pill",
            "shape": {"type": "capsule", "radius": 0.1, "half_height": 0.4},
            "position": [-1, 0.8, 0],
            "angular_velocity": [0, 0, 5],
        },
    ],
}

# Half sizes of each moving body's mesh in its own frame (m).
HALF = {"crate": [0.5, 0.2, 0.3], "ball": [0.25] * 3, "pill": [0.1, 0.5, 0.1]}


@pytest.fixture()
def run(binary, tmp_path):
    """The scene exported to run.glb and run to run.csv with the same options."""
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(SCENE))
    options = ["--every", "3"]
    glb, out = tmp_path / "run.glb", tmp_path / "run.csv"
    for command in (["export-gltf", str(scene), "--out", str(glb)], ["run", str(scene), "--out", str(out)]):
        result = subprocess.run([binary, *command, *options, "-q"], capture_output=True, text=True)
        assert result.returncode == 0, result.stderr
    rows = {}
    with open(out, newline="") as f:
        for row in csv.DictReader(f):
            rows.setdefault(row["body"], []).append(row)
    return glb, rows


def column(rows, names):
    return np.array([[float(r[n]) for n in names] for r in rows]).astype(np.float32)


def test_trimesh_loads_a_mesh_per_body_where_the_run_starts(run):
    glb, rows = run
    scene = trimesh.load(str(glb))
    assert isinstance(scene, trimesh.Scene)
    nodes = set(scene.graph.nodes_geometry)
    assert nodes == {"ground", "crate", "ball", "pill"}
    for name, half in HALF.items():
        transform, geometry = scene.graph[name]
        mesh = scene.geometry[geometry]
        # Corners given exactly, round rims from f32 sines: 1e-6 m is a few ulp of 0.5 m.
        np.testing.assert_allclose(mesh.bounds, [[-h for h in half], half], atol=1e-6)
        assert mesh.is_watertight, name
        start = rows[name][0]
        np.testing.assert_array_equal(
            transform[:3, 3].astype(np.float32), column([start], ["x", "y", "z"])[0]
        )
        x, y, z, w = column([start], ["qx", "qy", "qz", "qw"])[0].astype(np.float64)
        rotation = trimesh.transformations.quaternion_matrix([w, x, y, z])[:3, :3]
        # The file holds the quaternion in float32: its matrix is that close to the CSV's.
        np.testing.assert_allclose(transform[:3, :3], rotation, atol=1e-6)
    # The ground is a quad in y = 0, two triangles.
    transform, geometry = scene.graph["ground"]
    ground = scene.geometry[geometry]
    assert len(ground.faces) == 2
    np.testing.assert_array_equal(ground.vertices[:, 1], 0)
    # "#ff0000" is linear (1, 0, 0) in glTF; trimesh keeps it as 8-bit RGBA.
    crate = scene.geometry[scene.graph["crate"][1]]
    np.testing.assert_array_equal(crate.visual.material.baseColorFactor, [255, 0, 0, 255])


def glb_chunks(path):
    data = path.read_bytes()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    json_len, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON" and json_len % 4 == 0
    doc = json.loads(data[20 : 20 + json_len])
    bin_len, kind = struct.unpack_from("<I4s", data, 20 + json_len)
    assert kind == b"BIN\0" and bin_len % 4 == 0
    return doc, data[28 + json_len : 28 + json_len + bin_len]


def accessor(doc, blob, index):
    a = doc["accessors"][index]
    view = doc["bufferViews"][a["bufferView"]]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[a["type"]]
    assert a["componentType"] == 5126 and view["byteLength"] == 4 * width * a["count"]
    values = np.frombuffer(blob, "<f4", width * a["count"], view["byteOffset"])
    values = values.reshape(a["count"], width)
    np.testing.assert_array_equal(values.min(axis=0), np.float32(a["min"]))
    np.testing.assert_array_equal(values.max(axis=0), np.float32(a["max"]))
    return values


def test_keyframes_are_the_csv_rows_in_float32(run):
    glb, rows = run
    doc, blob = glb_chunks(glb)
    (animation,) = doc["animations"]
    names = [n["name"] for n in doc["nodes"]]
    seen = set()
    for channel in animation["channels"]:
        sampler = animation["samplers"][channel["sampler"]]
        name, path = names[channel["target"]["node"]], channel["target"]["path"]
        seen.add((name, path))
        times = accessor(doc, blob, sampler["input"])[:, 0]
        # 25 steps every 3rd: 0, 3, ..., 24 and the last, 25.
        assert len(times) == 10 and np.all(np.diff(times) > 0)
        np.testing.assert_array_equal(times, column(rows[name], ["time"])[:, 0])
        fields = ["x", "y", "z"] if path == "translation" else ["qx", "qy", "qz", "qw"]
        np.testing.assert_array_equal(accessor(doc, blob, sampler["output"]), column(rows[name], fields))
    assert seen == {(n, p) for n in HALF for p in ("translation", "rotation")}
