//! The `models` section: model files placed in the scene,
//! `{"file": "arm.urdf", "position": [..], "orientation": [..], "fixed_base": true,
//! "merge_fixed": true, "prefix": "left_", "self_collision": false}`, or an MJCF file
//! (`.xml`) with `position`, `orientation` and `prefix` (its bodies float or are welded
//! as the file says and its geoms' `contype`/`conaffinity` say what collides, so
//! `fixed_base`, `merge_fixed` and `self_collision` do not apply; the scene's gravity and
//! integrator stay, the file's `<option>` is not read). Files are found relative to the scene file's
//! folder; their links (bodies) become bodies named as in the file (after `prefix`),
//! which the scene's `joints` and `forces` can refer to.

use std::path::Path;

use tumble::World;

use crate::error::{Result, SceneError};
use crate::mjcf::{self, MjcfOptions};
use crate::reader::{Node, Obj};
use crate::urdf::{self, UrdfOptions};
use crate::FileKind;

const MODEL_KEYS: [&str; 7] = [
    "file",
    "position",
    "orientation",
    "fixed_base",
    "merge_fixed",
    "prefix",
    "self_collision",
];

/// Adds every model of `obj`'s `models`, appending the bodies' labels to `names` and
/// colours to `colors`; returns the models' warnings.
pub(crate) fn add_models(
    obj: &Obj<'_>,
    dir: &Path,
    world: &mut World,
    names: &mut Vec<String>,
    colors: &mut Vec<Option<[u8; 3]>>,
) -> Result<Vec<String>> {
    let Some(models) = obj.get("models") else {
        return Ok(Vec::new());
    };
    let mut warnings = Vec::new();
    for node in models.array()? {
        let m = node.object()?;
        m.only(&MODEL_KEYS)?;
        let file_node = m.required("file")?;
        let file = dir.join(file_node.str()?);
        match FileKind::of(&file) {
            FileKind::Urdf => {}
            FileKind::Mjcf => {
                warnings.extend(add_mjcf(&node, &m, &file, world, names, colors)?);
                continue;
            }
            FileKind::Scene => {
                return Err(file_node.err("expected a model file ending in .urdf or .xml (MJCF)"))
            }
        }
        let d = UrdfOptions::default();
        let opts = UrdfOptions {
            fixed_base: m.bool("fixed_base")?.unwrap_or(d.fixed_base),
            position: m.vec3("position")?.unwrap_or(d.position),
            orientation: m.quat("orientation")?.unwrap_or(d.orientation),
            merge_fixed: m.bool("merge_fixed")?.unwrap_or(d.merge_fixed),
            prefix: m.str("prefix")?.unwrap_or("").to_string(),
            self_collision: m.bool("self_collision")?.unwrap_or(d.self_collision),
        };
        let imported = urdf::load(&file, world, &opts)
            .map_err(|e| SceneError::new(format!("{}: {}", node.path(), e.field), e.reason))?;
        for id in &imported.created {
            let body = world.body(*id).expect("just created");
            names.push(body.name().unwrap_or_default().to_string());
        }
        colors.extend(imported.colors);
        warnings.extend(imported.warnings);
    }
    Ok(warnings)
}

/// One MJCF model of the list: placed, prefixed, without the file's `<option>`.
fn add_mjcf(
    node: &Node<'_>,
    m: &Obj<'_>,
    file: &Path,
    world: &mut World,
    names: &mut Vec<String>,
    colors: &mut Vec<Option<[u8; 3]>>,
) -> Result<Vec<String>> {
    for key in ["fixed_base", "merge_fixed"] {
        if let Some(n) = m.get(key) {
            return Err(n.err("not used for MJCF models (the file says which bodies move)"));
        }
    }
    if let Some(n) = m.get("self_collision") {
        return Err(n.err(
            "not used for MJCF models (the geoms' contype and conaffinity say what collides)",
        ));
    }
    let d = MjcfOptions::default();
    let opts = MjcfOptions {
        position: m.vec3("position")?.unwrap_or(d.position),
        orientation: m.quat("orientation")?.unwrap_or(d.orientation),
        world_settings: false,
        prefix: m.str("prefix")?.unwrap_or("").to_string(),
    };
    let imported = mjcf::load(file, world, &opts)
        .map_err(|e| SceneError::new(format!("{}: {}", node.path(), e.field), e.reason))?;
    for (id, color) in &imported.colors {
        let body = world.body(*id).expect("just created");
        names.push(body.name().unwrap_or_default().to_string());
        colors.push(*color);
    }
    Ok(imported.warnings.iter().map(ToString::to_string).collect())
}
