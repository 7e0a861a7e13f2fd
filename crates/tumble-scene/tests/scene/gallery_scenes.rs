//! The scenes added for the README's gallery behave as their descriptions say.

use tumble::Vec3;

fn run(name: &str) -> tumble_scene::Scene {
    let mut scene = tumble_scene::load(name).unwrap();
    let plan = scene.plan().unwrap();
    for k in 1..=plan.steps {
        scene.world.step(plan.step_dt(k)).unwrap();
    }
    scene
}

#[test]
fn pendulum_chain_stays_joined_and_keeps_its_energy() {
    let start = tumble_scene::load("pendulum_chain")
        .unwrap()
        .world
        .diagnostics()
        .total;
    let scene = run("pendulum_chain");
    let world = &scene.world;
    // Each link's ends (±0.2 m along its axis) stay on its neighbours' ends.
    let ends: Vec<(Vec3, Vec3)> = world
        .bodies()
        .map(|(_, b)| {
            let (p, q) = (b.position(), b.orientation());
            (
                p + q * Vec3::new(0.0, 0.2, 0.0),
                p + q * Vec3::new(0.0, -0.2, 0.0),
            )
        })
        .collect();
    assert!((ends[0].0 - Vec3::new(0.0, 2.5, 0.0)).length() < 0.01);
    for w in ends.windows(2) {
        let gap = (w[1].0 - w[0].1).length();
        assert!(gap < 0.01, "gap {gap} m");
    }
    // Released from rest: it swings, and the joints neither add nor lose much energy.
    let d = world.diagnostics();
    assert!(d.kinetic > 1.0, "kinetic {}", d.kinetic);
    let change = (d.total - start) / start.abs();
    assert!(change.abs() < 0.1, "energy changed by {change}");
}

#[test]
fn pyramid_is_struck_and_its_boxes_stay_above_the_ground() {
    let scene = run("pyramid");
    let mut moved = 0;
    let initial = tumble_scene::load("pyramid").unwrap();
    for ((_, b), (_, b0)) in scene.world.bodies().zip(initial.world.bodies()).skip(1) {
        assert!(b.position().y > 0.2, "{:?} sank", b.name());
        if (b.position() - b0.position()).length() > 0.05 {
            moved += 1;
        }
    }
    assert!(moved >= 2, "the ball knocked {moved} bodies");
}
