//! `tumble export-gltf`: the file is read back with the `gltf` crate (which validates it
//! against the glTF 2.0 schema and its index rules) and checked against the spec's layout
//! rules, against `tumble run --out` of the same run frame by frame, and against the
//! shapes' sizes and colours.

use std::collections::BTreeMap;
use std::path::Path;

use crate::common::{names, ok, one_line, path, refused, scratch};
use gltf::animation::util::{ReadOutputs, Rotations};
use serde_json::Value;

/// Every kind of shape, each kind of body, explicit colours and the palette's.
const SHAPES: &str = r##"{
  "name": "every shape",
  "dt": 0.01, "duration": 0.5,
  "bodies": [
    {"name": "ground", "kind": "static", "shape": {"type": "plane", "normal": [0, 1, 0]}},
    {"name": "terrain", "kind": "static", "position": [6, 0, 0],
     "shape": {"type": "heightfield", "heights": [[0, 0.5, 0], [0.2, 1, 0.1], [0, 0.3, 0]],
               "scale": [1.5, 0.5, 2]}},
    {"name": "ramp", "kind": "static", "position": [-6, 0, 0], "color": "#808080",
     "shape": {"type": "trimesh", "vertices": [[0, 0, 0], [2, 0, 0], [2, 1, 1], [0, 1, 1]],
               "indices": [[0, 1, 2], [0, 2, 3]]}},
    {"name": "ball", "shape": {"type": "sphere", "radius": 0.3}, "position": [0, 2, 0],
     "color": "#ff0000", "angular_velocity": [0, 3, 1]},
    {"name": "crate", "shape": {"type": "box", "half_extents": [0.4, 0.25, 0.15]},
     "position": [1.5, 1, 0], "orientation": [0.1, 0.2, 0.3, 0.9], "angular_velocity": [2, 0, 1]},
    {"name": "pill", "shape": {"type": "capsule", "radius": 0.2, "half_height": 0.35},
     "position": [-1.5, 1.5, 0], "velocity": [1, 0, 0]},
    {"name": "can", "shape": {"type": "cylinder", "radius": 0.25, "half_height": 0.4},
     "position": [0, 1.5, 1.5]},
    {"name": "cone", "shape": {"type": "convex_hull", "points": [[0, 0.6, 0], [0.3, -0.2, 0],
       [-0.3, -0.2, 0], [0, -0.2, 0.3], [0, -0.2, -0.3]]}, "position": [0, 1.5, -1.5]},
    {"name": "dumbbell", "shape": {"type": "compound", "children": [
       {"shape": {"type": "sphere", "radius": 0.2}, "position": [-0.5, 0, 0]},
       {"shape": {"type": "sphere", "radius": 0.2}, "position": [0.5, 0, 0]},
       {"shape": {"type": "cylinder", "radius": 0.05, "half_height": 0.5},
        "orientation": [0, 0, 0.7071067811865476, 0.7071067811865476]}]},
     "position": [1.5, 3, 1.5], "angular_velocity": [0, 0, 4]},
    {"name": "lift", "kind": "kinematic", "shape": {"type": "box", "half_extents": [0.5, 0.05, 0.5]},
     "position": [-1.5, 0.5, -1.5], "velocity": [0, 0.5, 0], "angular_velocity": [0, 1, 0]}
  ]
}"##;

/// The static bodies of [`SHAPES`].
const STATIC: [&str; 3] = ["ground", "terrain", "ramp"];

fn write_scene(dir: &Path) -> String {
    let file = dir.join("shapes.json");
    std::fs::write(&file, SHAPES).unwrap();
    path(&file).to_string()
}

/// `tumble run --out`'s rows per body: (time, [x, y, z, qx, qy, qz, qw]).
type Track = BTreeMap<String, Vec<(f64, [f64; 7])>>;

fn read_csv(file: &Path) -> Track {
    let text = std::fs::read_to_string(file).unwrap();
    let mut track = Track::new();
    for line in text.lines().skip(1) {
        let fields: Vec<&str> = line.split(',').collect();
        let num = |i: usize| fields[i].parse::<f64>().unwrap();
        let pose = [2, 3, 4, 5, 6, 7, 8].map(num);
        track
            .entry(fields[1].to_string())
            .or_default()
            .push((num(0), pose));
    }
    track
}

/// The GLB's JSON and BIN chunks, with the container's own rules checked on the way.
fn chunks(bytes: &[u8]) -> (Value, Vec<u8>) {
    let word = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(word(4), 2, "container version");
    assert_eq!(word(8), bytes.len(), "header length");
    let json_len = word(12);
    assert_eq!(&bytes[16..20], b"JSON");
    assert_eq!(json_len % 4, 0, "JSON chunk not 4-byte aligned");
    let json: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let at = 20 + json_len;
    let bin_len = word(at);
    assert_eq!(&bytes[at + 4..at + 8], b"BIN\0");
    assert_eq!(bin_len % 4, 0, "BIN chunk not 4-byte aligned");
    assert_eq!(at + 8 + bin_len, bytes.len(), "bytes after the BIN chunk");
    let declared = json["buffers"][0]["byteLength"].as_u64().unwrap() as usize;
    // The buffer may be up to 3 bytes shorter than its padded chunk (spec 4.4.3.3).
    assert!(
        declared <= bin_len && bin_len - declared < 4,
        "{declared} in {bin_len}"
    );
    assert!(
        json["buffers"][0].get("uri").is_none(),
        "a GLB's buffer has no uri"
    );
    (json, bytes[at + 8..at + 8 + declared].to_vec())
}

/// The layout rules of the spec on the JSON: views inside the buffer and 4-aligned,
/// accessors filling their views exactly with min and max of the right length,
/// samplers' inputs and outputs of one count.
fn check_layout(json: &Value, buffer_len: usize) {
    for view in json["bufferViews"].as_array().unwrap() {
        let (offset, len) = (
            view["byteOffset"].as_u64().unwrap(),
            view["byteLength"].as_u64().unwrap(),
        );
        assert_eq!(offset % 4, 0, "{view}");
        assert!(len > 0 && (offset + len) as usize <= buffer_len, "{view}");
    }
    let accessors = json["accessors"].as_array().unwrap();
    for a in accessors {
        let n = match a["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC3" => 3,
            "VEC4" => 4,
            other => panic!("{other}"),
        };
        // FLOAT for everything but vertex indices, UNSIGNED_INT; 4 bytes either way.
        assert!(
            a["componentType"] == 5126 || a["componentType"] == 5125,
            "{a}"
        );
        let count = a["count"].as_u64().unwrap();
        let view = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
        assert!(count >= 1);
        assert_eq!(count * n * 4, view["byteLength"].as_u64().unwrap(), "{a}");
        assert_eq!(a["min"].as_array().unwrap().len() as u64, n, "{a}");
        assert_eq!(a["max"].as_array().unwrap().len() as u64, n, "{a}");
    }
    for mesh in json["meshes"].as_array().unwrap() {
        let primitive = &mesh["primitives"][0];
        let indices = &accessors[primitive["indices"].as_u64().unwrap() as usize];
        assert_eq!(
            (&indices["componentType"], &indices["type"]),
            (&5125.into(), &"SCALAR".into())
        );
        let view = &json["bufferViews"][indices["bufferView"].as_u64().unwrap() as usize];
        assert_eq!(view["target"], 34963, "ELEMENT_ARRAY_BUFFER");
        let positions = &accessors[primitive["attributes"]["POSITION"].as_u64().unwrap() as usize];
        assert_eq!(
            indices["max"][0].as_u64().unwrap() + 1,
            positions["count"].as_u64().unwrap()
        );
    }
    for animation in json["animations"].as_array().unwrap() {
        for s in animation["samplers"].as_array().unwrap() {
            let input = &accessors[s["input"].as_u64().unwrap() as usize];
            let output = &accessors[s["output"].as_u64().unwrap() as usize];
            assert_eq!(input["count"], output["count"]);
            assert_eq!(s["interpolation"], "LINEAR");
        }
    }
    let nodes = json["nodes"].as_array().unwrap().len();
    let listed: Vec<u64> = json["scenes"][0]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_u64().unwrap())
        .collect();
    assert_eq!(
        listed,
        (0..nodes as u64).collect::<Vec<_>>(),
        "every node in the scene"
    );
}

fn f32s(v: &Value) -> Vec<f32> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap() as f32)
        .collect()
}

/// Exports [`SHAPES`] and runs it with the same options into a CSV: the file's nodes,
/// keyframe times and poses are the CSV's rows rounded to f32, bit for bit.
#[test]
fn a_run_reads_back_frame_by_frame_as_tumble_run_records_it() {
    let dir = scratch("gltf-frames");
    let scene = write_scene(&dir);
    let (glb, csv) = (dir.join("run.glb"), dir.join("run.csv"));
    // 0.43 s of 0.01 s steps, every 4th: steps 0, 4, ..., 40 and the last, 43, which is
    // off the grid and recorded as well, as `run` records it: 12 keyframes.
    let options = ["--duration", "0.43", "--every", "4"];
    ok(&[&["run", &scene, "--out", path(&csv)][..], &options].concat());
    let said = ok(&[&["export-gltf", &scene, "--out", path(&glb)][..], &options].concat());
    assert!(
        said.starts_with(&format!("wrote '{}' (", path(&glb))),
        "{said}"
    );
    assert!(said.ends_with("10 bodies, 12 keyframes)\n"), "{said}");
    let bytes = std::fs::read(&glb).unwrap();
    let (json, bin) = chunks(&bytes);
    check_layout(&json, bin.len());
    let doc = gltf::Gltf::from_slice(&bytes).expect("valid glTF 2.0");
    let track = read_csv(&csv);
    assert_eq!(doc.nodes().count(), track.len(), "a node per body");

    let animation = doc.animations().next().expect("one animation");
    assert_eq!(doc.animations().count(), 1);
    let moving = track.len() - STATIC.len();
    assert_eq!(
        animation.channels().count(),
        2 * moving,
        "translation and rotation each"
    );
    let mut animated = BTreeMap::new();
    for channel in animation.channels() {
        let name = channel.target().node().name().unwrap().to_string();
        assert!(!STATIC.contains(&name.as_str()), "{name} is static");
        let rows = &track[&name];
        let reader = channel.reader(|_| Some(&bin[..]));
        let times: Vec<f32> = reader.read_inputs().unwrap().collect();
        let expected: Vec<f32> = rows.iter().map(|(t, _)| *t as f32).collect();
        assert_eq!(times, expected, "{name}: times");
        assert_eq!(times.len(), 12);
        assert!(times.windows(2).all(|w| w[0] < w[1]), "strictly increasing");
        let poses: Vec<Vec<f32>> = match reader.read_outputs().unwrap() {
            ReadOutputs::Translations(t) => t.map(|p| p.to_vec()).collect(),
            ReadOutputs::Rotations(Rotations::F32(r)) => r.map(|q| q.to_vec()).collect(),
            _ => panic!("{name}: neither translation nor rotation"),
        };
        let path = channel.target().property();
        let fields = if poses[0].len() == 3 { 0..3 } else { 3..7 };
        for (frame, ((t, row), pose)) in rows.iter().zip(&poses).enumerate() {
            let expected: Vec<f32> = row[fields.clone()].iter().map(|x| *x as f32).collect();
            assert_eq!(pose, &expected, "{name} {path:?} at frame {frame}, t = {t}");
        }
        *animated.entry(name).or_insert(0) += 1;
    }
    assert!(animated.values().all(|n| *n == 2), "{animated:?}");
    assert_eq!(animated.len(), moving);

    // Every node stands where its body starts; a static body stays there.
    for node in doc.nodes() {
        let name = node.name().unwrap();
        let (t, r, _) = node.transform().decomposed();
        let rows = &track[name];
        for (time, row) in rows
            .iter()
            .filter(|_| STATIC.contains(&name))
            .chain(&rows[..1])
        {
            let expected = row.map(|x| x as f32);
            assert_eq!(t, expected[..3], "{name} at {time}");
            assert_eq!(r, expected[3..], "{name} at {time}");
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// (min, max) of a mesh's POSITION accessor, checked against the vertices themselves.
fn bounds(doc: &gltf::Gltf, bin: &[u8], name: &str) -> ([f32; 3], [f32; 3]) {
    let node = doc.nodes().find(|n| n.name() == Some(name)).unwrap();
    let primitive = node.mesh().expect(name).primitives().next().unwrap();
    let accessor = primitive.get(&gltf::Semantic::Positions).unwrap();
    let min: [f32; 3] = f32s(&accessor.min().unwrap()).try_into().unwrap();
    let max: [f32; 3] = f32s(&accessor.max().unwrap()).try_into().unwrap();
    let reader = primitive.reader(|_| Some(bin));
    let points: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    assert_eq!(indices.len() % 3, 0, "{name}: whole triangles");
    assert!(
        indices.iter().all(|i| (*i as usize) < points.len()),
        "{name}"
    );
    let mut distinct = points
        .iter()
        .map(|p| p.map(f32::to_bits))
        .collect::<Vec<_>>();
    distinct.sort();
    distinct.dedup();
    assert_eq!(
        distinct.len(),
        points.len(),
        "{name}: a vertex written twice"
    );
    if !STATIC.contains(&name) {
        // A closed surface, its faces turned one way: every edge a→b of a triangle is
        // met once, and b→a once, by its neighbour.
        let mut edges = BTreeMap::new();
        for t in indices.chunks_exact(3) {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for ((a, b), n) in &edges {
            assert_eq!(
                (*n, edges.get(&(*b, *a))),
                (1, Some(&1)),
                "{name}: edge {a}-{b}"
            );
        }
    }
    for i in 0..3 {
        // The spec's rule: min and max are the exact extremes of the data.
        assert_eq!(
            points.iter().map(|p| p[i]).fold(f32::INFINITY, f32::min),
            min[i],
            "{name}"
        );
        assert_eq!(
            points
                .iter()
                .map(|p| p[i])
                .fold(f32::NEG_INFINITY, f32::max),
            max[i],
            "{name}"
        );
    }
    (min, max)
}

/// The meshes span the shapes' sizes, every vertex once and closed shapes watertight
/// (see `bounds`): exactly (the same f64 → f32 rounding) for shapes
/// given by their corners; to 1e-6 m for the round ones, whose rim points come from f32
/// sines and cosines (errors of a few ulp of 0.3 m, ~1e-7 m). The quad of a plane lies in
/// it and spans at least 5 m either side.
#[test]
fn meshes_span_the_shapes() {
    let dir = scratch("gltf-meshes");
    let scene = write_scene(&dir);
    let glb = dir.join("run.glb");
    ok(&[
        "export-gltf",
        &scene,
        "--out",
        path(&glb),
        "--steps",
        "3",
        "--quiet",
    ]);
    let bytes = std::fs::read(&glb).unwrap();
    let (_, bin) = chunks(&bytes);
    let doc = gltf::Gltf::from_slice(&bytes).unwrap();
    let exact: [(&str, [f64; 3], [f64; 3]); 4] = [
        ("crate", [-0.4, -0.25, -0.15], [0.4, 0.25, 0.15]),
        ("cone", [-0.3, -0.2, -0.3], [0.3, 0.6, 0.3]),
        ("ramp", [0.0, 0.0, 0.0], [2.0, 1.0, 1.0]),
        // Samples at x = (c − 1)·1.5, z = (r − 1)·2, y = h·0.5 with h from 0 to 1.
        ("terrain", [-1.5, 0.0, -2.0], [1.5, 0.5, 2.0]),
    ];
    for (name, min, max) in exact {
        assert_eq!(
            bounds(&doc, &bin, name),
            (min.map(|x| x as f32), max.map(|x| x as f32))
        );
    }
    let round = [
        ("ball", [0.3, 0.3, 0.3]),
        ("pill", [0.2, 0.55, 0.2]),
        ("can", [0.25, 0.4, 0.25]),
        // Two balls of 0.2 at x = ±0.5 on a bar along x.
        ("dumbbell", [0.7, 0.2, 0.2]),
    ];
    for (name, half) in round {
        let (min, max) = bounds(&doc, &bin, name);
        for i in 0..3 {
            assert!(
                (max[i] - half[i]).abs() < 1e-6 && (min[i] + half[i]).abs() < 1e-6,
                "{name}: {min:?} {max:?}"
            );
        }
    }
    let (min, max) = bounds(&doc, &bin, "ground");
    assert_eq!((min[1], max[1]), (0.0, 0.0), "the quad lies in y = 0");
    assert!(min[0] <= -5.0 && min[2] <= -5.0 && max[0] >= 5.0 && max[2] >= 5.0);
    std::fs::remove_dir_all(dir).unwrap();
}

/// Each body's material is its colour as `tumble render` paints it (the scene's `color`,
/// else the palette's, kept in `extras.color`), sRGB decoded to glTF's linear base colour
/// (IEC 61966-2-1); only open surfaces (planes, meshes, height fields) are two-sided.
#[test]
fn materials_carry_the_render_colours() {
    let dir = scratch("gltf-colours");
    let scene = write_scene(&dir);
    let glb = dir.join("run.glb");
    ok(&[
        "export-gltf",
        &scene,
        "--out",
        path(&glb),
        "--steps",
        "1",
        "-q",
    ]);
    let doc = gltf::Gltf::from_slice(&std::fs::read(&glb).unwrap()).unwrap();
    let linear = |byte: u8| {
        let c = f64::from(byte) / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    for node in doc.nodes() {
        let name = node.name().unwrap();
        let material = node.mesh().unwrap().primitives().next().unwrap().material();
        assert_eq!(material.name(), Some(name));
        let factor = material.pbr_metallic_roughness().base_color_factor();
        let kind = if STATIC.contains(&name) {
            tumble::BodyKind::Static
        } else {
            tumble::BodyKind::Dynamic // the kinematic lift is coloured as a moving body
        };
        let hex = match name {
            "ball" => "#ff0000".to_string(),
            "ramp" => "#808080".to_string(),
            _ => tumble_render::palette(node.index(), kind).hex(),
        };
        let extras: Value =
            serde_json::from_str(material.extras().as_ref().unwrap().get()).unwrap();
        assert_eq!(extras["color"], hex.as_str(), "{name}");
        let bytes: Vec<u8> = (0..3)
            .map(|i| u8::from_str_radix(&hex[1 + 2 * i..3 + 2 * i], 16).unwrap())
            .collect();
        for i in 0..3 {
            // f32 powf against f64's: a few ulp of numbers below 1.
            assert!(
                (f64::from(factor[i]) - linear(bytes[i])).abs() < 1e-6,
                "{name}: {factor:?} for {hex}"
            );
        }
        assert_eq!(factor[3], 1.0);
        let open = STATIC.contains(&name);
        assert_eq!(
            material.double_sided(),
            open,
            "{name}: only open surfaces are two-sided"
        );
    }
    assert_eq!(linear(0x80), 0.21586050011389926);
    std::fs::remove_dir_all(dir).unwrap();
}

/// The base64 of a data URI, decoded (RFC 4648).
fn unbase64(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("{c} is not base64"),
    };
    let mut out = Vec::new();
    for group in text.as_bytes().chunks(4) {
        let digits: Vec<u8> = group
            .iter()
            .filter(|c| **c != b'=')
            .map(|c| value(*c))
            .collect();
        let word =
            digits.iter().fold(0u32, |w, d| w << 6 | u32::from(*d)) << (6 * (4 - digits.len()));
        out.extend(&word.to_be_bytes()[1..digits.len()]);
    }
    out
}

/// A `.gltf` is the `.glb`'s document with the same bytes as a base64 data URI; the same
/// export is the same file whatever the thread count.
#[test]
fn a_gltf_file_embeds_the_same_buffer_and_runs_are_reproducible() {
    let dir = scratch("gltf-text");
    let scene = write_scene(&dir);
    let (a, b, text) = (dir.join("a.glb"), dir.join("b.GLB"), dir.join("c.gltf"));
    let run = |out: &Path, threads: &str| {
        ok(&[
            "export-gltf",
            &scene,
            "--out",
            path(out),
            "--every",
            "7",
            "--threads",
            threads,
            "-q",
        ]);
        std::fs::read(out).unwrap()
    };
    let glb = run(&a, "1");
    assert_eq!(run(&b, "2"), glb, "bit-identical for 1 and 2 threads");
    let mut json: Value = serde_json::from_slice(&run(&text, "2")).unwrap();
    gltf::Gltf::from_slice(&std::fs::read(&text).unwrap()).expect("valid glTF 2.0");
    let (glb_json, bin) = chunks(&glb);
    let uri = json["buffers"][0]["uri"].as_str().unwrap().to_string();
    let data = uri
        .strip_prefix("data:application/octet-stream;base64,")
        .expect(&uri);
    assert_eq!(unbase64(data), bin);
    json["buffers"][0].as_object_mut().unwrap().remove("uri");
    assert_eq!(json, glb_json);
    assert_eq!(unbase64("Zm9vYmE="), b"fooba");
    std::fs::remove_dir_all(dir).unwrap();
}

/// A ball on a spring under explicit Euler with hω = 1, whose speed passes the engine's
/// limit after some thirty steps (as in failures.rs).
const UNSTABLE: &str = r#"{
  "dt": 0.01, "duration": 5, "integrator": "explicit_euler", "gravity": [0, 0, 0],
  "bodies": [{"name": "ball", "shape": {"type": "sphere", "radius": 0.1}, "mass": 1,
              "position": [0, 1, 0]}],
  "forces": [{"type": "spring", "body": "ball", "world_point": [0, 0, 0],
              "stiffness": 1e4, "rest_length": 0.99}]
}"#;

/// A run that fails part way exits 1 with `run`'s line, and the file holds it up to the
/// last good step, as the CSV does.
#[test]
fn a_failed_run_keeps_its_frames_to_the_last_good_step() {
    let dir = scratch("gltf-unstable");
    let scene = dir.join("stiff.json");
    std::fs::write(&scene, UNSTABLE).unwrap();
    let (glb, csv) = (dir.join("run.glb"), dir.join("run.csv"));
    let line = one_line(
        1,
        &[
            "run",
            path(&scene),
            "--out",
            path(&csv),
            "--every",
            "4",
            "-q",
        ],
    );
    assert_eq!(
        one_line(
            1,
            &[
                "export-gltf",
                path(&scene),
                "--out",
                path(&glb),
                "--every",
                "4",
                "-q"
            ]
        ),
        line
    );
    assert!(line.starts_with("step "), "{line}");
    let bytes = std::fs::read(&glb).unwrap();
    let doc = gltf::Gltf::from_slice(&bytes).unwrap();
    let (_, bin) = chunks(&bytes);
    let rows = &read_csv(&csv)["ball"];
    let channel = doc.animations().next().unwrap().channels().next().unwrap();
    let times: Vec<f32> = channel
        .reader(|_| Some(&bin[..]))
        .read_inputs()
        .unwrap()
        .collect();
    assert_eq!(
        times,
        rows.iter().map(|(t, _)| *t as f32).collect::<Vec<_>>()
    );
    let failed: u64 = line[5..].split(' ').next().unwrap().parse().unwrap();
    assert!(failed > 10, "{line}");
    // The last good step's time, k·dt: to an ulp, since the f32 build multiplies in f32.
    let last = f64::from(*times.last().unwrap());
    assert!(
        (last - (failed - 1) as f64 * 0.01).abs() < 1e-6,
        "{last}: {line}"
    );
    assert_eq!(names(&dir), ["run.csv", "run.glb", "stiff.json"]);
    std::fs::remove_dir_all(dir).unwrap();
}

/// Bad input: one line, exit 2, and nothing written.
#[test]
fn bad_input_is_one_line_and_writes_nothing() {
    let dir = scratch("gltf-refused");
    let out = dir.join("a.glb");
    let o = path(&out);
    let glb_scene = dir.join("scene.glb");
    std::fs::write(&glb_scene, r#"{"bodies": []}"#).unwrap();
    let d = path(&dir).to_string();
    let cases: Vec<(Vec<&str>, String)> = vec![
        (vec!["nope", "--out", o], "scene: 'nope' is neither a built-in scene (".into()),
        (vec!["spring", "--out", &d], format!("out: '{d}' is a folder; name a file")),
        (vec!["spring", "--out", "x.obj"], "out: 'x.obj': must end in .glb (binary glTF) or .gltf (JSON, buffer embedded)".into()),
        (vec!["spring", "--out", "no/such/a.glb"], "out: cannot create 'no/such/a.glb': the folder 'no/such' does not exist".into()),
        (vec![path(&glb_scene), "--out", path(&glb_scene)], format!("out: '{}' is the scene being read; name another file", path(&glb_scene))),
        (vec!["spring", "--out", o, "--every", "0"], "every: must be a whole number >= 1, got '0'".into()),
        (vec!["spring", "--out", o, "--dt", "-1"], "dt: must be".into()),
        (vec!["spring", "--out", o, "--steps", "3", "--duration", "1"], "steps: cannot be given together with --duration".into()),
        (vec!["spring", "--out", o, "--threads", "0"], "threads: must be a whole number from 1 to".into()),
        (vec!["spring"], "out: required; see 'tumble export-gltf --help'".into()),
        (vec!["spring", "--out", o, "--up", "x"], "up: 'x' is not a valid value".into()),
        // From 2^17 s on, 0.01 s is less than an f32 ulp (1/64 s): steps 13107201 and
        // 13107202 at 131072.02 s when k·dt is rounded from f64, 13107200 and 13107201 at
        // 131072 s in the f32 build, where k·dt is an f32 product (the end is below).
        (vec!["spring", "--out", o, "--steps", "20000000"], "every: steps 1310720".into()),
        // 10^8 + 2 keyframes of 4 + 28 bytes.
        (vec!["spring", "--out", o, "--steps", "100000000"], "every: 100000002 keyframes of 1 moving body would take 3200000064 bytes, more than the 1073741824 allowed; keyframe fewer steps with a larger --every".into()),
    ];
    for (args, expected) in cases {
        let line = refused(&[&["export-gltf"][..], &args].concat());
        assert!(line.starts_with(&expected), "{args:?}: {line}");
    }
    let line = refused(&["export-gltf", "spring", "--out", o, "--steps", "20000000"]);
    let tail = " s in f32, glTF's float for animation times; keyframe fewer steps with a \
                larger --every";
    assert!(
        line.contains(" are both at 131072") && line.ends_with(tail),
        "{line}"
    );
    assert_eq!(names(&dir), ["scene.glb"], "nothing written");
    std::fs::remove_dir_all(dir).unwrap();
}

/// A model's world: z up, gravity along −z.
const Z_UP: &str = r#"{
  "gravity": [0, 0, -9.81], "duration": 0.1,
  "bodies": [
    {"name": "floor", "kind": "static", "shape": {"type": "plane", "normal": [0, 0, 1]}},
    {"name": "link", "shape": {"type": "box", "half_extents": [0.1, 0.1, 0.5]}, "position": [1, 0, 2]}
  ]
}"#;

/// With gravity along −z the bodies hang under one node that turns +z to glTF's +y (auto,
/// or `--up z`); `--up y` writes them as they are. The bodies' own nodes and keyframes do
/// not change.
#[test]
fn a_z_up_scene_stands_up_under_one_node() {
    let dir = scratch("gltf-z-up");
    let scene = dir.join("model.json");
    std::fs::write(&scene, Z_UP).unwrap();
    let export = |up: &str, out: &str| {
        let out = dir.join(out);
        ok(&[
            "export-gltf",
            path(&scene),
            "--out",
            path(&out),
            "--up",
            up,
            "-q",
        ]);
        let bytes = std::fs::read(&out).unwrap();
        gltf::Gltf::from_slice(&bytes).expect("valid glTF 2.0");
        chunks(&bytes)
    };
    let (auto, bin) = export("auto", "auto.glb");
    let h = std::f32::consts::FRAC_1_SQRT_2;
    assert_eq!(auto["nodes"][2]["name"], "z-up");
    assert_eq!(f32s(&auto["nodes"][2]["rotation"]), [-h, 0.0, 0.0, h]);
    assert_eq!(auto["nodes"][2]["children"], serde_json::json!([0, 1]));
    assert_eq!(auto["scenes"][0]["nodes"], serde_json::json!([2]));
    assert_eq!(export("z", "z.glb"), (auto.clone(), bin.clone()));
    let (y, y_bin) = export("y", "y.glb");
    assert_eq!(y["nodes"].as_array().unwrap().len(), 2);
    assert_eq!(y["scenes"][0]["nodes"], serde_json::json!([0, 1]));
    assert_eq!(
        (&y["nodes"][1], &y["animations"]),
        (&auto["nodes"][1], &auto["animations"])
    );
    assert_eq!(y_bin, bin);
    // The link starts 2 m above the floor: in glTF's frame, 2 m up +y (the root's
    // rotation of (1, 0, 2) is (1, 2, 0), to f32 rounding of cos 90° ≈ 1e-8).
    let doc = gltf::Gltf::from_slice(&std::fs::read(dir.join("auto.glb")).unwrap()).unwrap();
    let root = doc.nodes().nth(2).unwrap().transform().matrix();
    let p = [1.0f32, 0.0, 2.0];
    let world: Vec<f32> = (0..3)
        .map(|r| (0..3).map(|c| root[c][r] * p[c]).sum::<f32>() + root[3][r])
        .collect();
    for (got, want) in world.iter().zip([1.0, 2.0, 0.0]) {
        assert!((got - want).abs() < 1e-6, "{world:?}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}
