//! MJCF text to an owned element tree: `<include>` spliced in, every element keeping its
//! file and line for messages; `<default>` classes and the attribute look-up through them;
//! numbers read with the element and attribute named in errors.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use tumble::Real;

use crate::error::{printable, Result, SceneError};

/// Deepest nesting of `<include>` accepted (a file including itself is caught earlier).
const MAX_INCLUDE_DEPTH: usize = 16;

/// One XML element with its attributes and element children.
#[derive(Debug, Clone)]
pub(crate) struct Elem {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Elem>,
    /// The file it was read from (its name, as messages show it).
    pub file: Rc<str>,
    pub line: u32,
}

impl Elem {
    /// The element's own attribute.
    pub fn own(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// `file:line: <tag name="...">`, the start of every message about this element.
    pub fn label(&self) -> String {
        let name = match self.own("name") {
            Some(n) => format!(" name=\"{}\"", printable(n)),
            None => String::new(),
        };
        format!("{}:{}: <{}{name}>", self.file, self.line, self.tag)
    }

    /// An error about this element: `file:line: <tag name="x">: reason`.
    pub fn err(&self, reason: impl Into<String>) -> SceneError {
        SceneError::new(self.label(), reason)
    }

    /// Children with the given tag.
    pub fn kids<'a>(&'a self, tag: &'a str) -> impl Iterator<Item = &'a Elem> + 'a {
        self.children.iter().filter(move |c| c.tag == tag)
    }
}

/// Reads `path` and every file it includes into one tree rooted at `<mujoco>`.
pub(crate) fn read(path: &Path) -> Result<Elem> {
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut stack = Vec::new();
    let root = read_file(path, &base, &mut stack, None)?;
    if root.tag != "mujoco" {
        return Err(root.err("the root element must be <mujoco>"));
    }
    Ok(root)
}

fn display_name(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string());
    printable(&name)
}

/// One file's root element, includes spliced in. `from`: the `<include>` naming it.
fn read_file(
    path: &Path,
    base: &Path,
    stack: &mut Vec<PathBuf>,
    from: Option<&Elem>,
) -> Result<Elem> {
    let shown = printable(&path.display().to_string());
    let fail = |reason: String| match from {
        Some(inc) => inc.err(format!("file: {reason}")),
        None => SceneError::new(display_name(path), reason),
    };
    if stack.len() >= MAX_INCLUDE_DEPTH || stack.iter().any(|p| p == path) {
        return Err(fail(format!("'{shown}' includes itself")));
    }
    let text =
        std::fs::read_to_string(path).map_err(|e| fail(format!("cannot read '{shown}': {e}")))?;
    let file: Rc<str> = display_name(path).into();
    let doc = roxmltree::Document::parse(&text).map_err(|e| {
        let pos = e.pos();
        SceneError::new(format!("{file}:{}", pos.row), format!("malformed XML: {e}"))
    })?;
    stack.push(path.to_path_buf());
    let root = convert(&doc, doc.root_element(), &file, base, stack);
    stack.pop();
    root
}

fn convert(
    doc: &roxmltree::Document<'_>,
    node: roxmltree::Node<'_, '_>,
    file: &Rc<str>,
    base: &Path,
    stack: &mut Vec<PathBuf>,
) -> Result<Elem> {
    let mut elem = Elem {
        tag: node.tag_name().name().to_string(),
        attrs: node
            .attributes()
            .map(|a| (a.name().to_string(), a.value().to_string()))
            .collect(),
        children: Vec::new(),
        file: file.clone(),
        line: doc.text_pos_at(node.range().start).row,
    };
    for child in node.children().filter(|n| n.is_element()) {
        let kid = convert(doc, child, file, base, stack)?;
        if kid.tag == "include" {
            elem.children.extend(include(&kid, base, stack)?);
        } else {
            elem.children.push(kid);
        }
    }
    Ok(elem)
}

/// The children of the included file's `<mujoco>`, to stand where the `<include>` stood.
/// MuJoCo resolves the path against the main file's directory.
fn include(inc: &Elem, base: &Path, stack: &mut Vec<PathBuf>) -> Result<Vec<Elem>> {
    let Some(name) = inc.own("file") else {
        return Err(inc.err("file: missing"));
    };
    let path = base.join(name);
    let root = read_file(&path, base, stack, Some(inc))?;
    if root.tag != "mujoco" {
        return Err(root.err("an included file's root element must be <mujoco>"));
    }
    Ok(root.children)
}

/// The `<default>` classes: per class, its parent and the attributes it gives each tag.
#[derive(Debug, Default)]
pub(crate) struct Defaults {
    classes: BTreeMap<String, DefaultClass>,
}

#[derive(Debug, Default)]
struct DefaultClass {
    parent: Option<String>,
    tags: BTreeMap<String, Vec<(String, String)>>,
}

/// The class every element without one uses.
pub(crate) const MAIN: &str = "main";

impl Defaults {
    /// Collects every `<default>` under the root (the outermost is class `main`).
    pub fn collect(root: &Elem) -> Result<Defaults> {
        let mut d = Defaults::default();
        d.classes.insert(MAIN.to_string(), DefaultClass::default());
        for top in root.kids("default") {
            d.add(top, None)?;
        }
        Ok(d)
    }

    fn add(&mut self, elem: &Elem, parent: Option<&str>) -> Result<()> {
        let name = match (elem.own("class"), parent) {
            (Some(c), _) => c.to_string(),
            (None, None) => MAIN.to_string(),
            (None, Some(_)) => return Err(elem.err("class: a nested <default> needs a class")),
        };
        if parent.is_some() && self.classes.contains_key(&name) {
            return Err(elem.err(format!("class: '{}' is defined twice", printable(&name))));
        }
        let entry = self.classes.entry(name.clone()).or_default();
        if parent.is_some() {
            entry.parent = parent.map(str::to_string);
        }
        for kid in &elem.children {
            if kid.tag == "default" {
                continue;
            }
            let attrs = entry.tags.entry(kid.tag.clone()).or_default();
            attrs.extend(kid.attrs.iter().cloned());
        }
        for kid in elem.kids("default") {
            self.add(kid, Some(&name))?;
        }
        Ok(())
    }

    /// Whether `class` is defined.
    pub fn has(&self, class: &str) -> bool {
        self.classes.contains_key(class)
    }

    /// The value `class` (or the nearest class it inherits from) gives `key` on `tag`.
    pub fn lookup(&self, class: &str, tag: &str, key: &str) -> Option<&str> {
        let mut current = Some(class);
        let mut hops = 0;
        while let (Some(name), true) = (current, hops < 64) {
            let c = self.classes.get(name)?;
            if let Some(v) = c
                .tags
                .get(tag)
                .and_then(|a| a.iter().rev().find(|(k, _)| k == key))
            {
                return Some(v.1.as_str());
            }
            current = c.parent.as_deref();
            hops += 1;
        }
        None
    }
}

/// An element seen through its default class: its own attributes first, then the class's.
#[derive(Clone, Copy)]
pub(crate) struct View<'a> {
    pub elem: &'a Elem,
    pub class: &'a str,
    pub defaults: &'a Defaults,
    /// The tag whose defaults apply (actuators share `general`'s).
    pub tag: &'a str,
}

impl<'a> View<'a> {
    /// `elem` with its class: its own `class`, else `inherited` (a body's `childclass`).
    pub fn new(elem: &'a Elem, inherited: &'a str, defaults: &'a Defaults) -> Result<View<'a>> {
        let class = elem.own("class").unwrap_or(inherited);
        if !defaults.has(class) {
            return Err(elem.err(format!(
                "class: no <default class=\"{}\">",
                printable(class)
            )));
        }
        Ok(View {
            elem,
            class,
            defaults,
            tag: &elem.tag,
        })
    }

    /// The attribute's text, the element's own or its class's.
    pub fn get(&self, key: &str) -> Option<&'a str> {
        self.elem
            .own(key)
            .or_else(|| self.defaults.lookup(self.class, self.tag, key))
    }

    /// An error naming this element and `key`.
    pub fn err(&self, key: &str, reason: impl Into<String>) -> SceneError {
        self.elem.err(format!("{key}: {}", reason.into()))
    }

    /// A list of numbers of length in `counts`.
    pub fn reals(&self, key: &str, counts: &[usize]) -> Result<Option<Vec<Real>>> {
        let Some(text) = self.get(key) else {
            return Ok(None);
        };
        let values = parse_reals(text)
            .map_err(|bad| self.err(key, format!("'{}' is not a number", printable(bad))))?;
        if !counts.contains(&values.len()) && !counts.is_empty() {
            let want: Vec<String> = counts.iter().map(|c| c.to_string()).collect();
            return Err(self.err(
                key,
                format!(
                    "expected {} numbers, got {}",
                    want.join(" or "),
                    values.len()
                ),
            ));
        }
        Ok(Some(values))
    }

    /// A single number.
    pub fn real(&self, key: &str) -> Result<Option<Real>> {
        Ok(self.reals(key, &[1])?.map(|v| v[0]))
    }

    /// A whole number (contype, conaffinity: bit sets).
    pub fn bits(&self, key: &str, default: u32) -> Result<u32> {
        match self.get(key) {
            None => Ok(default),
            Some(t) => t.trim().parse::<u32>().map_err(|_| {
                self.err(
                    key,
                    format!("'{}' is not a whole number >= 0", printable(t)),
                )
            }),
        }
    }

    /// `true`/`false` (and MuJoCo's `auto`, reported as `None`).
    pub fn flag(&self, key: &str) -> Result<Option<bool>> {
        match self.get(key) {
            None | Some("auto") => Ok(None),
            Some("true") => Ok(Some(true)),
            Some("false") => Ok(Some(false)),
            Some(t) => Err(self.err(
                key,
                format!("'{}' is not one of true, false, auto", printable(t)),
            )),
        }
    }
}

/// Whitespace-separated numbers; the first word that is not a finite number on failure.
fn parse_reals(text: &str) -> std::result::Result<Vec<Real>, &str> {
    text.split_whitespace()
        .map(|w| match w.parse::<Real>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(w),
        })
        .collect()
}
