//! `<compiler>` settings and MJCF frames: `pos` with one of `quat` (w x y z), `axisangle`,
//! `euler` (in `eulerseq`), `xyaxes`, `zaxis`; angles in the compiler's unit.

use tumble::{Mat3, Quat, Real, Vec3};

use super::parse::View;
use crate::error::{printable, Result};

/// Where inertias come from (`<compiler inertiafromgeom>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FromGeom {
    /// From the geoms only when a body has no `<inertial>` (MuJoCo's default).
    Auto,
    /// Always from the geoms.
    Always,
    /// Never: bodies without `<inertial>` are massless.
    Never,
}

/// The `<compiler>` attributes the import reads.
#[derive(Debug, Clone)]
pub(crate) struct Compiler {
    /// Angles in degrees (MuJoCo's default) rather than radians.
    pub degrees: bool,
    /// Axis letters of `euler`: lower case turns about the moving axes, upper case about
    /// the fixed ones.
    pub eulerseq: [u8; 3],
    pub from_geom: FromGeom,
    /// A joint `range` limits it unless `limited="false"` (MuJoCo's default, `true`).
    pub autolimits: bool,
    /// `settotalmass`: every moving body's mass and inertia scaled to this total (kg).
    pub total_mass: Option<Real>,
    /// `meshdir` and `assetdir`: where mesh files are, against the model file's folder.
    pub meshdir: Option<String>,
    pub assetdir: Option<String>,
    /// `strippath`: mesh file names lose their folders.
    pub strip_path: bool,
}

impl Default for Compiler {
    fn default() -> Self {
        Compiler {
            degrees: true,
            eulerseq: *b"xyz",
            from_geom: FromGeom::Auto,
            autolimits: true,
            total_mass: None,
            meshdir: None,
            assetdir: None,
            strip_path: false,
        }
    }
}

impl Compiler {
    /// Reads one `<compiler>` over the settings so far (a model may have several).
    pub fn read(&mut self, v: &View<'_>) -> Result<()> {
        match v.get("angle") {
            None => {}
            Some("degree") => self.degrees = true,
            Some("radian") => self.degrees = false,
            Some(u) => {
                return Err(v.err(
                    "angle",
                    format!(
                        "unknown unit '{}' (expected degree or radian)",
                        printable(u)
                    ),
                ))
            }
        }
        if let Some(seq) = v.get("eulerseq") {
            let b = seq.as_bytes();
            let ok = b.len() == 3 && b.iter().all(|c| b"xyzXYZ".contains(c));
            if !ok {
                return Err(v.err(
                    "eulerseq",
                    format!("'{}' is not three of x, y, z, X, Y, Z", printable(seq)),
                ));
            }
            self.eulerseq = [b[0], b[1], b[2]];
        }
        self.from_geom = match v.get("inertiafromgeom") {
            None => self.from_geom,
            Some("auto") => FromGeom::Auto,
            Some("true") => FromGeom::Always,
            Some("false") => FromGeom::Never,
            Some(t) => {
                return Err(v.err(
                    "inertiafromgeom",
                    format!("'{}' is not one of true, false, auto", printable(t)),
                ))
            }
        };
        if let Some(a) = v.flag("autolimits")? {
            self.autolimits = a;
        }
        if let Some(m) = v.real("settotalmass")? {
            // MuJoCo: a value <= 0 (its default, -1) leaves the masses as they are.
            self.total_mass = (m > 0.0).then_some(m);
        }
        if let Some(d) = v.get("meshdir") {
            self.meshdir = Some(d.to_string());
        }
        if let Some(d) = v.get("assetdir") {
            self.assetdir = Some(d.to_string());
        }
        if let Some(s) = v.flag("strippath")? {
            self.strip_path = s;
        }
        if v.get("coordinate") == Some("global") {
            return Err(v.err("coordinate", "global coordinates are not supported"));
        }
        Ok(())
    }

    /// An angle in the file's unit, in radians.
    pub fn angle(&self, a: Real) -> Real {
        if self.degrees {
            a.to_radians()
        } else {
            a
        }
    }
}

/// The element's `pos` (m), zero when absent.
pub(crate) fn position(v: &View<'_>) -> Result<Vec3> {
    Ok(v.reals("pos", &[3])?.map_or(Vec3::ZERO, |p| vec3(&p)))
}

pub(crate) fn vec3(p: &[Real]) -> Vec3 {
    Vec3::new(p[0], p[1], p[2])
}

const ORIENTATIONS: [&str; 5] = ["quat", "axisangle", "euler", "xyaxes", "zaxis"];

/// The element's orientation from whichever of the five forms it uses; identity if none.
pub(crate) fn orientation(v: &View<'_>, c: &Compiler) -> Result<Quat> {
    // Only the element's own attributes choose the form: a default's quat does not
    // override an element's euler.
    let own: Vec<&str> = ORIENTATIONS
        .into_iter()
        .filter(|k| v.elem.own(k).is_some())
        .collect();
    if own.len() > 1 {
        return Err(v.err(own[1], format!("orientation already given by {}", own[0])));
    }
    let key = own
        .first()
        .copied()
        .or_else(|| ORIENTATIONS.into_iter().find(|k| v.get(k).is_some()));
    match key {
        None => Ok(Quat::IDENTITY),
        Some("quat") => quat(v),
        Some("axisangle") => axis_angle(v, c),
        Some("euler") => euler(v, c),
        Some("xyaxes") => xy_axes(v),
        _ => z_axis(v),
    }
}

fn quat(v: &View<'_>) -> Result<Quat> {
    let q = v.reals("quat", &[4])?.unwrap_or_default();
    let q = Quat::from_xyzw(q[1], q[2], q[3], q[0]);
    if q.length() < 1e-12 {
        return Err(v.err("quat", "must not be zero"));
    }
    Ok(q.normalize())
}

fn axis_angle(v: &View<'_>, c: &Compiler) -> Result<Quat> {
    let a = v.reals("axisangle", &[4])?.unwrap_or_default();
    let axis = vec3(&a)
        .try_normalize()
        .ok_or_else(|| v.err("axisangle", "the axis must not be zero"))?;
    Ok(Quat::from_axis_angle(axis, c.angle(a[3])))
}

fn euler(v: &View<'_>, c: &Compiler) -> Result<Quat> {
    let a = v.reals("euler", &[3])?.unwrap_or_default();
    let mut q = Quat::IDENTITY;
    for (letter, angle) in c.eulerseq.iter().zip(a) {
        let axis = match letter.to_ascii_lowercase() {
            b'x' => Vec3::X,
            b'y' => Vec3::Y,
            _ => Vec3::Z,
        };
        let turn = Quat::from_axis_angle(axis, c.angle(angle));
        // MuJoCo: lower case composes on the right (moving axes), upper on the left.
        q = if letter.is_ascii_lowercase() {
            q * turn
        } else {
            turn * q
        };
    }
    Ok(q.normalize())
}

fn xy_axes(v: &View<'_>) -> Result<Quat> {
    let a = v.reals("xyaxes", &[6])?.unwrap_or_default();
    let bad = || v.err("xyaxes", "the axes must be non-zero and not parallel");
    let x = vec3(&a[..3]).try_normalize().ok_or_else(bad)?;
    let y = vec3(&a[3..]);
    let y = (y - x * x.dot(y)).try_normalize().ok_or_else(bad)?;
    let z = x.cross(y);
    Ok(Quat::from_mat3(&Mat3::from_cols(x, y, z)).normalize())
}

fn z_axis(v: &View<'_>) -> Result<Quat> {
    let a = v.reals("zaxis", &[3])?.unwrap_or_default();
    let z = vec3(&a)
        .try_normalize()
        .ok_or_else(|| v.err("zaxis", "must not be zero"))?;
    Ok(Quat::from_rotation_arc(Vec3::Z, z))
}

/// `(pos, orientation)` of an element's frame in its parent's.
pub(crate) fn frame(v: &View<'_>, c: &Compiler) -> Result<(Vec3, Quat)> {
    Ok((position(v)?, orientation(v, c)?))
}
