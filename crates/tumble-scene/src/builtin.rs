//! The built-in scenes, shared by the CLI, tests, benchmarks and the Python module.
//!
//! Each is the text of a file in the workspace's `scenes/` directory, compiled in with
//! `include_str!` so there is exactly one copy of every scene. A test checks that every
//! file in `scenes/` is listed here.

/// Name and JSON text of every built-in scene; the seed's free fall first.
const SCENES: [(&str, &str); 14] = [
    ("free_fall", include_str!("../../../scenes/free_fall.json")),
    ("spring", include_str!("../../../scenes/spring.json")),
    (
        "double_spring",
        include_str!("../../../scenes/double_spring.json"),
    ),
    (
        "dzhanibekov",
        include_str!("../../../scenes/dzhanibekov.json"),
    ),
    (
        "planar_spinner",
        include_str!("../../../scenes/planar_spinner.json"),
    ),
    ("dumbbell", include_str!("../../../scenes/dumbbell.json")),
    ("resting", include_str!("../../../scenes/resting.json")),
    ("door", include_str!("../../../scenes/door.json")),
    ("cradle", include_str!("../../../scenes/cradle.json")),
    (
        "rope_bridge",
        include_str!("../../../scenes/rope_bridge.json"),
    ),
    ("ragdoll", include_str!("../../../scenes/ragdoll.json")),
    ("pyramid", include_str!("../../../scenes/pyramid.json")),
    (
        "pendulum_chain",
        include_str!("../../../scenes/pendulum_chain.json"),
    ),
    (
        "character_course",
        include_str!("../../../scenes/character_course.json"),
    ),
];

/// The JSON text of the built-in scene `name`.
pub fn builtin(name: &str) -> Option<&'static str> {
    SCENES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, json)| *json)
}

/// The names of the built-in scenes, the seed's `free_fall` first.
pub fn builtin_names() -> Vec<&'static str> {
    SCENES.iter().map(|(n, _)| *n).collect()
}
