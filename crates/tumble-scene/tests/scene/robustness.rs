//! No scene text makes loading (or the first steps) panic: every leaf of every built-in
//! scene is replaced in turn by awkward values, and each result must load or be refused
//! with a one-line error.

use serde_json::{json, Value};
use tumble_scene::{builtin, builtin_names, load_str};

/// Values no scene author should write but some will.
fn awkward() -> Vec<Value> {
    let raw = ["1e400", "-1e400", "1e-320", "1e300", "-1e300"];
    let mut values: Vec<Value> = raw
        .iter()
        .map(|t| serde_json::from_str(t).unwrap())
        .collect();
    values.extend([
        json!(0),
        json!(-1),
        json!(-0.0),
        json!(1e-30),
        json!(12345),
        json!("x"),
        json!(null),
        json!(true),
        json!([]),
        json!([0, 0, 0]),
        json!({}),
    ]);
    values
}

/// Paths (as JSON pointers) to every leaf and every array or object of `v`.
fn pointers(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                pointers(item, format!("{at}/{i}"), out);
            }
        }
        Value::Object(map) => {
            for (k, item) in map {
                pointers(item, format!("{at}/{k}"), out);
            }
        }
        _ => {}
    }
    if !at.is_empty() {
        out.push(at);
    }
}

fn try_scene(text: &str) {
    match load_str(text) {
        Ok(mut scene) => {
            for _ in 0..3 {
                // A step may stop the run, with one line saying where; it may never leave
                // a value that is not finite. The character's move may refuse a step
                // (a displacement past the world's bounds) before the world's step.
                if let Err(e) = scene.step(scene.dt) {
                    let character = scene.character.is_some();
                    let refused = matches!(e, tumble::Error::InvalidField { .. });
                    assert!(
                        matches!(e, tumble::Error::Unstable(_)) || (character && refused),
                        "{e}"
                    );
                    assert_eq!(e.to_string().lines().count(), 1, "{e}");
                    break;
                }
            }
            for (_, b) in scene.world.bodies() {
                let q = b.orientation();
                let parts = [b.position(), b.linear_velocity(), b.angular_velocity()];
                assert!(
                    parts.iter().all(|v| v.is_finite()) && q.is_finite(),
                    "{text}"
                );
            }
        }
        Err(e) => assert_eq!(e.to_string().lines().count(), 1, "{e}"),
    }
}

#[test]
fn mutated_builtins_load_or_are_refused_without_panicking() {
    let values = awkward();
    for name in builtin_names() {
        let original: Value = serde_json::from_str(builtin(name).unwrap()).unwrap();
        let mut at = Vec::new();
        pointers(&original, String::new(), &mut at);
        for pointer in &at {
            for value in &values {
                let mut scene = original.clone();
                if let Some(slot) = scene.pointer_mut(pointer) {
                    *slot = value.clone();
                }
                try_scene(&scene.to_string());
            }
        }
    }
}

#[test]
fn truncated_text_is_refused_as_json() {
    let text = builtin("double_spring").unwrap();
    for end in (0..text.len()).step_by(7) {
        if let Some(prefix) = text.get(..end) {
            let e = load_str(prefix).unwrap_err();
            assert_eq!(e.field, "scene", "{e}");
        }
    }
}
