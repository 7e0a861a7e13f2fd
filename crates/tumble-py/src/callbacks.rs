//! Python force callbacks: `World.add_force_callback(fn)`, `fn(ctx)` called at every
//! force evaluation with a `tumble.ForceContext`.
//!
//! A call: the engine calls the Rust closure of `python_force` on the thread the step
//! runs on (the caller's, or one of the world's threads when a large world steps on
//! several). The closure takes the interpreter's lock (`Python::attach`), copies every
//! body's state of the evaluation into the world's one ForceContext object (about 100
//! bytes a body), opens it, calls fn(ctx), closes it, and adds the forces fn gave to the
//! engine's. The step loops (`steps.rs`) release the interpreter's lock whenever the world
//! has a Python callback, so that a callback on another thread can take it: holding it
//! while a world's thread waits for it would deadlock.
//!
//! An exception in fn stops the step: the closure keeps it in the context and tells the
//! engine (`ForceContext::fail`), which calls no callback again, undoes the step and
//! returns `CallbackFailed`; the loop then raises the kept exception, with its type,
//! message and traceback, in place of the engine's error. The world is as it was before
//! the step, bit for bit.
//!
//! The world is locked while it steps, so fn reads state through ctx, not through the
//! world or its bodies (those raise RuntimeError, "the world is busy", which stops the
//! step like any exception).
//!
//! A callback usually holds a body of its world: function -> Body -> World -> engine
//! closure -> context -> function is a cycle. The functions are kept in the context, not
//! the closures, and the handles, the world and the context tell the garbage collector
//! their references (`__traverse__`), so that it can free such a world.

use numpy::PyArray1;
use pyo3::exceptions::PyRuntimeError;
use pyo3::gc::PyVisit;
use pyo3::prelude::*;
use pyo3::PyTraverseError;
use tumble::Vec3;
use tumble::{AppliedForce, BodyId, EvaluatedState, Force, ForceCallback, ForceContext, Real};

use crate::body::PyBody;
use crate::convert::{engine, invalid, quat_out, vec3, vec3_out, wide, wrong_type};
use crate::world::{Inner, PyWorld};

/// A world's Python force callbacks: their context, and how many of the engine's closures
/// hold a reference to it (one per callback).
pub struct Callbacks {
    pub ctx: Py<PyForceContext>,
    closures: usize,
}

impl Callbacks {
    /// The references the world holds to Python objects, for the garbage collector: the
    /// context, once from here and once from each closure.
    pub fn traverse(&self, visit: &PyVisit<'_>) -> Result<(), PyTraverseError> {
        for _ in 0..=self.closures {
            visit.call(&self.ctx)?;
        }
        Ok(())
    }
}

/// What a force callback sees: the state of every body at the force evaluation being
/// made (`time`, and per body `position`, `center_of_mass`, `orientation`, `velocity`,
/// `angular_velocity`, `mass`), and where it puts forces (`add_force`, `add_torque`).
/// Bodies are given as `tumble.Body` handles (fastest) or names. Valid only inside the
/// call it was passed to.
#[pyclass(module = "tumble", name = "ForceContext")]
pub struct PyForceContext {
    /// The Python world's address, to refuse another world's bodies; an address, not a
    /// reference, because the world owns this object.
    world: usize,
    /// The bodies (creation order) the tables below were made for.
    ids: Vec<BodyId>,
    /// Per slot index of a handle: its generation and dense index, for live bodies.
    slots: Vec<Option<(u32, usize)>>,
    names: Vec<Option<String>>,
    /// Whether a call is under way; the fields below are that call's.
    open: bool,
    time: Real,
    states: Vec<EvaluatedState>,
    /// Forces given: dense index, force (N), where it acts (body frame, m; `None`: the
    /// centre of mass) and torque (N·m).
    pushes: Vec<(usize, Vec3, Option<Vec3>, Vec3)>,
    /// The exception that stopped the step, until the step loop raises it.
    error: Option<PyErr>,
    /// The world's Python callbacks, in the order added; the engine's closure of the
    /// k-th calls `functions[k]`. Here rather than in the closures so that the garbage
    /// collector sees them (see `__traverse__`).
    functions: Vec<Py<PyAny>>,
}

impl PyForceContext {
    fn new(world: &Bound<'_, PyWorld>) -> Self {
        PyForceContext {
            world: world.as_ptr() as usize,
            ids: Vec::new(),
            slots: Vec::new(),
            names: Vec::new(),
            open: false,
            time: 0.0,
            states: Vec::new(),
            pushes: Vec::new(),
            error: None,
            functions: Vec::new(),
        }
    }

    /// Opens the context for a call on the engine's evaluation `rust`.
    fn begin(&mut self, rust: &ForceContext<'_>) {
        if self.ids != rust.body_ids() {
            self.index(rust);
        }
        self.time = rust.time();
        self.states.clear();
        let n = rust.body_count();
        self.states.extend((0..n).filter_map(|i| rust.state_at(i)));
        self.pushes.clear();
        self.open = true;
    }

    /// The handle and name tables, remade when the bodies changed since the last call.
    fn index(&mut self, rust: &ForceContext<'_>) {
        self.ids.clear();
        self.ids.extend_from_slice(rust.body_ids());
        self.slots.clear();
        for (i, id) in self.ids.iter().enumerate() {
            let slot = id.index as usize;
            if self.slots.len() <= slot {
                self.slots.resize(slot + 1, None);
            }
            self.slots[slot] = Some((id.generation, i));
        }
        self.names.clear();
        let names = (0..self.ids.len()).map(|i| rust.name_at(i).map(str::to_string));
        self.names.extend(names);
    }

    /// Closes the context and hands the forces given to the engine.
    fn finish(&mut self, rust: &mut ForceContext<'_>) {
        self.open = false;
        for &(i, force, point, torque) in &self.pushes {
            let id = self.ids[i];
            match point {
                Some(p) => rust.add_force_at_local_point(id, force, p),
                None => rust.add_force(id, force),
            };
            rust.add_torque(id, torque);
        }
    }

    fn check_open(&self) -> PyResult<()> {
        if self.open {
            Ok(())
        } else {
            Err(PyRuntimeError::new_err(
                "ForceContext: only valid inside the force callback it was passed to",
            ))
        }
    }

    /// The dense index of a body argument: a `tumble.Body` of this world, or a name.
    fn dense(&self, body: &Bound<'_, PyAny>) -> PyResult<usize> {
        self.check_open()?;
        if let Ok(b) = body.cast::<PyBody>() {
            let b = b.get();
            if b.world.as_ptr() as usize != self.world {
                return Err(invalid("body", "this body belongs to another world"));
            }
            let slot = self.slots.get(b.id.index as usize).copied().flatten();
            return slot
                .filter(|&(generation, _)| generation == b.id.generation)
                .map(|(_, i)| i)
                .ok_or_else(|| invalid("body", "this body was removed"));
        }
        if let Ok(name) = body.extract::<String>() {
            return self
                .names
                .iter()
                .position(|n| n.as_deref() == Some(name.as_str()))
                .ok_or_else(|| invalid("body", format!("no body named '{name}'")));
        }
        Err(wrong_type("body", "a tumble.Body or a body's name", body))
    }

    fn state(&self, body: &Bound<'_, PyAny>) -> PyResult<EvaluatedState> {
        Ok(self.states[self.dense(body)?])
    }

    /// The exception that stopped the last step, if a callback raised one.
    pub fn take_error(&mut self) -> Option<PyErr> {
        self.error.take()
    }
}

#[pymethods]
impl PyForceContext {
    // A callback that holds a body of its world (the usual case) makes a cycle: function
    // -> Body -> World -> (engine closure) -> this -> function. The handles and the world
    // report their references, this reports the functions and drops them when the
    // collector breaks the cycle (the engine's closures then call nothing).
    fn __traverse__(&self, visit: PyVisit<'_>) -> Result<(), PyTraverseError> {
        for f in &self.functions {
            visit.call(f)?;
        }
        Ok(())
    }

    fn __clear__(&mut self) {
        self.functions.clear();
    }

    /// Simulated time of the state being evaluated (s).
    #[getter]
    fn time(&self) -> PyResult<f64> {
        self.check_open()?;
        Ok(wide(self.time))
    }

    /// World position of the body frame's origin (m), array (3,).
    fn position<'py>(
        &self,
        py: Python<'py>,
        body: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.state(body)?.position))
    }

    /// World position of the centre of mass (m), array (3,).
    fn center_of_mass<'py>(
        &self,
        py: Python<'py>,
        body: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.state(body)?.center_of_mass))
    }

    /// Orientation, body frame to world, [x, y, z, w].
    fn orientation<'py>(
        &self,
        py: Python<'py>,
        body: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(quat_out(py, self.state(body)?.orientation))
    }

    /// Velocity of the centre of mass (m/s, world frame), array (3,).
    fn velocity<'py>(
        &self,
        py: Python<'py>,
        body: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.state(body)?.velocity))
    }

    /// Angular velocity (rad/s, world frame), array (3,).
    fn angular_velocity<'py>(
        &self,
        py: Python<'py>,
        body: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.state(body)?.angular_velocity))
    }

    /// Mass (kg).
    fn mass(&self, body: &Bound<'_, PyAny>) -> PyResult<f64> {
        Ok(wide(self.state(body)?.mass))
    }

    /// Adds `force` (N, world frame) at `point` (m, body frame; default the centre of
    /// mass, as `World.add_force`), for this evaluation only; off the centre it also
    /// turns the body, τ = r × F. Checked as `World.add_force` checks them.
    #[pyo3(signature = (body, force, point = None))]
    fn add_force(
        &mut self,
        body: &Bound<'_, PyAny>,
        force: &Bound<'_, PyAny>,
        point: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let i = self.dense(body)?;
        let applied = AppliedForce {
            body: self.ids[i],
            force: vec3(force, "force")?,
            point: point.map(|p| vec3(p, "point")).transpose()?,
            torque: Vec3::ZERO,
        };
        Force::Applied(applied).validate().map_err(engine)?;
        self.pushes
            .push((i, applied.force, applied.point, Vec3::ZERO));
        Ok(())
    }

    /// Adds `torque` (N·m, world frame) for this evaluation only.
    fn add_torque(&mut self, body: &Bound<'_, PyAny>, torque: &Bound<'_, PyAny>) -> PyResult<()> {
        let i = self.dense(body)?;
        let applied = AppliedForce {
            body: self.ids[i],
            force: Vec3::ZERO,
            point: None,
            torque: vec3(torque, "torque")?,
        };
        Force::Applied(applied).validate().map_err(engine)?;
        self.pushes.push((i, Vec3::ZERO, None, applied.torque));
        Ok(())
    }

    fn __repr__(&self) -> String {
        if self.open {
            format!(
                "<tumble.ForceContext: t = {} s, {} bodies>",
                self.time,
                self.states.len()
            )
        } else {
            "<tumble.ForceContext: closed>".to_string()
        }
    }
}

/// The engine's callback that calls the world's `k`-th Python callback with its context.
fn python_force(ctx: Py<PyForceContext>, k: usize) -> ForceCallback {
    Box::new(move |rust: &mut ForceContext<'_>| {
        Python::attach(|py| {
            if let Err(e) = call(py, ctx.bind(py), k, rust) {
                let reason = e.to_string();
                rust.fail(reason);
                // The engine calls no callback after a failure, so this is the step's
                // one exception (the loop takes it when the step returns).
                if let Ok(mut c) = ctx.bind(py).try_borrow_mut() {
                    c.error = Some(e);
                }
            }
        })
    })
}

/// One call: the context opened on `rust`, the `k`-th function called with it, the forces
/// handed over.
fn call(
    py: Python<'_>,
    ctx: &Bound<'_, PyForceContext>,
    k: usize,
    rust: &mut ForceContext<'_>,
) -> PyResult<()> {
    let Some(func) = ctx.try_borrow()?.functions.get(k).map(|f| f.clone_ref(py)) else {
        // Cleared by the garbage collector: the world is being freed.
        return Ok(());
    };
    ctx.try_borrow_mut()?.begin(rust);
    let result = func.call1(py, (ctx,));
    let mut c = ctx.try_borrow_mut()?;
    c.open = false;
    result?;
    c.finish(rust);
    Ok(())
}

/// Adds `func` to the world of `inner` as a force callback, with the world's context
/// (made with its first callback).
fn add(world: &Bound<'_, PyWorld>, inner: &mut Inner, func: &Bound<'_, PyAny>) -> PyResult<()> {
    let py = world.py();
    let mut callbacks = match inner.callbacks.take() {
        Some(c) => c,
        None => Callbacks {
            ctx: Py::new(py, PyForceContext::new(world))?,
            closures: 0,
        },
    };
    let pushed = callbacks.ctx.bind(py).try_borrow_mut().map(|mut c| {
        c.functions.push(func.clone().unbind());
        c.functions.len() - 1
    });
    if let Ok(k) = pushed {
        let closure = python_force(callbacks.ctx.clone_ref(py), k);
        inner.world.add_force_callback(closure);
        callbacks.closures += 1;
    }
    inner.callbacks = Some(callbacks);
    pushed.map(|_| ()).map_err(PyErr::from)
}

#[pymethods]
impl PyWorld {
    /// Adds a force callback: `fn(ctx)` is called at every force evaluation with a
    /// tumble.ForceContext, whose `time` and body states are those being evaluated, and
    /// whose `add_force` and `add_torque` push bodies for that evaluation. How often per
    /// step: once with the Euler methods and Störmer–Verlet, twice with midpoint and
    /// velocity Verlet, four times with RK4 (bodies touching nothing); once per solver
    /// substep for bodies in contact or joined (once more when a joined body touches
    /// nothing). An exception in fn stops the step: the world is left as it was before
    /// it and the exception is raised by `step` or `simulate`. Wakes every body; forces
    /// on a sleeping body are not evaluated (while every body sleeps fn is not called):
    /// `sleep=False` for forces that may start on a body at rest. A call costs about
    /// 0.2 µs, plus 25 ns per body in the world (its state is copied for ctx), plus
    /// what fn does (ctx.position 0.4 µs, ctx.add_force 0.2 µs); 8 µs more when a large
    /// world steps on several threads (Python makes a thread state for each call).
    fn add_force_callback(slf: &Bound<'_, Self>, callback: &Bound<'_, PyAny>) -> PyResult<()> {
        if !callback.is_callable() {
            return Err(wrong_type("callback", "a callable fn(ctx)", callback));
        }
        let mut g = slf.get().lock()?;
        add(slf, &mut g, callback)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyForceContext>()
}
