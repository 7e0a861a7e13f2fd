//! A scene fuzzer: built-in scenes and the corpus, mutated the way a new user's mistakes
//! (and a hostile file) would mutate them, through the JSON reader, the loader and the
//! first steps of the run. What must hold for every input: no panic; a refusal is one
//! line; a run either finishes with every state finite or stops with the one-line
//! unstable-step error, never with a value that is not finite.
//!
//! The test command runs a short budget (`PROPTEST_CASES`, default 256 cases of up to 6
//! mutations each). A long run, for after a change to the reader, loader or step:
//!
//! ```sh
//! PROPTEST_CASES=20000 cargo test --release -p tumble-scene --test fuzz
//! ```

use proptest::prelude::*;
use serde_json::{json, Value};
use tumble_scene::{builtin, builtin_names, load_str};

/// A number anywhere on the float scale, or just past it, written as text.
fn number() -> impl Strategy<Value = Value> {
    prop_oneof![
        (-320i32..=310, any::<bool>()).prop_map(|(e, neg)| {
            let text = format!("{}1e{e}", if neg { "-" } else { "" });
            serde_json::from_str(&text).unwrap()
        }),
        (-1e3f64..1e3).prop_map(|x| json!(x)),
        prop_oneof![Just(0.0), Just(-0.0), Just(1.0), Just(-1.0)].prop_map(|x| json!(x)),
        Just(serde_json::from_str("1e400").unwrap()),
        any::<i64>().prop_map(|x| json!(x)),
    ]
}

/// Any JSON leaf or small structure.
fn value() -> impl Strategy<Value = Value> {
    let leaf = prop_oneof![
        4 => number(),
        1 => Just(Value::Null),
        1 => any::<bool>().prop_map(Value::Bool),
        1 => "[a-z_\\n\\t\"\\\\ 0-9\u{202e}]{0,12}".prop_map(Value::String),
    ];
    leaf.prop_recursive(2, 8, 4, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..5).prop_map(Value::Array),
            prop::collection::vec(number(), 3..=4).prop_map(Value::Array),
        ]
    })
}

/// Paths to every node of `v` below the root.
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

/// One edit: replace the node at a pointer (by index into the list of pointers), remove
/// it, or duplicate an array's element.
#[derive(Debug, Clone)]
enum Edit {
    Replace(usize, Value),
    Remove(usize),
    Duplicate(usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        6 => (any::<usize>(), value()).prop_map(|(i, v)| Edit::Replace(i, v)),
        1 => any::<usize>().prop_map(Edit::Remove),
        1 => any::<usize>().prop_map(Edit::Duplicate),
    ]
}

fn apply(scene: &mut Value, edit: &Edit) {
    let mut at = Vec::new();
    pointers(scene, String::new(), &mut at);
    if at.is_empty() {
        return;
    }
    let pick = |i: usize| at[i % at.len()].clone();
    match edit {
        Edit::Replace(i, v) => {
            if let Some(slot) = scene.pointer_mut(&pick(*i)) {
                *slot = v.clone();
            }
        }
        Edit::Remove(i) | Edit::Duplicate(i) => {
            let p = pick(*i);
            let (parent, key) = p.rsplit_once('/').unwrap();
            match scene.pointer_mut(parent) {
                Some(Value::Object(map)) if matches!(edit, Edit::Remove(_)) => {
                    map.remove(key);
                }
                Some(Value::Array(items)) => {
                    let k: usize = key.parse().unwrap();
                    if matches!(edit, Edit::Remove(_)) {
                        items.remove(k);
                    } else {
                        let copy = items[k].clone();
                        items.insert(k, copy);
                    }
                }
                _ => {}
            }
        }
    }
}

/// Small scenes only (the run is part of the check, and the budget is seconds).
fn seeds() -> Vec<Value> {
    let mut out: Vec<Value> = builtin_names()
        .into_iter()
        .filter(|n| !["pyramid", "rope_bridge", "pendulum_chain"].contains(n))
        .map(|n| serde_json::from_str(builtin(n).unwrap()).unwrap())
        .collect();
    let corpus = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus");
    let mut files: Vec<_> = std::fs::read_dir(corpus)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for f in files {
        out.push(serde_json::from_str(&std::fs::read_to_string(f).unwrap()).unwrap());
    }
    out
}

fn check(text: &str) -> Result<(), TestCaseError> {
    let mut scene = match load_str(text) {
        Ok(scene) => scene,
        Err(e) => {
            let line = e.to_string();
            prop_assert_eq!(line.lines().count(), 1, "{}", line);
            prop_assert!(line.len() < 400, "{}", line);
            return Ok(());
        }
    };
    for _ in 0..20 {
        if let Err(e) = scene.world.step(scene.dt) {
            let line = e.to_string();
            prop_assert!(matches!(e, tumble::Error::Unstable(_)), "{}", line);
            prop_assert_eq!(line.lines().count(), 1, "{}", line);
            break;
        }
    }
    // The invariant every step keeps: finite, within the world, within the speed limits.
    let limits = scene.world.speed_limits();
    for (_, b) in scene.world.bodies() {
        let parts = [b.position(), b.linear_velocity(), b.angular_velocity()];
        let finite = parts.iter().all(|v| v.is_finite()) && b.orientation().is_finite();
        prop_assert!(finite, "a state that is not finite from {}", text);
        prop_assert!(b.position().abs().max_element() <= tumble::limits::MAX_COORDINATE);
        prop_assert!(b.linear_velocity().length() <= limits.max_speed, "{}", text);
        prop_assert!(
            b.angular_velocity().length() <= limits.max_angular_speed,
            "{}",
            text
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(256),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn mutated_scenes_load_or_are_refused_and_never_run_to_nan(
        seed in any::<usize>(),
        edits in prop::collection::vec(edit(), 1..=6),
    ) {
        let seeds = seeds();
        let mut scene = seeds[seed % seeds.len()].clone();
        for e in &edits {
            apply(&mut scene, e);
        }
        check(&scene.to_string())?;
    }
}
