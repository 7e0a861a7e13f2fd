//! Snapshots (issue 18) on every built-in scene and every integrator: 2 s straight equals
//! 1 s, snapshot, restore into a fresh world, 1 s — bit for bit.
//!
//! The oracle is twofold: the state hash (every body's state bits) after every step of
//! the second second, and the snapshot bytes at the end, which hold everything else a
//! world keeps (contacts with warm starts and anchors, broad-phase trees, sleep timers,
//! islands, joint impulses, integrator memory). Equal bytes mean equal worlds.

use tumble::{Integrator, World};
use tumble_scene::{builtin_names, load, Scene};

/// Steps `scene` `n` times by its own `dt`, recording the state hash after each step; a
/// failed step (an explicit integrator may blow a stiff scene up: that is the method, not
/// the snapshot) is recorded by its message and ends the run.
fn run(scene: &mut Scene, n: usize, out: &mut Vec<String>) {
    for _ in 0..n {
        match scene.step(scene.dt) {
            Ok(()) => out.push(format!("{:016x}", scene.world.state_hash())),
            Err(e) => {
                out.push(e.to_string());
                return;
            }
        }
    }
}

fn scene(name: &str, integrator: Integrator) -> Scene {
    let mut s = load(name).unwrap();
    s.world.set_integrator(integrator);
    s
}

/// Runs `name` 2 s straight and 1 s + snapshot + restore into a fresh world + 1 s, and
/// compares the second seconds step by step and the worlds at the end.
fn check_scene(name: &str, integrator: Integrator) {
    let mut straight = scene(name, integrator);
    let half = (1.0 / straight.dt).round() as usize;
    let mut before = Vec::new();
    run(&mut straight, half, &mut before);
    let bytes = straight.world.snapshot();
    let walker = straight.character.clone();
    let mut first = Vec::new();
    run(&mut straight, half, &mut first);

    let mut resumed = scene(name, integrator);
    resumed.world = World::from_snapshot(&bytes).unwrap();
    // The character's walker is the scene's, not the world's: carried over as is.
    resumed.character = walker;
    assert_eq!(
        resumed.world.snapshot(),
        bytes,
        "{name}: restore is not exact"
    );
    let mut second = Vec::new();
    run(&mut resumed, half, &mut second);
    assert_eq!(first, second, "{name} with {integrator:?}: runs differ");
    assert_eq!(
        straight.world.snapshot(),
        resumed.world.snapshot(),
        "{name} with {integrator:?}: worlds differ after 1 s more"
    );
    assert_eq!(straight.world.time(), resumed.world.time());
}

#[test]
fn every_builtin_scene_continues_bit_identically_with_every_integrator() {
    let names = builtin_names();
    assert!(names.len() >= 14, "the scenes are all there");
    for name in names {
        for integrator in Integrator::ALL {
            check_scene(name, integrator);
        }
    }
}

#[test]
fn a_snapshot_restored_into_the_world_it_came_from_rewinds_it() {
    // Rollback: the pyramid 0.5 s on, then back to the snapshot and on again, twice.
    let mut s = load("pyramid").unwrap();
    run(&mut s, 50, &mut Vec::new());
    let bytes = s.world.snapshot();
    let mut once = Vec::new();
    run(&mut s, 30, &mut once);
    s.world.restore(&bytes).unwrap();
    let mut again = Vec::new();
    run(&mut s, 30, &mut again);
    assert_eq!(once, again);
    assert_eq!(s.world.step_count(), 80);
}
