//! Collision detection per step for 1k, 10k and 100k bodies: broad-phase updates, the
//! pair list, then the narrow phase on every pair. Run with
//! `cargo bench -p tumble --bench collision`.
//!
//! Half spheres, half boxes, about 0.5 m across, scattered uniformly through a cube sized
//! so each body's enlarged box meets a few others. Each step about 1% of the bodies jump
//! several metres (teleports: their proxies are reinserted) and the rest jitter by
//! centimetres about a home point (their proxies stay put), the common case of a settled
//! scene with a few fast bodies. Before each size the bench prints the body, pair and
//! manifold counts (the same per body at every size, so the work is of the same kind) and
//! the fastest of ten steps phase by phase: proxy updates, `pairs()`, narrow phase. The
//! algorithmic cost per step grows like n (updates, pairs) plus k log n (the ~n/100
//! reinsertions and their tree queries); past the cache sizes memory stalls add to it.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::time::{Duration, Instant};
use tumble::broad_phase::{BroadPhase, Filter, ProxyId, ProxyKind};
use tumble::math::PI;
use tumble::narrow_phase::{collide, Manifold};
use tumble::{Aabb, Mat3, Pose, Quat, Real, Shape, Vec3};

/// Broad-phase margin (m): how far a stored box reaches beyond the body.
const MARGIN: Real = 0.1;
/// Speculative contact distance passed to the narrow phase (m).
const CONTACT_MARGIN: Real = 0.02;
/// Volume of the scatter cube per body (m³). A 0.5 m body's box enlarged by the margin is
/// about 0.7–0.9 m across, so boxes meet when centres are within ~0.8 m on every axis:
/// a (1.6 m)³ ≈ 4 m³ region, which at this density holds about three other bodies.
const VOLUME_PER_BODY: Real = 1.3;
/// Fraction of bodies teleported per step.
const JUMP_FRACTION: f64 = 0.01;
/// Largest jump along each axis (m), and the jitter about home (m).
const JUMP: Real = 6.0;
const JITTER: Real = 0.02;

/// SplitMix64: a small deterministic generator, so runs are repeatable.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.unit() as Real
    }
    fn vec(&mut self, lo: Real, hi: Real) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
    fn rotation(&mut self) -> Quat {
        let axis = self.vec(-1.0, 1.0).try_normalize().unwrap_or(Vec3::X);
        Quat::from_axis_angle(axis, self.range(0.0, 2.0 * PI))
    }
}

/// World box of a sphere or a box at `pose`: a box's half extents seen along the world
/// axes are |R|·h.
fn tight_aabb(shape: &Shape, pose: &Pose) -> Aabb {
    match shape {
        Shape::Sphere { radius } => Aabb::from_center(pose.position, Vec3::splat(*radius)),
        Shape::Box { half_extents } => {
            let r = Mat3::from_quat(pose.rotation);
            let abs = Mat3::from_cols(r.x_axis.abs(), r.y_axis.abs(), r.z_axis.abs());
            Aabb::from_center(pose.position, abs * *half_extents)
        }
        _ => Aabb::from_center(pose.position, Vec3::ZERO),
    }
}

struct Body {
    shape: Shape,
    home: Vec3,
    pose: Pose,
    proxy: ProxyId,
}

struct Scene {
    bodies: Vec<Body>,
    broad: BroadPhase,
    rng: Rng,
    side: Real,
    pairs: Vec<(u32, u32)>,
    manifolds: Vec<Manifold>,
}

/// What one step found.
struct StepCounts {
    reinserted: usize,
    pairs: usize,
    manifolds: usize,
}

impl Scene {
    fn new(n: usize) -> Scene {
        let side = (VOLUME_PER_BODY * n as Real).cbrt();
        let mut rng = Rng(n as u64);
        let mut broad = BroadPhase::new(MARGIN);
        let mut bodies = Vec::with_capacity(n);
        for i in 0..n {
            let home = rng.vec(0.0, side);
            let (shape, rotation) = if i % 2 == 0 {
                (Shape::sphere(rng.range(0.2, 0.3)), Quat::IDENTITY)
            } else {
                (Shape::cuboid(rng.vec(0.15, 0.3)), rng.rotation())
            };
            let pose = Pose::new(home, rotation);
            let proxy = broad.insert(
                tight_aabb(&shape, &pose),
                i as u32,
                ProxyKind::Moving,
                Filter::default(),
            );
            bodies.push(Body {
                shape,
                home,
                pose,
                proxy,
            });
        }
        let mut pairs = Vec::new();
        broad.pairs(&mut pairs);
        Scene {
            bodies,
            broad,
            rng,
            side,
            pairs,
            manifolds: Vec::new(),
        }
    }

    /// One step: move the bodies and update their proxies, then the pairs, then the
    /// narrow phase on each pair.
    fn step(&mut self) -> StepCounts {
        let reinserted = self.move_bodies();
        self.find_pairs();
        self.narrow_phase();
        StepCounts {
            reinserted,
            pairs: self.pairs.len(),
            manifolds: self.manifolds.len(),
        }
    }

    /// Teleports ~1% of the bodies and jitters the rest; returns how many proxies the
    /// broad phase reinserted.
    fn move_bodies(&mut self) -> usize {
        let mut reinserted = 0;
        for body in &mut self.bodies {
            let displacement = if self.rng.unit() < JUMP_FRACTION {
                // A teleport several metres away, wrapped into the cube so the density
                // stays uniform; no displacement is passed, so no forward stretch.
                let jump = self.rng.vec(-JUMP, JUMP);
                body.home = (body.home + jump).rem_euclid(Vec3::splat(self.side));
                body.pose.position = body.home;
                if matches!(body.shape, Shape::Box { .. }) {
                    body.pose.rotation = self.rng.rotation();
                }
                Vec3::ZERO
            } else {
                let to = body.home + self.rng.vec(-JITTER, JITTER);
                let d = to - body.pose.position;
                body.pose.position = to;
                d
            };
            let aabb = tight_aabb(&body.shape, &body.pose);
            reinserted += self.broad.update(body.proxy, aabb, displacement) as usize;
        }
        reinserted
    }

    fn find_pairs(&mut self) {
        self.broad.pairs(&mut self.pairs);
    }

    fn narrow_phase(&mut self) {
        self.manifolds.clear();
        for &(a, b) in &self.pairs {
            let (a, b) = (&self.bodies[a as usize], &self.bodies[b as usize]);
            collide(
                &a.shape,
                &a.pose,
                &b.shape,
                &b.pose,
                CONTACT_MARGIN,
                &mut self.manifolds,
            );
        }
    }

    /// The fastest of a few steps, phase by phase (ms): where the time goes, untimed by
    /// criterion.
    fn phase_times(&mut self, steps: usize) -> [f64; 3] {
        let mut best = [f64::INFINITY; 3];
        for _ in 0..steps {
            let t0 = Instant::now();
            self.move_bodies();
            let t1 = Instant::now();
            self.find_pairs();
            let t2 = Instant::now();
            self.narrow_phase();
            let t3 = Instant::now();
            for (b, d) in best.iter_mut().zip([t1 - t0, t2 - t1, t3 - t2]) {
                *b = b.min(d.as_secs_f64() * 1e3);
            }
        }
        best
    }
}

fn collision_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("collision_step");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5));
    for n in [1_000, 10_000, 100_000] {
        let mut scene = Scene::new(n);
        let counts = scene.step();
        let [update, pairs, narrow] = scene.phase_times(10);
        println!(
            "collision_step/{n}: {n} bodies, {} pairs ({:.2} per body), {} manifolds, \
             {} proxies reinserted in the step; fastest of 10 steps: update {update:.3} ms, \
             pairs {pairs:.3} ms, narrow phase {narrow:.3} ms; moving tree height {}",
            counts.pairs,
            counts.pairs as f64 / n as f64,
            counts.manifolds,
            counts.reinserted,
            scene.broad.tree_heights()[1],
        );
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| scene.step().pairs)
        });
    }
    group.finish();
}

criterion_group!(benches, collision_step);
criterion_main!(benches);
