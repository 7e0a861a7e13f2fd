//! Both scenes build in every engine, step without NaNs, and start as the brief says.

use tumble_bench::{
    pyramid, rain, rapier_f32, rapier_f64, tumble_engine, SceneSpec, ShapeSpec, Simulation,
    RAIN_HALF_WIDTH,
};

fn step_and_check(mut sim: Box<dyn Simulation>, spec: &SceneSpec) {
    let start = sim.dynamic_positions();
    assert_eq!(start.len(), spec.dynamic_count());
    for _ in 0..3 {
        sim.step();
    }
    let end = sim.dynamic_positions();
    let label = format!("{} {} {}", spec.name, sim.engine(), sim.precision());
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
fn both_scenes_step_in_every_engine() {
    for spec in [pyramid(), rain()] {
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
