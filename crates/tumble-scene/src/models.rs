//! The `models` section: model files placed in the scene,
//! `{"file": "arm.urdf", "position": [..], "orientation": [..], "fixed_base": true,
//! "merge_fixed": true, "prefix": "left_"}`. Files are found relative to the scene
//! file's folder; their links become bodies named as in the file (after `prefix`), which
//! the scene's `joints` and `forces` can refer to.

use std::path::Path;

use tumble::World;

use crate::error::{Result, SceneError};
use crate::reader::Obj;
use crate::urdf::{self, UrdfOptions};
use crate::FileKind;

const MODEL_KEYS: [&str; 6] = [
    "file",
    "position",
    "orientation",
    "fixed_base",
    "merge_fixed",
    "prefix",
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
        if FileKind::of(&file) != FileKind::Urdf {
            return Err(file_node.err("expected a model file ending in .urdf"));
        }
        let d = UrdfOptions::default();
        let opts = UrdfOptions {
            fixed_base: m.bool("fixed_base")?.unwrap_or(d.fixed_base),
            position: m.vec3("position")?.unwrap_or(d.position),
            orientation: m.quat("orientation")?.unwrap_or(d.orientation),
            merge_fixed: m.bool("merge_fixed")?.unwrap_or(d.merge_fixed),
            prefix: m.str("prefix")?.unwrap_or("").to_string(),
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
