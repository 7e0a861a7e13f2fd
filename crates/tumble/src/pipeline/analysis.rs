//! Measurements of the integrators themselves: observed order of convergence, energy
//! behaviour on a harmonic oscillator, and the largest stable step on a stiff spring.
//! They make the seed's "convergence, order, stability" visible, and back
//! `tumble analyze`, docs/integrators.md and the tests.

use crate::collision::shape::Shape;
use crate::dynamics::body::{BodyDef, MassSpec};
use crate::dynamics::force::{Force, Spring, SpringEnd};
use crate::dynamics::integrate::Integrator;
use crate::math::{Real, Vec3, PI};
use crate::pipeline::world::{World, WorldDef};

/// A 1 kg point-like body on a spring of stiffness `k` (N/m) and damping `b` (N·s/m) to the
/// origin, rest length 0, starting at x = 1 m at rest, with no gravity.
pub fn oscillator(integrator: Integrator, k: Real, b: Real) -> World {
    // Sleeping would freeze a well-damped oscillator at rest; these measure the method.
    // An unstable method's growth is what they measure, so the speed bound is the largest
    // the engine accepts: the run stops only where the arithmetic would give out.
    let most = crate::limits::MAX_MAGNITUDE;
    let mut world = World::new(&WorldDef {
        gravity: Vec3::ZERO,
        integrator,
        sleep: false,
        limits: Some(crate::limits::SpeedLimits {
            max_speed: most,
            max_angular_speed: most,
        }),
        ..Default::default()
    });
    let body = world
        .create_body(
            &BodyDef {
                position: Vec3::new(1.0, 0.0, 0.0),
                mass: MassSpec::Mass(1.0),
                ..Default::default()
            },
            Shape::sphere(0.05),
        )
        .expect("a valid built-in body");
    world
        .add_force(Force::Spring(Spring {
            body,
            anchor: Vec3::ZERO,
            other: SpringEnd::World(Vec3::ZERO),
            stiffness: k,
            rest_length: 0.0,
            damping: b,
        }))
        .expect("a valid built-in spring");
    world
}

/// x(t) of [`oscillator`]: x = e^{−ζω₀t}(cos ω_d t + ζω₀/ω_d sin ω_d t) (underdamped).
pub fn oscillator_exact(k: Real, b: Real, t: Real) -> Real {
    let w0 = k.sqrt();
    let zeta = b / (2.0 * w0);
    let wd = w0 * (1.0 - zeta * zeta).sqrt();
    (-zeta * w0 * t).exp() * ((wd * t).cos() + zeta * w0 / wd * (wd * t).sin())
}

/// Runs `world` for `steps` steps of `dt`, stopping early at any step error.
fn run(world: &mut World, dt: Real, steps: usize) {
    for _ in 0..steps {
        if world.step(dt).is_err() {
            break;
        }
    }
}

/// Errors at a fixed time for a series of halving steps, and the fitted order.
#[derive(Debug, Clone, PartialEq)]
pub struct Convergence {
    /// The method.
    pub integrator: Integrator,
    /// Step sizes tried (s).
    pub dts: Vec<Real>,
    /// Phase-space error √(Δx² + (Δv/ω)²) at the end time (m), one per step size.
    pub errors: Vec<Real>,
    /// Least-squares slope of log(error) against log(dt).
    pub order: Real,
}

/// The observed order of `integrator` on the undamped oscillator with ω = 2π rad/s,
/// x(0) = 1 m, v(0) = 0, measured at t = 1.125 s for dt = `dt0`, `dt0`/2, … (`levels` sizes).
pub fn convergence(integrator: Integrator, dt0: Real, levels: usize) -> Convergence {
    let k = 4.0 * PI * PI;
    // An eighth of a period past the first: at whole periods the phase and amplitude
    // errors of some methods cancel to first order and fake a higher order.
    let end = 1.125;
    let mut dts = Vec::new();
    let mut errors = Vec::new();
    for level in 0..levels {
        let steps = ((end / dt0).round() as usize) << level;
        let dt = end / steps as Real;
        let mut world = oscillator(integrator, k, 0.0);
        run(&mut world, dt, steps);
        let (x, v) = world
            .bodies()
            .next()
            .map_or((Real::NAN, Real::NAN), |(_, b)| {
                (b.position().x, b.linear_velocity().x)
            });
        let w = k.sqrt();
        // Phase-space distance: a position-only error at a turning point would hide the
        // phase error to first order and make every method look one order better.
        let ex = x - (w * end).cos();
        let ev = (v + w * (w * end).sin()) / w;
        dts.push(dt);
        errors.push((ex * ex + ev * ev).sqrt());
    }
    let order = log_log_slope(&dts, &errors);
    Convergence {
        integrator,
        dts,
        errors,
        order,
    }
}

/// The step series `tumble analyze` and the tests use: dt₀ = 0.0125 s halved four times
/// in f64. In f32 the finest errors would sink below rounding, so three sizes, and RK4
/// starts at 0.075 s.
pub fn default_steps(integrator: Integrator) -> (Real, usize) {
    let single = std::mem::size_of::<Real>() == 4;
    match (single, integrator.order()) {
        (false, _) => (0.0125, 5),
        (true, 4) => (0.075, 3),
        (true, _) => (0.0125, 3),
    }
}

/// Least-squares slope of ln y against ln x.
pub fn log_log_slope(x: &[Real], y: &[Real]) -> Real {
    let pts: Vec<(Real, Real)> = x.iter().zip(y).map(|(a, b)| (a.ln(), b.ln())).collect();
    let n = pts.len() as Real;
    let mx = pts.iter().map(|p| p.0).sum::<Real>() / n;
    let my = pts.iter().map(|p| p.1).sum::<Real>() / n;
    let sxy: Real = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: Real = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    sxy / sxx
}

/// How the total energy of the undamped oscillator behaves over a long run.
#[derive(Debug, Clone, PartialEq)]
pub struct EnergyBehaviour {
    /// The method.
    pub integrator: Integrator,
    /// (E_end − E₀) / E₀.
    pub final_change: Real,
    /// Largest |E − E₀| / E₀ seen along the way.
    pub max_deviation: Real,
    /// Energy sampled once per period, relative to E₀.
    pub per_period: Vec<Real>,
    /// Largest |E − E₀| / E₀ within each period.
    pub deviation_per_period: Vec<Real>,
}

/// Energy of the ω = 2π oscillator over `periods` periods at step `dt`.
pub fn energy_behaviour(integrator: Integrator, dt: Real, periods: usize) -> EnergyBehaviour {
    let k = 4.0 * PI * PI;
    let mut world = oscillator(integrator, k, 0.0);
    let e0 = world.diagnostics().total;
    let steps_per_period = (1.0 / dt).round() as usize;
    let mut max_deviation: Real = 0.0;
    let mut per_period = vec![1.0];
    let mut deviation_per_period = Vec::new();
    for _ in 0..periods {
        let mut deviation: Real = 0.0;
        for _ in 0..steps_per_period {
            if world.step(dt).is_err() {
                break;
            }
            let e = world.diagnostics().total;
            deviation = deviation.max(((e - e0) / e0).abs());
        }
        max_deviation = max_deviation.max(deviation);
        deviation_per_period.push(deviation);
        per_period.push(world.diagnostics().total / e0);
    }
    EnergyBehaviour {
        integrator,
        final_change: per_period.last().copied().unwrap_or(1.0) - 1.0,
        max_deviation,
        per_period,
        deviation_per_period,
    }
}

/// The largest step (as the dimensionless h·ω) at which a stiff oscillator (ω = 100 rad/s)
/// stays bounded: amplitude below twice its start over 100 periods. Searched by
/// bisection on h·ω in [1e-3, 10]; `None` when no step in that range is stable.
pub fn largest_stable_step(integrator: Integrator) -> Option<Real> {
    let k: Real = 1.0e4;
    let omega = k.sqrt();
    let stable = |h_omega: Real| -> bool {
        let dt = h_omega / omega;
        let steps = (100.0 * 2.0 * PI / omega / dt).ceil() as usize;
        let mut world = oscillator(integrator, k, 0.0);
        for _ in 0..steps {
            if world.step(dt).is_err() {
                return false;
            }
            let b = world.bodies().next().map(|(_, b)| b.position().x);
            match b {
                Some(x) if x.is_finite() && x.abs() <= 2.0 => {}
                _ => return false,
            }
        }
        true
    };
    let (mut lo, mut hi): (Real, Real) = (1e-3, 10.0);
    if !stable(lo) {
        return None;
    }
    if stable(hi) {
        return Some(hi);
    }
    // 24 halvings of the log-interval pin the limit to 4 parts in 10⁷.
    for _ in 0..24 {
        let mid = (lo * hi).sqrt();
        if stable(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(lo)
}

/// One row of `tumble analyze`.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The method.
    pub integrator: Integrator,
    /// Observed order of convergence.
    pub order: Real,
    /// Relative energy change after 100 periods at 20 steps per period.
    pub energy_change: Real,
    /// Largest |ΔE|/E₀ seen over those periods.
    pub energy_max_deviation: Real,
    /// Largest stable h·ω on the stiff spring (`None`: none found; 10 means ≥ 10).
    pub stable_h_omega: Option<Real>,
}

/// The whole analysis, one row per integrator.
pub fn report() -> Vec<Row> {
    Integrator::ALL
        .into_iter()
        .map(|integrator| {
            let (dt0, levels) = default_steps(integrator);
            let c = convergence(integrator, dt0, levels);
            let e = energy_behaviour(integrator, 0.05, 100);
            Row {
                integrator,
                order: c.order,
                energy_change: e.final_change,
                energy_max_deviation: e.max_deviation,
                stable_h_omega: largest_stable_step(integrator),
            }
        })
        .collect()
}
