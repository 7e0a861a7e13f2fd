//! The engine's source keeps the shape docs/ARCHITECTURE.md promises: a strict import
//! stack (core < collision < dynamics < pipeline, no module importing one above it, no
//! circle among modules) and no function longer than a screen and a half.
//!
//! Reads `crates/tumble/src` as text: a `crate::a::b` path anywhere in a file (a `use` or
//! an inline path) is an import of the module it names. Comments are skipped.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The longest function allowed, counted from its `fn` line to its closing brace.
const MAX_FUNCTION_LINES: usize = 80;

/// The layers, lowest first; a module may import its own layer and those below.
const LAYERS: [&str; 4] = ["core", "collision", "dynamics", "pipeline"];

fn sources() -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    let mut dirs = vec![root.clone()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).expect("src is readable") {
            let path: PathBuf = entry.expect("entry").path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path
                    .strip_prefix(&root)
                    .unwrap()
                    .to_string_lossy()
                    .into_owned();
                let text = std::fs::read_to_string(&path).expect("source is text");
                files.push((rel.replace('\\', "/"), text));
            }
        }
    }
    files.sort();
    files
}

/// The module a file defines, as a path of names (`collision/shape/mod.rs` ->
/// `collision::shape`).
fn module_of(file: &str) -> Vec<String> {
    let stem = file.trim_end_matches(".rs");
    let mut parts: Vec<String> = stem.split('/').map(str::to_string).collect();
    if parts.last().is_some_and(|p| p == "mod" || p == "lib") {
        parts.pop();
    }
    parts
}

/// A module's unit: its layer directory and the module below it (`dynamics::solver`), or
/// a top-level file's own module (`math`).
fn unit_of(module: &[String]) -> String {
    match module {
        [layer, unit, ..] if LAYERS.contains(&layer.as_str()) => format!("{layer}::{unit}"),
        [top, ..] => top.clone(),
        [] => "lib".into(),
    }
}

/// The layer of a unit: its directory, or `core` for top-level files.
fn layer_of(unit: &str) -> usize {
    let first = unit.split("::").next().unwrap_or("");
    LAYERS.iter().position(|l| *l == first).unwrap_or(0)
}

/// The code of a file without `//` comments (string contents are kept: harmless here).
fn code_lines(text: &str) -> impl Iterator<Item = &str> {
    text.lines().map(|l| l.split("//").next().unwrap_or(""))
}

/// The `crate::...` paths a file names, cut to the longest prefix that is a module.
fn imports(text: &str, modules: &BTreeSet<Vec<String>>) -> BTreeSet<Vec<String>> {
    let mut out = BTreeSet::new();
    for line in code_lines(text) {
        for (at, _) in line.match_indices("crate::") {
            let rest = &line[at + "crate::".len()..];
            let path: Vec<String> = rest
                .split("::")
                .map(|p| {
                    p.chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect()
                })
                .take_while(|p: &String| !p.is_empty())
                .collect();
            let known = (1..=path.len())
                .rev()
                .find(|&n| modules.contains(&path[..n]));
            if let Some(n) = known {
                out.insert(path[..n].to_vec());
            }
        }
    }
    out
}

fn unit_graph() -> BTreeMap<String, BTreeSet<String>> {
    let files = sources();
    let modules: BTreeSet<Vec<String>> = files.iter().map(|(f, _)| module_of(f)).collect();
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (file, text) in &files {
        let from = unit_of(&module_of(file));
        if from == "lib" {
            continue;
        }
        let to: BTreeSet<String> = imports(text, &modules)
            .iter()
            .map(|m| unit_of(m))
            .filter(|u| *u != from && u != "lib")
            .collect();
        graph.entry(from).or_default().extend(to);
    }
    graph
}

#[test]
fn no_module_imports_a_layer_above_its_own() {
    let mut wrong = Vec::new();
    for (from, targets) in unit_graph() {
        for to in targets {
            if layer_of(&to) > layer_of(&from) {
                wrong.push(format!("{from} -> {to}"));
            }
        }
    }
    assert!(wrong.is_empty(), "imports up the stack: {wrong:?}");
}

#[test]
fn modules_import_each_other_in_no_circle() {
    let graph = unit_graph();
    // Depth-first search with colours; a grey node met again closes a circle.
    fn visit(
        node: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        colour: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        match colour.get(node) {
            Some(2) => return None,
            Some(1) => {
                let at = path.iter().position(|p| p == node).unwrap_or(0);
                let mut circle = path[at..].to_vec();
                circle.push(node.to_string());
                return Some(circle);
            }
            _ => {}
        }
        colour.insert(node.to_string(), 1);
        path.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            if let Some(c) = visit(next, graph, colour, path) {
                return Some(c);
            }
        }
        path.pop();
        colour.insert(node.to_string(), 2);
        None
    }
    let mut colour = BTreeMap::new();
    for node in graph.keys() {
        let circle = visit(node, &graph, &mut colour, &mut Vec::new());
        assert!(
            circle.is_none(),
            "import circle: {}",
            circle.unwrap().join(" -> ")
        );
    }
}

/// Every function's length in lines, from the line with `fn` to the one closing it.
fn function_lengths(text: &str) -> Vec<(usize, String, usize)> {
    let lines: Vec<&str> = code_lines(text).collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let after_fn = [
            "fn ",
            "pub fn ",
            "pub(crate) fn ",
            "pub(super) fn ",
            "const fn ",
        ]
        .iter()
        .chain(&["unsafe fn ", "pub(crate) unsafe fn ", "pub unsafe fn "])
        .find_map(|p| trimmed.strip_prefix(p));
        let Some(rest) = after_fn else { continue };
        let name: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let (mut depth, mut opened) = (0i64, false);
        for (j, l) in lines.iter().enumerate().skip(i) {
            for ch in l.chars() {
                match ch {
                    '{' => {
                        depth += 1;
                        opened = true;
                    }
                    '}' => depth -= 1,
                    ';' if !opened && depth == 0 => break,
                    _ => {}
                }
            }
            if !opened && l.contains(';') {
                break;
            }
            if opened && depth <= 0 {
                out.push((i + 1, name.clone(), j - i + 1));
                break;
            }
        }
    }
    out
}

#[test]
fn no_function_is_longer_than_a_screen_and_a_half() {
    let mut long = Vec::new();
    for (file, text) in sources() {
        for (line, name, n) in function_lengths(&text) {
            if n > MAX_FUNCTION_LINES {
                long.push(format!("{file}:{line} {name} ({n} lines)"));
            }
        }
    }
    assert!(
        long.is_empty(),
        "functions over {MAX_FUNCTION_LINES} lines: {long:?}"
    );
}

#[test]
fn the_checks_see_what_they_check() {
    // A function of 100 lines is measured as such; an import is found and cut to its
    // module; a file's unit and layer are what the layout says.
    let body: String = (0..98).map(|_| "    let x = 1;\n").collect();
    let text = format!("fn long() {{\n{body}}}\n");
    assert_eq!(function_lengths(&text), vec![(1, "long".to_string(), 100)]);
    let modules: BTreeSet<Vec<String>> = [vec!["dynamics".into(), "body".into()]].into();
    let found = imports(
        "use crate::dynamics::body::{Body, Motion}; // crate::x",
        &modules,
    );
    assert_eq!(
        found,
        [vec!["dynamics".to_string(), "body".to_string()]].into()
    );
    let unit = unit_of(&module_of("dynamics/solver/contact.rs"));
    assert_eq!((unit.as_str(), layer_of(&unit)), ("dynamics::solver", 2));
    assert_eq!(layer_of(&unit_of(&module_of("math.rs"))), 0);
}
