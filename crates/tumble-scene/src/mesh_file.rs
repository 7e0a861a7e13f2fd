//! Mesh files: Wavefront OBJ and STL (ASCII and binary) read into vertices and
//! triangles, as model files (URDF, MJCF) refer to them.
//!
//! Only geometry is read: OBJ's `v` and `f` lines (polygons split into fans, `v/vt/vn`
//! and negative indices understood; every other line skipped), STL's facets (normals
//! ignored: the winding is what the hull builder and the mesh shape use). A file is
//! binary STL when its size is exactly 84 + 50 n bytes for the n its header states,
//! whatever its first five bytes say (binary files beginning with `solid` exist);
//! otherwise it is read as ASCII STL. Errors name the file and, for text, the line:
//! `link.obj:7: f: index 9 out of range (8 vertices)`.

use std::path::Path;

use tumble::{Real, Vec3};

use crate::error::{printable, Result, SceneError};

/// A mesh as read: vertices (file units) and triangles indexing them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions, as the file gives them.
    pub vertices: Vec<Vec3>,
    /// Triangles, three indices into `vertices` each.
    pub triangles: Vec<[u32; 3]>,
}

/// The largest mesh read: 10 million triangles (500 MB of binary STL).
pub const MAX_TRIANGLES: usize = 10_000_000;

/// Reads an OBJ or STL file, chosen by its extension (`.obj`, `.stl`, any case).
pub fn read_mesh(path: &Path) -> Result<MeshData> {
    let name = printable(&path.display().to_string());
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let bytes = std::fs::read(path)
        .map_err(|e| SceneError::new(name.clone(), format!("cannot read mesh file: {e}")))?;
    let mesh = match ext.as_deref() {
        Some("obj") => read_obj(&name, &String::from_utf8_lossy(&bytes))?,
        Some("stl") => read_stl(&name, &bytes)?,
        _ => {
            return Err(SceneError::new(
                name,
                "unsupported mesh format (expected .obj or .stl)",
            ))
        }
    };
    if mesh.triangles.is_empty() {
        return Err(SceneError::new(name, "mesh has no triangles"));
    }
    Ok(mesh)
}

/// The triangles of `triangles` that have an area, as `TriMesh::new` judges it: exported
/// meshes often hold slivers (three corners on a line, or two the same), which add nothing
/// to a static mesh's surface but which the engine's mesh refuses.
pub(crate) fn with_area(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    triangles
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            tumble::TriMesh::has_area(a, b, c)
        })
        .copied()
        .collect()
}

fn line_err(name: &str, line: usize, reason: impl Into<String>) -> SceneError {
    SceneError::new(format!("{name}:{line}"), reason)
}

/// Three finite numbers from `words`.
fn point(name: &str, line: usize, words: &[&str]) -> Result<Vec3> {
    let mut xyz = [0.0 as Real; 3];
    for (i, slot) in xyz.iter_mut().enumerate() {
        let word = words
            .get(i)
            .ok_or_else(|| line_err(name, line, "expected three coordinates"))?;
        *slot = word
            .parse::<Real>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| {
                line_err(
                    name,
                    line,
                    format!("'{}' is not a finite number", printable(word)),
                )
            })?;
    }
    Ok(Vec3::from_array(xyz))
}

/// Wavefront OBJ: `v x y z [w]` and `f i j k ...` (1-based, negative from the end).
pub fn read_obj(name: &str, text: &str) -> Result<MeshData> {
    let mut mesh = MeshData::default();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let words: Vec<&str> = raw.split_whitespace().collect();
        match words.first() {
            Some(&"v") => mesh.vertices.push(point(name, line, &words[1..])?),
            Some(&"f") => {
                let mut face = Vec::with_capacity(words.len() - 1);
                for word in &words[1..] {
                    face.push(obj_index(name, line, word, mesh.vertices.len())?);
                }
                // A face of fewer than 3 vertices encloses nothing: skipped.
                for k in 1..face.len().saturating_sub(1) {
                    mesh.triangles.push([face[0], face[k], face[k + 1]]);
                }
                if mesh.triangles.len() > MAX_TRIANGLES {
                    return Err(line_err(name, line, "more than 10 million triangles"));
                }
            }
            _ => {}
        }
    }
    Ok(mesh)
}

/// One `f` entry, `i`, `i/t`, `i//n` or `i/t/n`, as a 0-based index.
fn obj_index(name: &str, line: usize, word: &str, count: usize) -> Result<u32> {
    let first = word.split('/').next().unwrap_or("");
    let bad = || {
        line_err(
            name,
            line,
            format!(
                "f: index '{}' out of range ({count} vertices so far)",
                printable(first)
            ),
        )
    };
    let i: i64 = first.parse().map_err(|_| bad())?;
    let index = match i {
        1.. => i - 1,
        ..=-1 => count as i64 + i,
        0 => return Err(bad()),
    };
    if index < 0 || index >= count as i64 {
        return Err(bad());
    }
    Ok(index as u32)
}

/// STL, binary or ASCII (see the module's note on telling them apart).
pub fn read_stl(name: &str, bytes: &[u8]) -> Result<MeshData> {
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if bytes.len() as u64 == 84 + 50 * n as u64 {
            return read_binary_stl(name, &bytes[84..], n);
        }
    }
    if !bytes.trim_ascii_start().starts_with(b"solid") {
        return Err(SceneError::new(
            name,
            "neither binary STL (size is not 84 + 50 × its triangle count) nor ASCII STL (no 'solid')",
        ));
    }
    read_ascii_stl(name, &String::from_utf8_lossy(bytes))
}

fn read_binary_stl(name: &str, body: &[u8], n: usize) -> Result<MeshData> {
    if n > MAX_TRIANGLES {
        return Err(SceneError::new(name, "more than 10 million triangles"));
    }
    let mut mesh = MeshData::default();
    for (t, facet) in body.chunks_exact(50).enumerate() {
        let mut tri = [0u32; 3];
        for (k, slot) in tri.iter_mut().enumerate() {
            let mut xyz = [0.0 as Real; 3];
            for (c, x) in xyz.iter_mut().enumerate() {
                let at = 12 + 12 * k + 4 * c;
                let raw = [facet[at], facet[at + 1], facet[at + 2], facet[at + 3]];
                *x = Real::from(f32::from_le_bytes(raw));
            }
            let p = Vec3::from_array(xyz);
            if !p.is_finite() {
                return Err(SceneError::new(
                    name,
                    format!("triangle {t}: vertex {k} is not finite"),
                ));
            }
            *slot = mesh.vertices.len() as u32;
            mesh.vertices.push(p);
        }
        mesh.triangles.push(tri);
    }
    Ok(mesh)
}

fn read_ascii_stl(name: &str, text: &str) -> Result<MeshData> {
    let mut mesh = MeshData::default();
    let mut corners: Vec<u32> = Vec::with_capacity(3);
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let words: Vec<&str> = raw.split_whitespace().collect();
        match words.first() {
            Some(&"vertex") => {
                corners.push(mesh.vertices.len() as u32);
                mesh.vertices.push(point(name, line, &words[1..])?);
            }
            Some(&"endloop") => {
                let [a, b, c] = corners[..] else {
                    return Err(line_err(name, line, "a facet needs exactly 3 vertices"));
                };
                mesh.triangles.push([a, b, c]);
                corners.clear();
                if mesh.triangles.len() > MAX_TRIANGLES {
                    return Err(line_err(name, line, "more than 10 million triangles"));
                }
            }
            _ => {}
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_quads_become_fans_and_negative_indices_count_back() {
        let text = "# cube side\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1/1 2//2 3 -1\n";
        let mesh = read_obj("a.obj", text).unwrap();
        assert_eq!(mesh.vertices.len(), 4);
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let err = read_obj("a.obj", "v 0 0 0\nf 1 2 3\n").unwrap_err();
        assert_eq!(
            err.to_string(),
            "a.obj:2: f: index '2' out of range (1 vertices so far)"
        );
    }

    #[test]
    fn ascii_stl_reads_facets() {
        let text = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
                    vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        let mesh = read_stl("t.stl", text.as_bytes()).unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
        assert_eq!(mesh.vertices[1], Vec3::X);
        let err = read_stl("t.stl", b"solid t\nvertex 0 0 nan\n").unwrap_err();
        assert_eq!(err.to_string(), "t.stl:2: 'nan' is not a finite number");
    }
}
