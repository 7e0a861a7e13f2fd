//! Every scene builds in every engine, steps without NaNs, and starts as the brief says.

use tumble_bench::{
    joint_grid, pyramid, rain, rapier_f32, rapier_f64, tumble_engine, SceneSpec, ShapeSpec,
    Simulation, RAIN_HALF_WIDTH,
};

fn step_and_check(mut sim: Box<dyn Simulation>, spec: &SceneSpec) {
    let start = sim.dynamic_positions();
    assert_eq!(start.len(), spec.dynamic_count());
    for _ in 0..3 {
        sim.step();
    }
    let end = sim.dynamic_positions();
    let label = format!("{} {} {}", spec.name, sim.engine(), sim.precision());
    let gaps = sim.joint_gaps();
    assert_eq!(gaps.len(), spec.joints.len(), "{label}");
    // Three steps of sag open a joint by a few millimetres at most.
    assert!(
        gaps.iter().all(|g| *g < 0.02),
        "{label}: a joint opened by {:?} m",
        gaps.iter().copied().fold(0.0, f64::max)
    );
    assert_eq!(end.len(), start.len(), "{label}");
    assert!(
        end.iter().flatten().all(|x| x.is_finite()),
        "{label}: a position is not finite"
    );
    // Nothing should have moved more than free fall allows in 3 steps (plus a margin).
    let moved = tumble_bench::max_displacement(&start, &end);
    assert!(moved < 0.1, "{label}: moved {moved} m in 3 steps");
}

#[test]
fn every_scene_steps_in_every_engine() {
    for spec in [pyramid(), rain(), joint_grid()] {
        step_and_check(Box::new(tumble_engine::build(&spec)), &spec);
        step_and_check(Box::new(rapier_f64::build(&spec)), &spec);
        step_and_check(Box::new(rapier_f32::build(&spec)), &spec);
    }
}

#[test]
fn pyramid_is_385_touching_unit_boxes() {
    let spec = pyramid();
    assert_eq!(spec.dynamic_count(), 385);
    for b in spec.bodies.iter().filter(|b| b.dynamic) {
        assert_eq!(b.shape, ShapeSpec::Cuboid([0.5; 3]));
        let layer = b.position[1] - 0.5;
        assert_eq!(layer, layer.round());
    }
}

#[test]
fn rain_starts_apart_and_inside_the_walls() {
    let spec = rain();
    let bodies: Vec<_> = spec.bodies.iter().filter(|b| b.dynamic).collect();
    let spheres = bodies
        .iter()
        .filter(|b| matches!(b.shape, ShapeSpec::Sphere(_)))
        .count();
    assert_eq!((bodies.len(), spheres), (2000, 1000));
    // Bounding spheres: a box of half extent 0.25 reaches 0.25·√3 from its centre.
    let reach = 0.25 * 3f64.sqrt();
    for (i, a) in bodies.iter().enumerate() {
        assert!(a.position[0].abs() + reach < RAIN_HALF_WIDTH);
        assert!(a.position[2].abs() + reach < RAIN_HALF_WIDTH);
        for b in &bodies[i + 1..] {
            let d: f64 = (0..3)
                .map(|k| (a.position[k] - b.position[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(d > 2.0 * reach, "bodies {d} m apart overlap");
        }
    }
}

#[test]
fn joint_grid_is_a_closed_net_hanging_from_one_edge() {
    let spec = joint_grid();
    assert_eq!(spec.bodies.len(), 900);
    // Columns 0, 4, ..., 28 and 29 of the first row.
    assert_eq!(spec.bodies.len() - spec.dynamic_count(), 9);
    assert!(spec
        .bodies
        .iter()
        .filter(|b| !b.dynamic)
        .all(|b| b.position[2] == 0.0));
    // 2 * 30 * 29 neighbour pairs, less the one between the fixed bodies at columns 28, 29.
    assert_eq!(spec.joints.len(), 1739);
    for j in &spec.joints {
        let (a, b) = (&spec.bodies[j.bodies[0]], &spec.bodies[j.bodies[1]]);
        assert!(a.dynamic || b.dynamic);
        // The anchors meet halfway between the two bodies.
        for k in 0..3 {
            assert_eq!(
                a.position[k] + j.anchors[0][k],
                b.position[k] + j.anchors[1][k]
            );
        }
        assert_eq!(tumble_bench::distance(a.position, b.position), 1.0);
    }
    // Every engine starts with every joint closed.
    let sims: [Box<dyn Simulation>; 3] = [
        Box::new(tumble_engine::build(&spec)),
        Box::new(rapier_f64::build(&spec)),
        Box::new(rapier_f32::build(&spec)),
    ];
    for sim in sims {
        assert!(
            sim.joint_gaps().iter().all(|g| *g < 1e-6),
            "{}",
            sim.engine()
        );
    }
}
