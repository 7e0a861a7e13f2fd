//! Heavy loads on light bodies (issue 15, point 2): the islands of a large mass ratio get
//! stiffened contacts and more passes (`solver/mass_ratio.rs`, `softness::LoadSpring`).
//! All at the defaults (4 substeps, one pass), f64 and f32 alike unless said.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::awake_on_ground;
use tumble::prelude::*;

fn world() -> World {
    awake_on_ground(WorldDef::default().gravity)
}

fn body(w: &mut World, at: Vec3, mass: Real, shape: Shape) -> BodyId {
    let def = BodyDef {
        position: at,
        mass: MassSpec::Mass(mass),
        friction: 0.6,
        ..Default::default()
    };
    w.create_body(&def, shape).unwrap()
}

#[test]
fn a_heavy_slab_on_light_cubes_sinks_under_a_centimetre_and_keeps_them_in_place() {
    // Four 1 kg cubes of side `size` at the corners of a square, a slab `ratio` times all
    // four of them on top. The soft contacts alone (a spring of the light cube's
    // effective mass) sank it 7 mm at 50:1 and 28 mm at 200:1 on each cube. Measured now:
    // at most 6.9 mm, the cubes moved 0.5 mm, whatever the cube size and step.
    for size in [0.5 as Real, 0.2] {
        for ratio in [50.0 as Real, 200.0] {
            for dt in [1.0 as Real / 60.0, 1.0 / 240.0] {
                let mut w = world();
                let h = 0.5 * size;
                let corners = [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)];
                let cubes: Vec<(BodyId, Vec3)> = corners
                    .iter()
                    .map(|&(x, z)| {
                        let at = Vec3::new(x * 2.0 * size, h, z * 2.0 * size);
                        (body(&mut w, at, 1.0, Shape::cuboid(Vec3::splat(h))), at)
                    })
                    .collect();
                let thick = 0.2 * size;
                let top = Vec3::new(0.0, size + thick, 0.0);
                let slab_shape = Shape::cuboid(Vec3::new(3.0 * size, thick, 3.0 * size));
                let slab = body(&mut w, top, 4.0 * ratio, slab_shape);
                let at = format!("cubes of {size} m, {ratio}:1 on each, dt {dt:.4}");
                let mut deepest: Real = 0.0;
                for _ in 0..(10.0 / dt).round() as usize {
                    w.step(dt).unwrap();
                    deepest = deepest.max(top.y - w.body(slab).unwrap().position().y);
                }
                assert!(deepest < 0.01, "{at}: the slab sank {deepest} m");
                for (id, start) in cubes {
                    let moved = w.body(id).unwrap().position() - start;
                    let aside = Vec3::new(moved.x, 0.0, moved.z).length();
                    assert!(aside < 0.002, "{at}: a cube was squeezed {aside} m aside");
                }
            }
        }
    }
}

#[test]
fn a_light_box_under_a_thousand_times_heavier_one_rests_without_rocking() {
    // 1 m boxes of 1 kg and 1000 kg (and 100 kg), the heavy one on top. Unstiffened, with
    // three passes, the 1:1000 pair rocked at 3.5 cm/s a second after landing. Measured
    // now: 3.1 mm/s at dt 1/60, 8.2 mm/s at dt 1/240; the 1:100 pair is still (< 0.1 mm/s).
    for (ratio, calm) in [(100.0 as Real, 0.001 as Real), (1000.0, 0.015)] {
        for dt in [1.0 as Real / 60.0, 1.0 / 240.0] {
            let mut w = world();
            let cube = || Shape::cuboid(Vec3::splat(0.5));
            let light = body(&mut w, Vec3::new(0.0, 0.5, 0.0), 1.0, cube());
            let heavy = body(&mut w, Vec3::new(0.0, 1.5, 0.0), ratio, cube());
            let mut fastest: Real = 0.0;
            for i in 0..(5.0 / dt).round() as usize {
                w.step(dt).unwrap();
                if i as Real * dt > 1.0 {
                    for id in [light, heavy] {
                        let v = w.body(id).unwrap().linear_velocity().length();
                        fastest = fastest.max(v);
                    }
                }
            }
            let top = w.body(heavy).unwrap().position();
            let at = format!("1:{ratio}, dt {dt:.4}");
            assert!(fastest < calm, "{at}: rocking at {fastest} m/s");
            assert!(
                top.x.abs().max(top.z.abs()) < 1e-3,
                "{at}: the top moved to {top:?}"
            );
        }
    }
}

#[test]
fn a_heavy_ball_stays_on_a_light_box() {
    // A 500 kg ball of 0.5 m radius on a 1 kg unit box. Rigid, the ball would sit still;
    // on soft contacts the box tilts under any offset of the ball, which rolls further
    // that way: it rolled off within 10 s (3.4 m away). Stiffened it stays on for 10 s at
    // both steps, having crept 0.2 m (0.35 m at 1/240) from the middle; it still rolls off
    // by 30 s (see docs/integrators.md, "Mass ratios").
    for dt in [1.0 as Real / 60.0, 1.0 / 240.0] {
        let mut w = world();
        let b = body(
            &mut w,
            Vec3::new(0.0, 0.5, 0.0),
            1.0,
            Shape::cuboid(Vec3::splat(0.5)),
        );
        let ball = body(&mut w, Vec3::new(0.0, 1.5, 0.0), 500.0, Shape::sphere(0.5));
        for _ in 0..(10.0 / dt).round() as usize {
            w.step(dt).unwrap();
        }
        let (p, q) = (
            w.body(ball).unwrap().position(),
            w.body(b).unwrap().position(),
        );
        let off = Vec3::new(p.x - q.x, 0.0, p.z - q.z).length();
        assert!(
            p.y > 1.4 && off < 0.5,
            "dt {dt:.4}: the ball at {p:?}, the box at {q:?}"
        );
    }
}
