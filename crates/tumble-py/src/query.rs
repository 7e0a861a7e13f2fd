//! World queries (ray casts, shape casts, point and box overlap) and contacts: what the
//! narrow phase found, with the solver's impulses, and begin/end events.

use numpy::PyArray1;
use pyo3::prelude::*;
use tumble::{Aabb, BodyId, ContactEventKind, Pose, QueryFilter, Ray, Real};

use crate::body::{handle, PyBody};
use crate::convert::{engine, invalid, layer_bits, quat_or, real, vec3, vec3_out, wide};
use crate::shapes::shape_of;
use crate::world::{body_arg, Inner, PyWorld};

/// A ray's hit: the `body`, the ray parameter `t` (hit point = origin + t·direction), the
/// `point` (m) and the unit surface `normal`, world frame, and the `subshape` index
/// (compound child or mesh triangle).
#[pyclass(module = "tumble", name = "RayHit", frozen, get_all)]
pub struct RayHit {
    /// The body hit.
    body: Py<PyBody>,
    /// Ray parameter: the hit is at origin + t·direction.
    t: f64,
    /// Where the ray hits (m, world), (3,).
    point: Py<PyArray1<f64>>,
    /// Unit surface normal there, (3,).
    normal: Py<PyArray1<f64>>,
    /// Index of the compound child or mesh triangle hit.
    subshape: u32,
}

#[pymethods]
impl RayHit {
    fn __repr__(&self) -> String {
        format!("<tumble.RayHit t={}>", self.t)
    }
}

/// A shape cast's hit: the `body`, the fraction `t` in [0, 1] of the translation travelled
/// before touching, the contact `point` (m) and the `normal` on the body hit, pointing
/// towards the cast shape.
#[pyclass(module = "tumble", name = "ShapeHit", frozen, get_all)]
pub struct ShapeHit {
    /// The body hit.
    body: Py<PyBody>,
    /// Fraction of the translation travelled before touching, in [0, 1].
    t: f64,
    /// Contact point (m, world), (3,).
    point: Py<PyArray1<f64>>,
    /// Unit normal on the body hit, towards the cast shape, (3,).
    normal: Py<PyArray1<f64>>,
}

#[pymethods]
impl ShapeHit {
    fn __repr__(&self) -> String {
        format!("<tumble.ShapeHit t={}>", self.t)
    }
}

/// One contact point: `position` midway between the two surfaces, `point_a` and `point_b`
/// on each surface (m); `separation` along the normal (m, negative when penetrating);
/// `normal_impulse` (N·s) and `tangent_impulse` (N·s, array (3,)) applied over the last
/// step: divide by dt for the mean force.
#[pyclass(module = "tumble", name = "ContactPoint", frozen, get_all)]
pub struct ContactPoint {
    /// The point midway between the two surfaces (m), (3,).
    position: Py<PyArray1<f64>>,
    /// The point on body_a's surface (m), (3,).
    point_a: Py<PyArray1<f64>>,
    /// The point on body_b's surface (m), (3,).
    point_b: Py<PyArray1<f64>>,
    /// Distance between the surfaces along the normal (m); negative when penetrating.
    separation: f64,
    /// Normal impulse applied over the last step (N·s).
    normal_impulse: f64,
    /// Friction impulse applied over the last step (N·s, world), (3,).
    tangent_impulse: Py<PyArray1<f64>>,
}

/// A contact manifold between `body_a` and `body_b`: the unit `normal` from a to b and up
/// to four `points`.
#[pyclass(module = "tumble", name = "Contact", frozen, get_all)]
pub struct Contact {
    /// The first body; the normal points away from it.
    body_a: Py<PyBody>,
    /// The second body.
    body_b: Py<PyBody>,
    /// Unit normal from body_a to body_b, (3,).
    normal: Py<PyArray1<f64>>,
    /// Up to four ContactPoints.
    points: Vec<Py<ContactPoint>>,
}

#[pymethods]
impl Contact {
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "<tumble.Contact {} - {}: {} points>",
            self.body_a
                .bind(py)
                .repr()
                .map_or_else(|_| "?".into(), |r| r.to_string()),
            self.body_b
                .bind(py)
                .repr()
                .map_or_else(|_| "?".into(), |r| r.to_string()),
            self.points.len()
        )
    }
}

/// Two bodies started (`kind` "begin") or stopped ("end") touching at the last step.
#[pyclass(module = "tumble", name = "ContactEvent", frozen, get_all)]
pub struct ContactEvent {
    /// "begin" or "end".
    kind: &'static str,
    /// The first body (lower creation order).
    body_a: Py<PyBody>,
    /// The second body.
    body_b: Py<PyBody>,
}

#[pymethods]
impl ContactEvent {
    fn __repr__(&self) -> String {
        format!("<tumble.ContactEvent {}>", self.kind)
    }
}

/// A body started or stopped overlapping a sensor: the `sensor` and the `body` (handles),
/// `began` (True when the overlap started, False when it ended) and the simulated `time`
/// (s) it was seen at (the end of the step that found it, or of the edit that ended it).
#[pyclass(module = "tumble", name = "SensorEvent", frozen, get_all)]
pub struct SensorEvent {
    /// The sensor.
    sensor: Py<PyBody>,
    /// The body that entered or left it.
    body: Py<PyBody>,
    /// True when the overlap began.
    began: bool,
    /// When (s).
    time: f64,
}

#[pymethods]
impl SensorEvent {
    fn __repr__(&self) -> String {
        let what = if self.began { "began" } else { "ended" };
        format!("<tumble.SensorEvent {what} t={}>", self.time)
    }
}

fn filter(
    slf: &Bound<'_, PyWorld>,
    g: &Inner,
    mask: i64,
    exclude: Option<&Bound<'_, PyAny>>,
) -> PyResult<QueryFilter> {
    Ok(QueryFilter {
        mask: layer_bits(mask, "mask")?,
        exclude: exclude
            .map(|e| body_arg(slf, g, e, "exclude"))
            .transpose()?,
    })
}

fn bodies<'py>(slf: &Bound<'py, PyWorld>, ids: Vec<BodyId>) -> PyResult<Vec<Bound<'py, PyBody>>> {
    ids.into_iter().map(|id| handle(slf, id)).collect()
}

fn max_t_of(max_t: f64) -> PyResult<Real> {
    if max_t.is_nan() || max_t < 0.0 {
        return Err(invalid("max_t", "must be >= 0"));
    }
    // The broad phase's tree walk clips the ray to max_t; an unbounded ray is clipped to
    // a length far beyond any scene instead of carrying infinities through it.
    Ok(real(max_t.min(1e12)))
}

fn ray_of(origin: &Bound<'_, PyAny>, direction: &Bound<'_, PyAny>) -> PyResult<Ray> {
    let o = vec3(origin, "origin")?;
    let d = vec3(direction, "direction")?;
    if !o.is_finite() {
        return Err(invalid("origin", "must be finite numbers"));
    }
    if !d.is_finite() || d.length_squared() == 0.0 {
        return Err(invalid("direction", "must be a non-zero finite vector"));
    }
    Ok(Ray::new(o, d))
}

fn ray_hit(slf: &Bound<'_, PyWorld>, ray: &Ray, h: tumble::WorldRayHit) -> PyResult<RayHit> {
    let py = slf.py();
    Ok(RayHit {
        body: handle(slf, h.body)?.unbind(),
        t: wide(h.hit.t),
        point: vec3_out(py, ray.at(h.hit.t)).unbind(),
        normal: vec3_out(py, h.hit.normal).unbind(),
        subshape: h.hit.subshape,
    })
}

fn contact_list<'py>(
    slf: &Bound<'py, PyWorld>,
    contacts: &[tumble::Contact],
) -> PyResult<Vec<Contact>> {
    let py = slf.py();
    contacts
        .iter()
        .map(|c| {
            let points = c
                .manifold
                .points()
                .iter()
                .map(|p| {
                    Py::new(
                        py,
                        ContactPoint {
                            position: vec3_out(py, (p.point_a + p.point_b) * 0.5).unbind(),
                            point_a: vec3_out(py, p.point_a).unbind(),
                            point_b: vec3_out(py, p.point_b).unbind(),
                            separation: wide(p.separation),
                            normal_impulse: wide(p.total_normal_impulse),
                            tangent_impulse: vec3_out(py, p.total_tangent_impulse).unbind(),
                        },
                    )
                })
                .collect::<PyResult<Vec<_>>>()?;
            Ok(Contact {
                body_a: handle(slf, c.body_a)?.unbind(),
                body_b: handle(slf, c.body_b)?.unbind(),
                normal: vec3_out(py, c.manifold.normal).unbind(),
                points,
            })
        })
        .collect()
}

#[pymethods]
impl PyWorld {
    /// The nearest body the ray origin + t·direction hits with t in [0, max_t] (t in
    /// units of the direction's length), or None. A ray starting inside a body hits it at
    /// t = 0. Only bodies whose collision group meets `mask` are seen; `exclude` (a body
    /// or name) is never.
    #[pyo3(signature = (origin, direction, max_t = f64::INFINITY, *, mask = 0xFFFF_FFFF, exclude = None))]
    fn cast_ray(
        slf: &Bound<'_, Self>,
        origin: &Bound<'_, PyAny>,
        direction: &Bound<'_, PyAny>,
        max_t: f64,
        mask: i64,
        exclude: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Option<RayHit>> {
        let ray = ray_of(origin, direction)?;
        let max_t = max_t_of(max_t)?;
        let hit = {
            let g = slf.get().lock()?;
            let f = filter(slf, &g, mask, exclude)?;
            g.world.cast_ray(&ray, max_t, &f)
        };
        hit.map(|h| ray_hit(slf, &ray, h)).transpose()
    }

    /// Every body the ray hits with t in [0, max_t], nearest first (one hit per body).
    #[pyo3(signature = (origin, direction, max_t = f64::INFINITY, *, mask = 0xFFFF_FFFF, exclude = None))]
    fn cast_ray_all(
        slf: &Bound<'_, Self>,
        origin: &Bound<'_, PyAny>,
        direction: &Bound<'_, PyAny>,
        max_t: f64,
        mask: i64,
        exclude: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Vec<RayHit>> {
        let ray = ray_of(origin, direction)?;
        let max_t = max_t_of(max_t)?;
        let hits = {
            let g = slf.get().lock()?;
            let f = filter(slf, &g, mask, exclude)?;
            g.world.cast_ray_all(&ray, max_t, &f)
        };
        hits.into_iter().map(|h| ray_hit(slf, &ray, h)).collect()
    }

    /// Sweeps a convex `shape` placed at `position` (m) and `orientation` [x, y, z, w]
    /// along `translation` (m, no rotation) and returns the first body it would touch, or
    /// None.
    #[pyo3(signature = (shape, position, translation, orientation = None, *, mask = 0xFFFF_FFFF, exclude = None))]
    #[allow(clippy::too_many_arguments)]
    fn cast_shape(
        slf: &Bound<'_, Self>,
        shape: &Bound<'_, PyAny>,
        position: &Bound<'_, PyAny>,
        translation: &Bound<'_, PyAny>,
        orientation: Option<&Bound<'_, PyAny>>,
        mask: i64,
        exclude: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Option<ShapeHit>> {
        let py = slf.py();
        let shape = shape_of(shape, "shape")?;
        let p = vec3(position, "position")?;
        let q = quat_or(orientation, "orientation")?;
        let d = vec3(translation, "translation")?;
        if !p.is_finite() {
            return Err(invalid("position", "must be finite numbers"));
        }
        if !d.is_finite() {
            return Err(invalid("translation", "must be finite numbers"));
        }
        let len = q.length();
        if !(len > 0.0 && len.is_finite()) {
            return Err(invalid(
                "orientation",
                "must be a non-zero quaternion [x, y, z, w]",
            ));
        }
        let hit = {
            let g = slf.get().lock()?;
            let f = filter(slf, &g, mask, exclude)?;
            g.world
                .cast_shape(&shape, &Pose::new(p, q / len), d, &f)
                .map_err(engine)?
        };
        hit.map(|h| {
            Ok(ShapeHit {
                body: handle(slf, h.body)?.unbind(),
                t: wide(h.hit.t),
                point: vec3_out(py, h.hit.point).unbind(),
                normal: vec3_out(py, h.hit.normal).unbind(),
            })
        })
        .transpose()
    }

    /// The bodies containing the world `point` (m), in creation order.
    #[pyo3(signature = (point, *, mask = 0xFFFF_FFFF, exclude = None))]
    fn query_point<'py>(
        slf: &Bound<'py, Self>,
        point: &Bound<'py, PyAny>,
        mask: i64,
        exclude: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Vec<Bound<'py, PyBody>>> {
        let p = vec3(point, "point")?;
        if !p.is_finite() {
            return Err(invalid("point", "must be finite numbers"));
        }
        let ids = {
            let g = slf.get().lock()?;
            let f = filter(slf, &g, mask, exclude)?;
            g.world.query_point(p, &f)
        };
        bodies(slf, ids)
    }

    /// The bodies whose bounding box overlaps the box from `lower` to `upper` (m, world
    /// axes), in creation order.
    #[pyo3(signature = (lower, upper, *, mask = 0xFFFF_FFFF, exclude = None))]
    fn query_aabb<'py>(
        slf: &Bound<'py, Self>,
        lower: &Bound<'py, PyAny>,
        upper: &Bound<'py, PyAny>,
        mask: i64,
        exclude: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Vec<Bound<'py, PyBody>>> {
        let lo = vec3(lower, "lower")?;
        let hi = vec3(upper, "upper")?;
        if !lo.is_finite() || !hi.is_finite() {
            return Err(invalid("lower", "the box's corners must be finite numbers"));
        }
        if lo.cmpgt(hi).any() {
            return Err(invalid("upper", "must be >= lower in every component"));
        }
        let ids = {
            let g = slf.get().lock()?;
            let f = filter(slf, &g, mask, exclude)?;
            g.world.query_aabb(&Aabb::new(lo, hi), &f)
        };
        bodies(slf, ids)
    }

    /// The contact manifolds of the last step, with the impulses the solver applied.
    fn contacts(slf: &Bound<'_, Self>) -> PyResult<Vec<Contact>> {
        let contacts = slf.get().lock()?.world.contacts().to_vec();
        contact_list(slf, &contacts)
    }

    /// Runs collision detection on the current state (no step) and returns its contacts.
    fn update_contacts(slf: &Bound<'_, Self>) -> PyResult<Vec<Contact>> {
        let contacts = slf.get().lock()?.world.update_contacts().to_vec();
        contact_list(slf, &contacts)
    }

    /// Pairs that started or stopped touching at the last step.
    fn contact_events(slf: &Bound<'_, Self>) -> PyResult<Vec<ContactEvent>> {
        let events = slf.get().lock()?.world.contact_events().to_vec();
        events
            .into_iter()
            .map(|e| {
                Ok(ContactEvent {
                    kind: match e.kind {
                        ContactEventKind::Begin => "begin",
                        ContactEventKind::End => "end",
                    },
                    body_a: handle(slf, e.body_a)?.unbind(),
                    body_b: handle(slf, e.body_b)?.unbind(),
                })
            })
            .collect()
    }

    /// Keeps bodies `a` and `b` (handles or names) from ever touching, as a joint between
    /// them does (MuJoCo's `<contact><exclude>`); kept by snapshots, copies, batches and
    /// saved scenes (the scene key `exclude`).
    fn exclude_contacts(
        slf: &Bound<'_, Self>,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let mut g = slf.get().lock()?;
        let (a, b) = (body_arg(slf, &g, a, "a")?, body_arg(slf, &g, b, "b")?);
        g.world.exclude_contacts(a, b).map_err(engine)
    }

    /// Lets an excluded pair touch again; returns whether it was excluded.
    fn allow_contacts(
        slf: &Bound<'_, Self>,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
    ) -> PyResult<bool> {
        let mut g = slf.get().lock()?;
        let (a, b) = (body_arg(slf, &g, a, "a")?, body_arg(slf, &g, b, "b")?);
        g.world.allow_contacts(a, b).map_err(engine)
    }

    /// The excluded pairs, each (older body, newer body).
    #[getter]
    fn excluded_contacts<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<Vec<(Bound<'py, PyBody>, Bound<'py, PyBody>)>> {
        let pairs = slf.get().lock()?.world.excluded_contacts().to_vec();
        pairs
            .into_iter()
            .map(|(a, b)| Ok((handle(slf, a)?, handle(slf, b)?)))
            .collect()
    }

    /// The sensor events of the last step, in (sensor, body) order: bodies that began or
    /// stopped overlapping a sensor. End events of edits made before the step (a body
    /// removed, a sensor flag changed) come first, with the time of the edit.
    fn sensor_events(slf: &Bound<'_, Self>) -> PyResult<Vec<SensorEvent>> {
        let events = slf.get().lock()?.world.sensor_events().to_vec();
        events
            .into_iter()
            .map(|e| {
                Ok(SensorEvent {
                    sensor: handle(slf, e.sensor)?.unbind(),
                    body: handle(slf, e.body)?.unbind(),
                    began: e.began,
                    time: wide(e.time),
                })
            })
            .collect()
    }

    /// The bodies overlapping `sensor` (a handle or a name) as of the last step; empty for
    /// a body that is not a sensor.
    fn sensor_overlaps<'py>(
        slf: &Bound<'py, Self>,
        sensor: &Bound<'py, PyAny>,
    ) -> PyResult<Vec<Bound<'py, PyBody>>> {
        let ids = {
            let g = slf.get().lock()?;
            let id = body_arg(slf, &g, sensor, "sensor")?;
            g.world.sensor_overlaps(id).map_err(engine)?
        };
        bodies(slf, ids)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<RayHit>()?;
    m.add_class::<ShapeHit>()?;
    m.add_class::<Contact>()?;
    m.add_class::<ContactPoint>()?;
    m.add_class::<ContactEvent>()?;
    m.add_class::<SensorEvent>()?;
    Ok(())
}
