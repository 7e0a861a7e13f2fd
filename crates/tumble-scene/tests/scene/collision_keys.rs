//! The scene keys added for collision detection: static-only shapes and collision layers.

use tumble::{BodyKind, Shape};
use tumble_scene::load_str;

fn error(json: &str) -> String {
    match load_str(json) {
        Ok(_) => panic!("accepted {json}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn planes_meshes_and_height_fields_load_on_static_bodies() {
    let scene = load_str(
        r#"{"bodies": [
            {"kind": "static", "shape": {"type": "plane", "normal": [0, 2, 0], "offset": 1}},
            {"kind": "static", "shape": {"type": "trimesh", "vertices": [[0,0,0],[1,0,0],[0,0,1]], "indices": [[0,2,1]]}},
            {"kind": "static", "shape": {"type": "heightfield", "heights": [[0,1],[2,3]], "scale": [1, 0.5, 2]}},
            {"shape": {"type": "sphere", "radius": 1}, "collision_group": 2, "collision_mask": 6}
        ]}"#,
    )
    .unwrap();
    let bodies: Vec<_> = scene.world.bodies().map(|(_, b)| b).collect();
    // The plane's normal is stored unit length, its offset scaled with it.
    assert_eq!(bodies[0].shape(), &Shape::plane(tumble::Vec3::Y, 0.5));
    assert!(matches!(bodies[1].shape(), Shape::TriMesh(m) if m.indices() == [[0, 2, 1]]));
    assert!(
        matches!(bodies[2].shape(), Shape::HeightField(h) if h.rows() == 2 && h.cols() == 2 && h.heights() == [0.0, 1.0, 2.0, 3.0])
    );
    assert_eq!(bodies[3].collision_filter(), (2, 6));
    assert_eq!(bodies[3].kind(), BodyKind::Dynamic);
}

#[test]
fn collision_keys_are_checked_with_their_paths() {
    let plane = r#"{"type": "plane", "normal": [0, 1, 0]}"#;
    assert_eq!(
        error(&format!(r#"{{"bodies": [{{"shape": {plane}}}]}}"#)),
        "bodies[0].kind: a plane shape needs a static body"
    );
    assert_eq!(
        error(
            r#"{"bodies": [{"kind": "static", "shape": {"type": "plane", "normal": [0, 0, 0]}}]}"#
        ),
        "bodies[0].shape.normal: must be a non-zero vector"
    );
    assert_eq!(
        error(r#"{"bodies": [{"shape": {"type": "sphere", "radius": 1}, "collision_group": -1}]}"#),
        "bodies[0].collision_group: must be a whole number >= 0"
    );
    assert_eq!(
        error(
            r#"{"bodies": [{"shape": {"type": "sphere", "radius": 1}, "collision_mask": 4294967296}]}"#
        ),
        "bodies[0].collision_mask: must be at most 4294967295"
    );
    assert_eq!(
        error(
            r#"{"bodies": [{"kind": "static", "shape": {"type": "heightfield", "heights": [[0, 1], [2]]}}]}"#
        ),
        "bodies[0].shape.heights[1]: every row must have the same number of heights"
    );
    assert_eq!(
        error(
            r#"{"bodies": [{"kind": "static", "shape": {"type": "trimesh", "vertices": [[0,0,0]], "indices": [[0, 1]]}}]}"#
        ),
        "bodies[0].shape.indices[0]: expected 3 vertex indices"
    );
    assert!(error(r#"{"bodies": [{"kind": "static", "shape": {"type": "trimesh", "vertices": [[0,0,0],[1,0,0],[0,1,0]], "indices": [[0, 1, 5]]}}]}"#)
        .starts_with("bodies[0].shape.indices[0]: "));
    assert_eq!(
        error(r#"{"bodies": [{"shape": {"type": "compound", "children": [{"shape": {"type": "plane", "normal": [0, 1, 0]}}]}}]}"#),
        "bodies[0].shape.children[0].shape.type: planes, meshes and height fields cannot be compound children"
    );
}
