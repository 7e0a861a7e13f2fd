//! URDF text -> [`Model`]: links (inertial, collision geometry) and joints, every number
//! checked for form, every element remembered by where it is (`file:line: <link
//! name="upper">`) so that later errors can name it. Visual elements, materials,
//! transmissions and `<gazebo>` blocks are skipped without a word: they do not move
//! anything.

use std::path::{Path, PathBuf};

use roxmltree::{Document, Node};
use tumble::limits::short;
use tumble::math::symmetric_eigen;
use tumble::{Mat3, Quat, Real, Vec3};

use crate::error::{printable, Result, SceneError};

/// A rigid transform: where a child frame sits in its parent's, and how it is turned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Pose {
    pub position: Vec3,
    pub rotation: Quat,
}

impl Pose {
    pub const IDENTITY: Pose = Pose {
        position: Vec3::ZERO,
        rotation: Quat::IDENTITY,
    };
    /// `self` then `inner`: the frame `inner` places, seen from `self`'s parent.
    pub fn then(&self, inner: &Pose) -> Pose {
        Pose {
            position: self.position + self.rotation * inner.position,
            rotation: (self.rotation * inner.rotation).normalize(),
        }
    }
}

/// One `<link>`.
#[derive(Debug, Clone)]
pub(crate) struct Link {
    pub name: String,
    /// `file:line: <link name="...">`, the prefix of this link's errors.
    pub at: String,
    pub inertial: Option<Inertial>,
    pub collisions: Vec<Collision>,
    /// The colour of its first visual's material (pictures only).
    pub color: Option<[u8; 3]>,
}

/// A link's `<inertial>`: mass (kg) and the tensor about the centre of mass, both in the
/// link frame (the `<origin>`'s rotation already applied: R I Rᵀ). `inertia` is `None`
/// when the file gives a mass but an all-zero tensor (common in exported files, and
/// ignored by PyBullet, which by default takes the tensor from the collision shapes):
/// the builder then does the same and says so. `problem` says why a tensor given with a
/// mass > 0 is not a possible one (not positive definite, or a principal moment above
/// the sum of the other two): the builder ignores it for a link that does not move, and
/// takes a moving link's from its collision geometry, as PyBullet does, with a warning.
#[derive(Debug, Clone)]
pub(crate) struct Inertial {
    pub center: Vec3,
    pub mass: Real,
    pub inertia: Option<Mat3>,
    pub problem: Option<String>,
}

/// One `<collision>`: its geometry placed in the link frame.
#[derive(Debug, Clone)]
pub(crate) struct Collision {
    pub at: String,
    pub origin: Pose,
    pub geometry: Geometry,
}

/// URDF's four geometries. Cylinders lie along their own z axis.
#[derive(Debug, Clone)]
pub(crate) enum Geometry {
    Box {
        half_extents: Vec3,
    },
    Sphere {
        radius: Real,
    },
    Cylinder {
        radius: Real,
        length: Real,
    },
    /// PyBullet's extension: a capsule whose `length` is the shaft's, caps excluded.
    Capsule {
        radius: Real,
        length: Real,
    },
    /// PyBullet's extension: the plane through the origin with this unit normal, for a
    /// static link whose only geometry it is.
    Plane {
        normal: Vec3,
    },
    Mesh {
        file: PathBuf,
        scale: Vec3,
    },
}

/// The joint types of URDF.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum JointType {
    Revolute,
    Continuous,
    Prismatic,
    Fixed,
    Floating,
    Planar,
    /// PyBullet's extension: a ball joint, three turning coordinates about one point.
    Spherical,
}

/// One `<joint>`: the child's frame is `origin` in the parent's frame at zero.
#[derive(Debug, Clone)]
pub(crate) struct Joint {
    pub name: String,
    pub at: String,
    pub kind: JointType,
    pub parent: String,
    pub child: String,
    pub origin: Pose,
    /// Unit axis in the joint (child) frame.
    pub axis: Vec3,
    pub limits: Option<[Real; 2]>,
    pub damping: Real,
    pub friction: Real,
}

/// A whole `<robot>`.
#[derive(Debug, Clone)]
pub(crate) struct Model {
    pub name: String,
    pub links: Vec<Link>,
    pub joints: Vec<Joint>,
    /// What was read but will not be built as written, one line each.
    pub warnings: Vec<String>,
}

/// Where the text came from: the name errors use and the folder meshes resolve against.
pub(crate) struct Source<'a> {
    pub label: String,
    pub dir: &'a Path,
}

/// Parses URDF text.
pub(crate) fn parse(text: &str, src: &Source<'_>) -> Result<Model> {
    // NUL bytes after the last element (written by some exporters, e.g. PyBullet's
    // humanoid.urdf) are not XML, and say nothing: dropped, as TinyXML (PyBullet) does.
    let text = text.trim_end_matches(|c: char| c == '\0' || c.is_whitespace());
    let text = blank_declaration(text);
    let doc = Document::parse(&text).map_err(|e| {
        let pos = e.pos();
        SceneError::new(
            format!("{}:{}", src.label, pos.row),
            format!("malformed XML: {e}"),
        )
    })?;
    let cx = Cx {
        doc: &doc,
        src,
        warnings: Default::default(),
    };
    let robot = doc.root_element();
    if robot.tag_name().name() != "robot" {
        return Err(cx.err(robot, "", "the root element must be <robot>"));
    }
    let mut model = Model {
        name: robot.attribute("name").unwrap_or("robot").to_string(),
        links: Vec::new(),
        joints: Vec::new(),
        warnings: Vec::new(),
    };
    let materials = materials(robot);
    for node in robot.children().filter(Node::is_element) {
        match node.tag_name().name() {
            "link" => {
                let mut link = cx.link(node)?;
                link.color = color(node, &materials);
                model.links.push(link);
            }
            "joint" => model.joints.push(cx.joint(node)?),
            _ => {}
        }
    }
    if model.links.is_empty() {
        return Err(cx.err(robot, "", "has no <link>"));
    }
    model.warnings = cx.warnings.take();
    Ok(model)
}

struct Cx<'a, 'input> {
    doc: &'a Document<'input>,
    src: &'a Source<'a>,
    warnings: std::cell::RefCell<Vec<String>>,
}

impl Cx<'_, '_> {
    /// `file:line: <tag name="...">`.
    fn at(&self, node: Node<'_, '_>) -> String {
        let line = self.doc.text_pos_at(node.range().start).row;
        let tag = node.tag_name().name();
        match node.attribute("name") {
            Some(n) => format!(
                "{}:{line}: <{tag} name=\"{}\">",
                self.src.label,
                printable(n)
            ),
            None => format!("{}:{line}: <{tag}>", self.src.label),
        }
    }

    /// An error at `node`; `field` (may be empty) is the attribute path within it.
    fn err(&self, node: Node<'_, '_>, field: &str, reason: impl Into<String>) -> SceneError {
        let at = self.at(node);
        match field {
            "" => SceneError::new(at, reason),
            f => SceneError::new(format!("{at}: {f}"), reason),
        }
    }

    /// `N` finite numbers from a space-separated attribute, if present.
    fn reals<const N: usize>(
        &self,
        node: Node<'_, '_>,
        field: &str,
        attr: &str,
    ) -> Result<Option<[Real; N]>> {
        let Some(text) = node.attribute(attr) else {
            return Ok(None);
        };
        let (read, why) = numbers_as_pybullet_reads(text);
        if let Some(why) = why {
            self.warnings.borrow_mut().push(format!(
                "{}: {field}: '{}' {why}",
                self.at(node),
                printable(text)
            ));
        }
        let words: Vec<&str> = read.split(is_separator).filter(|w| !w.is_empty()).collect();
        let nums: Vec<Real> = words
            .iter()
            .filter_map(|w| w.parse::<Real>().ok().filter(|x| x.is_finite()))
            .collect();
        if nums.len() == words.len() && nums.len() > N {
            // PyBullet reads the first N and ignores the rest (`scale="1 1 1 1"`).
            self.warnings.borrow_mut().push(format!(
                "{}: {field}: expected {N} numbers, got {} ('{}'); the first {N} used, as PyBullet does",
                self.at(node),
                nums.len(),
                printable(text)
            ));
            let mut first = [0.0; N];
            first.copy_from_slice(&nums[..N]);
            return Ok(Some(first));
        }
        match <[Real; N]>::try_from(nums) {
            Ok(a) if words.len() == N => Ok(Some(a)),
            _ => Err(self.err(
                node,
                field,
                format!("expected {N} finite numbers, got '{}'", printable(text)),
            )),
        }
    }

    fn real(&self, node: Node<'_, '_>, field: &str, attr: &str) -> Result<Option<Real>> {
        Ok(self.reals::<1>(node, field, attr)?.map(|[x]| x))
    }

    fn required_real(&self, node: Node<'_, '_>, field: &str, attr: &str) -> Result<Real> {
        self.real(node, field, attr)?
            .ok_or_else(|| self.err(node, field, "is required"))
    }

    fn name(&self, node: Node<'_, '_>) -> Result<String> {
        let name = node
            .attribute("name")
            .ok_or_else(|| self.err(node, "name", "is required"))?;
        // Plain numbers are names in published files (spirit40.urdf numbers its joints);
        // the scene checks that none reads as an unnamed body's or joint's index label.
        if !crate::body::is_plain_number(name) {
            crate::body::check_name(name, "links and joints")
                .map_err(|reason| self.err(node, "name", reason))?;
        }
        Ok(name.to_string())
    }

    /// The `<origin>` child of `node` (identity when absent). URDF's `rpy` is roll about
    /// x, then pitch about y, then yaw about z, all about the fixed parent axes:
    /// R = Rz(yaw) Ry(pitch) Rx(roll).
    fn origin(&self, node: Node<'_, '_>, field: &str) -> Result<Pose> {
        let Some(o) = child(node, "origin") else {
            return Ok(Pose::IDENTITY);
        };
        let xyz = self.reals::<3>(o, &format!("{field}origin.xyz"), "xyz")?;
        let rpy = self.reals::<3>(o, &format!("{field}origin.rpy"), "rpy")?;
        let [r, p, y] = rpy.unwrap_or([0.0; 3]);
        Ok(Pose {
            position: Vec3::from_array(xyz.unwrap_or([0.0; 3])),
            rotation: Quat::from_rotation_z(y)
                * Quat::from_rotation_y(p)
                * Quat::from_rotation_x(r),
        })
    }

    fn link(&self, node: Node<'_, '_>) -> Result<Link> {
        let name = self.name(node)?;
        let inertial = child(node, "inertial")
            .map(|i| self.inertial(node, i))
            .transpose()?;
        let mut collisions = Vec::new();
        for c in node.children().filter(|c| c.has_tag_name("collision")) {
            collisions.push(self.collision(c)?);
        }
        Ok(Link {
            name,
            at: self.at(node),
            inertial,
            collisions,
            color: None,
        })
    }

    /// The `<inertial>` of `link`; a mass of 0 (allowed: URDF's static bases have it)
    /// leaves the tensor unchecked, any other must be a possible one.
    fn inertial(&self, link: Node<'_, '_>, node: Node<'_, '_>) -> Result<Inertial> {
        let origin = self.origin(node, "inertial.")?;
        let mass_node =
            child(node, "mass").ok_or_else(|| self.err(link, "inertial.mass", "is required"))?;
        let mass = self.required_real(mass_node, "inertial.mass.value", "value")?;
        if mass < 0.0 {
            return Err(self.err(link, "inertial.mass", format!("must be >= 0, got {mass}")));
        }
        let i = match child(node, "inertia") {
            Some(i) => i,
            None if mass == 0.0 => return Ok(zero_mass(origin)),
            None => return Err(self.err(link, "inertial.inertia", "is required")),
        };
        let mut v = [0.0; 6];
        for (slot, key) in v.iter_mut().zip(["ixx", "ixy", "ixz", "iyy", "iyz", "izz"]) {
            *slot = self
                .real(i, &format!("inertial.inertia.{key}"), key)?
                .unwrap_or(0.0);
        }
        let [xx, xy, xz, yy, yz, zz] = v;
        // A negative moment about an axis is impossible outright, and no file written by
        // a tool has one (pybullet_data's 1,095 files have none), so it is an error; the
        // subtler impossibilities below are warned about and mended as PyBullet does.
        for (key, x) in [("ixx", xx), ("iyy", yy), ("izz", zz)] {
            if x < 0.0 {
                let field = format!("inertial.inertia.{key}");
                return Err(self.err(link, &field, format!("must be >= 0, got {x}")));
            }
        }
        let local = Mat3::from_cols_array(&[xx, xy, xz, xy, yy, yz, xz, yz, zz]);
        if v.iter().all(|&x| x == 0.0) {
            return Ok(Inertial {
                inertia: None,
                ..zero_mass(origin)
            }
            .with_mass(mass));
        }
        let problem = (mass > 0.0).then(|| tensor_problem(local)).flatten();
        let r = Mat3::from_quat(origin.rotation);
        Ok(Inertial {
            center: origin.position,
            mass,
            inertia: Some(r * local * r.transpose()),
            problem,
        })
    }

    fn collision(&self, node: Node<'_, '_>) -> Result<Collision> {
        let origin = self.origin(node, "")?;
        let geometry = child(node, "geometry")
            .and_then(|g| g.children().find(Node::is_element))
            .ok_or_else(|| {
                self.err(
                    node,
                    "geometry",
                    "is required (box, cylinder, sphere or mesh)",
                )
            })?;
        Ok(Collision {
            at: self.at(node),
            origin,
            geometry: self.geometry(geometry)?,
        })
    }

    fn geometry(&self, g: Node<'_, '_>) -> Result<Geometry> {
        let positive = |field: &str, attr: &str| -> Result<Real> {
            let x = self.required_real(g, field, attr)?;
            if x <= 0.0 {
                return Err(self.err(g, field, format!("must be > 0, got {x}")));
            }
            Ok(x)
        };
        match g.tag_name().name() {
            "box" => {
                let size = self.reals::<3>(g, "size", "size")?;
                let size = size.ok_or_else(|| self.err(g, "size", "is required"))?;
                if size.iter().any(|&s| s <= 0.0) {
                    return Err(self.err(g, "size", "each side must be > 0"));
                }
                Ok(Geometry::Box {
                    half_extents: Vec3::from_array(size) * 0.5,
                })
            }
            "sphere" => Ok(Geometry::Sphere {
                radius: positive("radius", "radius")?,
            }),
            "cylinder" => Ok(Geometry::Cylinder {
                radius: positive("radius", "radius")?,
                length: positive("length", "length")?,
            }),
            "capsule" => Ok(Geometry::Capsule {
                radius: positive("radius", "radius")?,
                length: positive("length", "length")?,
            }),
            "mesh" => self.mesh(g),
            "plane" => {
                let normal = self.reals::<3>(g, "normal", "normal")?;
                let normal = normal.map_or(Vec3::Z, Vec3::from_array);
                match normal.try_normalize() {
                    Some(normal) => Ok(Geometry::Plane { normal }),
                    None => Err(self.err(g, "normal", "must be a non-zero direction")),
                }
            }
            other => Err(self.err(
                g,
                "",
                format!(
                    "unknown geometry '{}' (expected box, cylinder, sphere, capsule, mesh or plane)",
                    printable(other)
                ),
            )),
        }
    }

    fn mesh(&self, g: Node<'_, '_>) -> Result<Geometry> {
        let name = g
            .attribute("filename")
            .ok_or_else(|| self.err(g, "filename", "is required"))?;
        let scale = match self.reals::<3>(g, "scale", "scale")? {
            Some(s) if s.contains(&0.0) => return Err(self.err(g, "scale", "must not be 0")),
            Some(s) => Vec3::from_array(s),
            None => Vec3::ONE,
        };
        let file = resolve(name, self.src.dir).ok_or_else(|| {
            self.err(
                g,
                "filename",
                format!("mesh file '{}' not found", printable(name)),
            )
        })?;
        Ok(Geometry::Mesh { file, scale })
    }

    fn joint(&self, node: Node<'_, '_>) -> Result<Joint> {
        let name = self.name(node)?;
        let type_name = node.attribute("type").unwrap_or("");
        let kind = match type_name {
            "revolute" => JointType::Revolute,
            "continuous" => JointType::Continuous,
            "prismatic" => JointType::Prismatic,
            "fixed" => JointType::Fixed,
            "floating" => JointType::Floating,
            "planar" => JointType::Planar,
            "spherical" => JointType::Spherical,
            other => {
                return Err(self.err(
                    node,
                    "type",
                    format!(
                        "unknown joint type '{}' (expected revolute, continuous, prismatic, fixed, floating, planar or spherical)",
                        printable(other)
                    ),
                ))
            }
        };
        let link_of = |tag: &str| -> Result<String> {
            child(node, tag)
                .and_then(|n| n.attribute("link"))
                .map(str::to_string)
                .ok_or_else(|| self.err(node, &format!("{tag}.link"), "is required"))
        };
        let (parent, child_link) = (link_of("parent")?, link_of("child")?);
        let axis = match child(node, "axis") {
            Some(a) => self.reals::<3>(a, "axis.xyz", "xyz")?.map(Vec3::from_array),
            None => None,
        }
        .unwrap_or(Vec3::X);
        let has_axis = !matches!(
            kind,
            JointType::Fixed | JointType::Floating | JointType::Spherical
        );
        if has_axis && axis.length() < 1e-9 {
            return Err(self.err(node, "axis.xyz", "must be a non-zero direction"));
        }
        let (damping, friction) = self.dynamics(node)?;
        if kind == JointType::Spherical {
            self.spherical_unread(node, damping, friction);
        }
        Ok(Joint {
            at: self.at(node),
            limits: self.limits(node, kind)?,
            origin: self.origin(node, "")?,
            axis: axis.try_normalize().unwrap_or(Vec3::X),
            name,
            kind,
            parent,
            child: child_link,
            damping,
            friction,
        })
    }

    /// `<limit lower upper>` of revolute and prismatic joints (other types ignore it).
    fn limits(&self, node: Node<'_, '_>, kind: JointType) -> Result<Option<[Real; 2]>> {
        if !matches!(kind, JointType::Revolute | JointType::Prismatic) {
            return Ok(None);
        }
        let Some(l) = child(node, "limit") else {
            return Ok(None);
        };
        let lower = self.real(l, "limit.lower", "lower")?.unwrap_or(0.0);
        let upper = self.real(l, "limit.upper", "upper")?.unwrap_or(0.0);
        if lower > upper {
            // PyBullet's convention (Bullet's): lower above upper means no limits.
            self.warnings.borrow_mut().push(format!(
                "{}: limit: lower ({lower}) > upper ({upper}), read as no limits (PyBullet's convention)",
                self.at(node)
            ));
            return Ok(None);
        }
        Ok(Some([lower, upper]))
    }

    /// What of a `spherical` joint is read but not built: its `<limit>` (PyBullet's swing
    /// and twist bounds, whose convention differs from the ball joint's cone) and its
    /// `<dynamics>`, each with a warning.
    fn spherical_unread(&self, node: Node<'_, '_>, damping: Real, friction: Real) {
        let mut unread = Vec::new();
        if child(node, "limit").is_some_and(|l| {
            ["lower", "upper", "twist"]
                .iter()
                .any(|k| l.attribute(*k).is_some())
        }) {
            unread.push("limit: its bounds");
        }
        if damping > 0.0 || friction > 0.0 {
            unread.push("dynamics: its damping and friction");
        }
        for what in unread {
            self.warnings.borrow_mut().push(format!(
                "{}: {what} are not applied to a spherical joint (a ball joint, free to turn)",
                self.at(node)
            ));
        }
    }

    /// `<dynamics damping friction>`, both >= 0 (default 0).
    fn dynamics(&self, node: Node<'_, '_>) -> Result<(Real, Real)> {
        let Some(d) = child(node, "dynamics") else {
            return Ok((0.0, 0.0));
        };
        let mut out = [0.0; 2];
        for (slot, key) in out.iter_mut().zip(["damping", "friction"]) {
            let field = format!("dynamics.{key}");
            let x = self.real(d, &field, key)?.unwrap_or(0.0);
            if x < 0.0 {
                return Err(self.err(node, &field, format!("must be >= 0, got {x}")));
            }
            *slot = x;
        }
        Ok((out[0], out[1]))
    }
}

fn zero_mass(origin: Pose) -> Inertial {
    Inertial {
        center: origin.position,
        mass: 0.0,
        inertia: Some(Mat3::ZERO),
        problem: None,
    }
}

/// Why `m` is not a possible inertia tensor, if it is not: it must be positive definite,
/// with no principal moment above the sum of the other two (with a relative slack of
/// 1e-6 for files that round their moments to a few digits). A moment at or under the
/// engine's [`tumble::limits::ZERO_MOMENT_SHARE`] of the largest counts as zero: biped2d_pybullet.urdf's sliders carry
/// a rod's tensor whose smallest moment comes out at 2e-18 of the others, and a body
/// that light about one axis made its joints let go (the slider fell through its axis).
fn tensor_problem(m: Mat3) -> Option<String> {
    let (moments, _) = symmetric_eigen(m);
    let mut sorted = moments.to_array();
    sorted.sort_by(Real::total_cmp);
    let [a, b, c] = sorted.map(short);
    let list = format!("principal moments [{a}, {b}, {c}]");
    if moments.min_element() <= tumble::limits::ZERO_MOMENT_SHARE * moments.max_element() {
        return Some(format!("is not positive definite: its {list}"));
    }
    let sum = moments.x + moments.y + moments.z;
    let largest = moments.max_element();
    if largest > (sum - largest) * (1.0 + 1e-6) {
        return Some(format!(
            "is impossible: of its {list} the largest exceeds the sum of the other two"
        ));
    }
    None
}

impl Inertial {
    fn with_mass(self, mass: Real) -> Inertial {
        Inertial { mass, ..self }
    }
}

/// The text with its `<?xml ...?>` declaration blanked out (newlines kept, so lines stay
/// where they were): it says nothing a URDF reader needs, and files that put comments or
/// blank lines before it (which XML forbids, and PyBullet reads) would otherwise fail.
fn blank_declaration(text: &str) -> std::borrow::Cow<'_, str> {
    let Some(start) = text.find("<?xml") else {
        return text.into();
    };
    let Some(len) = text[start..].find("?>") else {
        return text.into();
    };
    let end = start + len + 2;
    let blank: String = text[start..end]
        .chars()
        .map(|c| if c == '\n' { '\n' } else { ' ' })
        .collect();
    format!("{}{blank}{}", &text[..start], &text[end..]).into()
}

/// The robot's named materials' colours, `<material name><color rgba>`, in file order.
fn materials<'a>(robot: Node<'a, '_>) -> Vec<(&'a str, [u8; 3])> {
    robot
        .children()
        .filter(|m| m.has_tag_name("material"))
        .filter_map(|m| Some((m.attribute("name")?, rgba(m)?)))
        .collect()
}

/// A material's `<color rgba="r g b a">` (0 to 1 each) as bytes; badly formed colours are
/// ignored, as everything visual is.
fn rgba(material: Node<'_, '_>) -> Option<[u8; 3]> {
    let text = child(material, "color")?.attribute("rgba")?;
    let v: Vec<f64> = text
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect();
    let byte = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    match v[..] {
        [r, g, b, ..] if v.iter().all(|x| x.is_finite()) => Some([byte(r), byte(g), byte(b)]),
        _ => None,
    }
}

/// The colour of a link's first visual's material: its own `<color>`, or the named
/// material's.
fn color(link: Node<'_, '_>, materials: &[(&str, [u8; 3])]) -> Option<[u8; 3]> {
    let material = child(child(link, "visual")?, "material")?;
    rgba(material).or_else(|| {
        let name = material.attribute("name")?;
        materials.iter().find(|(n, _)| *n == name).map(|(_, c)| *c)
    })
}

/// The first element child of `node` called `tag`.
fn child<'a, 'input>(node: Node<'a, 'input>, tag: &str) -> Option<Node<'a, 'input>> {
    node.children().find(|c| c.has_tag_name(tag))
}

/// A mesh file name as URDF writes it, resolved to an existing file: `package://pkg/rest`
/// is looked for as `rest` in the folder named `pkg` among the URDF's folder and its
/// ancestors (or in a `pkg` folder beside one of them), then as `rest` and `pkg/rest`
/// next to the URDF, as ROS-less loaders (PyBullet) do; `file://` is a plain path;
/// anything else is relative to the URDF's folder.
pub(crate) fn resolve(name: &str, dir: &Path) -> Option<PathBuf> {
    if let Some(rest) = name.strip_prefix("package://") {
        let (pkg, tail) = rest.split_once('/').unwrap_or((rest, ""));
        let mut candidates = Vec::new();
        for a in dir.ancestors() {
            if a.file_name().is_some_and(|n| n == pkg) {
                candidates.push(a.join(tail));
            }
            candidates.push(a.join(pkg).join(tail));
        }
        candidates.push(dir.join(tail));
        return candidates.into_iter().find(|p| p.is_file());
    }
    let path = Path::new(name.strip_prefix("file://").unwrap_or(name));
    let path = if path.is_absolute() {
        path.to_path_buf()
    } else {
        dir.join(path)
    };
    path.is_file().then_some(path)
}

/// The numbers text of an attribute as PyBullet's reader takes it, and why it differs
/// from the text when it does. Two slips seen in published files are read as PyBullet
/// reads them: xacro's `$(optenv NAME default...)` left unexpanded (husky.urdf) gives its
/// default (PyBullet reads no environment, and neither do we: a file loads the same
/// everywhere), and a number with stray trailing dots (`-1.57.`, biped2d_pybullet.urdf)
/// is read up to them, as a C++ stream reads it. Anything else is left for the caller to
/// refuse.
fn numbers_as_pybullet_reads(text: &str) -> (std::borrow::Cow<'_, str>, Option<String>) {
    let trimmed = text.trim();
    if let Some(inner) = trimmed
        .strip_prefix("$(optenv")
        .and_then(|rest| rest.strip_suffix(')'))
    {
        let mut words = inner.split_whitespace();
        if words.next().is_some() {
            let default = words.collect::<Vec<_>>().join(" ");
            let why = format!(
                "is xacro's optenv left unexpanded; its default '{}' used",
                printable(&default)
            );
            return (default.into(), Some(why));
        }
    }
    let stray = |w: &str| w.len() > 1 && w.ends_with('.') && w.trim_end_matches('.').contains('.');
    if text.split(is_separator).any(stray) {
        let read: String = text
            .split_inclusive(is_separator)
            .map(|w| {
                let (word, sep) = w.split_at(w.trim_end_matches(is_separator).len());
                if stray(word) {
                    format!("{}{sep}", word.trim_end_matches('.'))
                } else {
                    w.to_string()
                }
            })
            .collect();
        let why = format!(
            "has stray dots; read as '{}', as PyBullet reads it",
            printable(&read)
        );
        return (read.into(), Some(why));
    }
    (text.into(), None)
}

/// What separates the numbers of an attribute: whitespace, as the format says; commas
/// too, as PyBullet allows.
fn is_separator(c: char) -> bool {
    c.is_whitespace() || c == ','
}
