//! Tall stacks get finer substeps and contacts stiffer in proportion.
//!
//! A soft contact is a spring of stiffness m ω² for its effective mass m, so it holds a load
//! only by sinking: at rest its depth is the load's acceleration over ω² (g / ω² for a
//! lone box). Up a stack of n equal boxes the k-th contact from the top carries k boxes,
//! and the tower sinks about n² g / ω² in all: 28 mm for 20 boxes at the default 60 Hz
//! (measured 27.58 mm). Towers of 0.1 m, 0.25 m and 0.5 m cubes did worse than sink: the
//! same millimetres of sag are a larger tilt for a small box, and those towers fell over.
//! The sag is the spring's own steady state, not a convergence error, so neither more
//! passes nor an exact solve of the same springs removes it; only a stiffer spring does,
//! and Gauss–Seidel keeps a stiffer spring still only when the substep shrinks with it
//! (the quarter-substep-rate cap on ω). Every variant that stiffened without finer
//! substeps made towers sway or fall (docs/integrators.md, "Tall stacks").
//!
//! So the solver predicts, each step, how far each island's stack would sink at the
//! world's rate: the bodies are levelled breadth first from those touching the ground,
//! each body's weight and load shared among its supports one level down, each support's
//! sag that of its spring under its load, and the island's sag that of its deepest path of
//! supports. Predicted rather than measured, it is known from the step a stack is built,
//! before it sinks: measuring the depths instead switched a tower over only once it had
//! sunk, and the switch made it sway 16 cm. An island whose sag would exceed the tolerance
//! (the linear slop, the depth the engine already treats as touching, or [`SAG_SHARE`] of
//! its thinnest body where that is less) is solved with `k` times the substeps and `k`
//! times the contact frequency, `k` = ⌈√(sag / tolerance)⌉ at most [`FINEST`], which
//! brings its sag under the tolerance while every substep sees the same hω as at the
//! world's rate. Measured on a 20-box tower at dt 1/60: k = 3, sink 3.1 mm after 10 s
//! (27.6 mm before), lean 2.1 mm (9.6); towers of 0.1–2 m cubes all stand at 3.1 mm.
//!
//! Only islands held by contacts alone take part: islands with joints, with a large mass
//! ratio (which have their own cure, `mass_ratio.rs`), touching a kinematic body (which
//! moves once per base substep) or with a pair being pushed out of an overlap (whose
//! allowances are the world rate's: a column of ten cubes made half inside each other
//! leant 10 cm instead of 1.7 cm) keep the world's rate. Islands whose sag stays under the
//! tolerance, the pyramid and the rain benches among them, are untouched bit for bit.

use super::body::BodySim;
use crate::dynamics::island::{find, union};
use crate::math::Real;

/// The most substeps a tall island gets, as a multiple of the world's: enough for a
/// 60-box tower of equal boxes at the defaults (k = 6 for 40 boxes), at eight times the
/// solver's cost for such an island.
pub(crate) const FINEST: u32 = 8;

/// The most an island may sag, as a share of its thinnest body's thickness, where that is
/// less than the slop: 5 mm is a twentieth of a 0.1 m cube but a tenth of a 5 cm brick,
/// and a 20-course wall of 5 cm bricks, predicted to sag under 5 mm, fell (it stands with
/// 2 mm allowed, no brick moving more than 1.9 mm in 10 s).
pub(crate) const SAG_SHARE: Real = 0.04;

/// A contact between two bodies of the step, as the stack search sees it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Support {
    pub a: usize,
    pub b: usize,
    /// Whether the pair keeps its island at the world's rate (an overlap being pushed out).
    pub busy: bool,
    /// Whether the pair ran at a tall stack's finer rate last step.
    pub was_fine: bool,
}

/// What the search knows of a body that the solver does not move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Fixed {
    /// A static body (or one asleep): ground to stand on.
    Ground,
    /// A kinematic body: it moves once per base substep, so what it touches keeps that rate.
    Kinematic,
}

/// The springs' scale: gravity's acceleration `g` (m/s²), the contacts' ω at the world's
/// rate (rad/s), the sag allowed an island (m), and the speed (m/s) above which a body is
/// not resting on its supports (see [`tall_islands`]): that of two steps of free fall, or
/// of a fall through the slop, whichever is larger.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Scale {
    pub g: Real,
    pub omega: Real,
    pub tolerance: Real,
    pub rest_speed: Real,
}

/// For each body, whether its island is a tall stack, and how many times finer those
/// islands' substeps are (one multiple for all, the largest needed); `None` when no island
/// needs it. `fixed(k)` says what a body the solver does not move is; `joined` are the
/// bodies of joints, `heavy` the mass-ratio islands' flags (see `mass_ratio`).
///
/// Only resting islands become tall: with a body faster than `rest_speed`, the loads are
/// not yet the stack's weight. Bodies landing on each other make chains of contacts for a
/// step or two; counted, they sent a tenth of the steps of a 2,000-body rain to finer
/// substeps, 4 % more instructions over its first 200 steps. An island already tall stays
/// so however fast it moves: a stack that sways or settles is still a stack, and dropped
/// to the world's rate it would sink and spring back.
pub(crate) fn tall_islands(
    (sims, speed, half_thickness): (&[BodySim], impl Fn(usize) -> Real, impl Fn(usize) -> Real),
    fixed: impl Fn(usize) -> Fixed,
    contacts: &[Support],
    (joined, heavy): (impl Iterator<Item = usize>, &[bool]),
    scale: Scale,
) -> Option<(Vec<bool>, u32)> {
    if scale.g <= 0.0 || scale.omega <= 0.0 || scale.tolerance <= 0.0 || contacts.is_empty() {
        return None;
    }
    let n = sims.len();
    let moving = |k: usize| sims[k].moves;
    let mut kept = vec![false; n];
    for c in contacts.iter().filter(|c| c.was_fine) {
        (kept[c.a], kept[c.b]) = (true, true);
    }
    let mut barred: Vec<bool> = (0..n)
        .map(|k| {
            let heavy = heavy.get(k).copied().unwrap_or(false);
            heavy || (speed(k) > scale.rest_speed && !kept[k])
        })
        .collect();
    for k in joined.chain(contacts.iter().filter(|c| c.busy).flat_map(|c| [c.a, c.b])) {
        barred[k] = true;
    }
    let sag = Levels::new(sims, &fixed, contacts, &mut barred).sag(sims, scale);
    let mut parent: Vec<usize> = (0..n).collect();
    for c in contacts.iter().filter(|c| moving(c.a) && moving(c.b)) {
        union(&mut parent, c.a, c.b);
    }
    let mut island_sag: Vec<Real> = vec![0.0; n];
    let mut island_barred = vec![false; n];
    let mut allowed = vec![scale.tolerance; n];
    for k in (0..n).filter(|&k| moving(k)) {
        let root = find(&mut parent, k);
        island_sag[root] = island_sag[root].max(sag[k]);
        island_barred[root] |= barred[k];
        allowed[root] = allowed[root].min(SAG_SHARE * 2.0 * half_thickness(k));
    }
    let multiple = |root: usize| -> u32 {
        if island_barred[root] || island_sag[root] <= allowed[root] {
            return 1;
        }
        let k = (island_sag[root] / allowed[root]).sqrt().ceil();
        (k as u32).clamp(1, FINEST)
    };
    let mut finest = 1;
    let flags: Vec<bool> = (0..n)
        .map(|k| {
            if !moving(k) {
                return false;
            }
            let m = multiple(find(&mut parent, k));
            finest = finest.max(m);
            m > 1
        })
        .collect();
    (finest > 1).then_some((flags, finest))
}

/// The moving bodies by breadth-first levels from the ground: level 0 touches a body the
/// solver does not move, level l + 1 touches level l. A body's supports are its contacts
/// with the level below (with the ground, at level 0): stacks are walked up and down
/// along those alone, never sideways.
struct Levels {
    /// Per body, its level (`u32::MAX`: out of reach of the ground).
    level: Vec<u32>,
    /// The bodies in the order they were reached (levels ascending).
    order: Vec<usize>,
    /// Per body, its neighbours among the moving bodies (compressed rows: `next[start[k]..
    /// start[k + 1]]`), in contact order.
    start: Vec<usize>,
    next: Vec<usize>,
    /// Per body, how many contacts it has with the ground.
    grounded: Vec<u32>,
}

impl Levels {
    /// Levels of `contacts`' moving bodies; bodies touching a kinematic body are marked in
    /// `barred`.
    fn new(
        sims: &[BodySim],
        fixed: &impl Fn(usize) -> Fixed,
        contacts: &[Support],
        barred: &mut [bool],
    ) -> Levels {
        let n = sims.len();
        let moving = |k: usize| sims[k].moves;
        let mut start = vec![0usize; n + 1];
        for c in contacts.iter().filter(|c| moving(c.a) && moving(c.b)) {
            start[c.a + 1] += 1;
            start[c.b + 1] += 1;
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut next = vec![0usize; start[n]];
        let mut level = vec![u32::MAX; n];
        let mut grounded = vec![0u32; n];
        let mut order = Vec::new();
        for c in contacts {
            match (moving(c.a), moving(c.b)) {
                (true, true) => {
                    next[fill[c.a]] = c.b;
                    fill[c.a] += 1;
                    next[fill[c.b]] = c.a;
                    fill[c.b] += 1;
                }
                (true, false) | (false, true) => {
                    let (m, other) = if moving(c.a) { (c.a, c.b) } else { (c.b, c.a) };
                    if fixed(other) == Fixed::Kinematic {
                        barred[m] = true;
                    }
                    if level[m] == u32::MAX {
                        level[m] = 0;
                        order.push(m);
                    }
                    grounded[m] += 1;
                }
                (false, false) => {}
            }
        }
        let mut head = 0;
        while head < order.len() {
            let u = order[head];
            head += 1;
            for &v in &next[start[u]..start[u + 1]] {
                if level[v] == u32::MAX {
                    level[v] = level[u] + 1;
                    order.push(v);
                }
            }
        }
        Levels {
            level,
            order,
            start,
            next,
            grounded,
        }
    }

    /// The supports of body `u`: its neighbours one level down.
    fn below(&self, u: usize) -> impl Iterator<Item = usize> + '_ {
        let l = self.level[u];
        self.next[self.start[u]..self.start[u + 1]]
            .iter()
            .copied()
            .filter(move |&v| l > 0 && self.level[v] == l - 1)
    }

    /// How many supports body `u` has (contacts with the ground, at level 0).
    fn supports(&self, u: usize) -> Real {
        match self.level[u] {
            0 => self.grounded[u] as Real,
            _ => self.below(u).count() as Real,
        }
    }

    /// Per body, the sag at the world's rate of the deepest path of supports from the
    /// ground up to it. Each body's weight and what it carries go down to its supports in
    /// equal shares (top level first), and a support carrying the mass M sinks by
    /// M g / (μ ω²), μ being the pair's reduced mass (the body's own on the ground): the
    /// soft contact's spring at rest. On a tower of n equal boxes this sums to about
    /// n² g / ω², which is what the towers measure.
    fn sag(&self, sims: &[BodySim], scale: Scale) -> Vec<Real> {
        let n = sims.len();
        let inv_mass = |k: usize| sims[k].inv_mass;
        let mut load: Vec<Real> = (0..n)
            .map(|k| match inv_mass(k) {
                m if m > 0.0 => 1.0 / m,
                _ => 0.0,
            })
            .collect();
        for &u in self.order.iter().rev() {
            let share = load[u] / self.supports(u);
            for v in self.below(u) {
                load[v] += share;
            }
        }
        let per_mass = scale.g / (scale.omega * scale.omega);
        let mut sag: Vec<Real> = vec![0.0; n];
        for &u in &self.order {
            let share = load[u] / self.supports(u);
            sag[u] = match self.level[u] {
                0 => share * inv_mass(u) * per_mass,
                _ => self
                    .below(u)
                    .map(|v| sag[v] + share * (inv_mass(u) + inv_mass(v)) * per_mass)
                    .fold(0.0, Real::max),
            };
        }
        sag
    }
}
