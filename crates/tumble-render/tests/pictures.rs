//! Pictures checked pixel by pixel: where the bodies are, what colour, and where nothing is.

use glam::Vec3;
use tumble_render::{Camera, Model, Overlays, Pixmap, Renderer, Rgb, Snapshot, BACKGROUND};

const W: u32 = 160;
const H: u32 = 120;

/// A red ball dropped from 3 m beside a blue box on a ground plane.
const SCENE: &str = r##"{
  "dt": 0.01, "duration": 0.6,
  "bodies": [
    {"name": "ground", "kind": "static", "shape": {"type": "plane", "normal": [0, 1, 0]}},
    {"name": "ball", "color": "#ff0000", "shape": {"type": "sphere", "radius": 0.3},
     "position": [0, 3, 0]},
    {"name": "crate", "color": "#2040e0", "shape": {"type": "box", "half_extents": [0.3, 0.3, 0.3]},
     "position": [1.5, 0.3, 0]}
  ]
}"##;

fn is_red(p: &[u8]) -> bool {
    p[0] > 50 && p[1] < 30 && p[2] < 30
}

fn pixel(pixmap: &Pixmap, x: f32, y: f32) -> [u8; 3] {
    let i = 4 * (y as usize * pixmap.width() as usize + x as usize);
    let d = pixmap.data();
    [d[i], d[i + 1], d[i + 2]]
}

/// Mean pixel position of the red pixels, and their count.
fn red_centroid(pixmap: &Pixmap) -> (f32, f32, usize) {
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0);
    for (i, p) in pixmap.data().chunks(4).enumerate() {
        if is_red(p) {
            sx += (i % W as usize) as f32;
            sy += (i / W as usize) as f32;
            n += 1;
        }
    }
    (sx / n.max(1) as f32, sy / n.max(1) as f32, n)
}

/// Frames of the falling ball at t = 0, 0.2, 0.4, 0.6 s, from a camera in front.
fn frames() -> (Camera, Vec<Snapshot>, Renderer) {
    let mut scene = tumble_scene::load_str(SCENE).unwrap();
    let mut snapshots = vec![Snapshot::capture(&scene.world)];
    for _ in 0..3 {
        for _ in 0..20 {
            scene.world.step(0.01).unwrap();
        }
        snapshots.push(Snapshot::capture(&scene.world));
    }
    let colours: Vec<Option<Rgb>> = scene.body_colors.iter().map(|c| c.map(Rgb)).collect();
    let model = Model::new(&scene.world, &colours, 0.3);
    let camera = Camera::look_at(Vec3::new(0.5, 2.0, 7.0), Vec3::new(0.5, 1.5, 0.0), W, H).unwrap();
    let overlays = Overlays {
        time: true,
        ..Overlays::default()
    };
    (
        camera,
        snapshots.clone(),
        Renderer::new(model, camera, overlays, 4.0),
    )
}

#[test]
fn a_falling_ball_moves_down_the_picture_in_red_where_it_is() {
    let (camera, snapshots, renderer) = frames();
    let mut last_y = f32::NEG_INFINITY;
    for s in &snapshots {
        let picture = renderer.render(s);
        let (cx, cy, n) = red_centroid(&picture);
        assert!(n > 30, "t = {}: only {n} red pixels", s.time);
        assert!(
            cy > last_y + 3.0,
            "t = {}: centroid at y = {cy} after {last_y}",
            s.time
        );
        last_y = cy;
        // The ball's centre, projected, is red, and the red blob is centred on it.
        let centre = camera.project(s.poses[1].0).unwrap();
        assert!(
            is_red(&pixel(&picture, centre.x, centre.y)),
            "t = {}",
            s.time
        );
        assert!(
            (cx - centre.x).abs() < 2.0 && (cy - centre.y).abs() < 2.0,
            "({cx}, {cy}) vs {centre:?}"
        );
        // Nothing red far from it.
        for p in picture
            .data()
            .chunks(4)
            .enumerate()
            .filter(|(_, p)| is_red(p))
        {
            let (x, y) = ((p.0 % W as usize) as f32, (p.0 / W as usize) as f32);
            assert!(
                (x - centre.x).hypot(y - centre.y) < 20.0,
                "stray red at ({x}, {y})"
            );
        }
    }
    // Physics: after 0.6 s the ball has fallen ½ g t² = 1.764 m.
    let fallen = snapshots[0].poses[1].0.y - snapshots[3].poses[1].0.y;
    assert!((fallen - 1.764).abs() < 0.05, "{fallen}");
}

#[test]
fn background_above_and_ground_below_where_no_body_is() {
    let (camera, snapshots, renderer) = frames();
    let picture = renderer.render(&snapshots[0]);
    // The top right corner is sky: exactly the background colour.
    assert_eq!(pixel(&picture, W as f32 - 3.0, 3.0), BACKGROUND.0);
    // A point on the ground plane left of everything is ground (grey), not a body.
    let ground = camera.project(Vec3::new(-1.5, 0.0, 1.0)).unwrap();
    let [r, g, b] = pixel(&picture, ground.x, ground.y);
    assert!(
        r.abs_diff(g) < 20 && g.abs_diff(b) < 20 && r > 120 && [r, g, b] != BACKGROUND.0,
        "{:?}",
        [r, g, b]
    );
    // The box is blue where it stands, lit but not washed out.
    let crate_centre = camera.project(snapshots[0].poses[2].0).unwrap();
    let [r, g, b] = pixel(&picture, crate_centre.x, crate_centre.y);
    assert!(b > 100 && r < 60 && g < 80, "{:?}", [r, g, b]);
    // The time is printed in the top-left corner: dark pixels there.
    let dark = (0..20u32)
        .flat_map(|y| (0..70u32).map(move |x| (x, y)))
        .filter(|(x, y)| {
            pixel(&picture, *x as f32, *y as f32)
                .iter()
                .all(|c| *c < 100)
        })
        .count();
    assert!(dark > 10, "{dark} dark pixels where the time should be");
}

#[test]
fn every_shape_is_drawn_solid() {
    let json = r##"{"gravity": [0, 0, 0], "bodies": [
      {"shape": {"type": "capsule", "radius": 0.3, "half_height": 0.3}, "position": [-2, 0, 0]},
      {"shape": {"type": "cylinder", "radius": 0.3, "half_height": 0.3}, "position": [-1, 0, 0]},
      {"shape": {"type": "convex_hull", "points": [[0,0,0],[0.5,0,0],[0,0.5,0],[0,0,0.5]]}, "position": [0, 0, 0]},
      {"shape": {"type": "compound", "children": [{"shape": {"type": "sphere", "radius": 0.2}, "position": [0, 0.3, 0]}]}, "position": [1, 0, 0]},
      {"kind": "static", "shape": {"type": "trimesh", "vertices": [[0,0,0],[0.6,0,0],[0,0.6,0]], "indices": [[0,1,2]]}, "position": [2, 0, 0]},
      {"kind": "static", "shape": {"type": "heightfield", "heights": [[0,0.5],[0,0]], "scale": [0.5, 1, 0.5]}, "position": [0, -1.5, 0]}
    ]}"##;
    let scene = tumble_scene::load_str(json).unwrap();
    let model = Model::new(&scene.world, &[], 0.2);
    let snapshot = Snapshot::capture(&scene.world);
    let camera =
        Camera::look_at(Vec3::new(0.0, 0.0, 8.0), Vec3::new(0.0, -0.3, 0.0), W, H).unwrap();
    let picture = Renderer::new(model.clone(), camera, Overlays::default(), 4.0).render(&snapshot);
    for (i, (body, (p, _))) in model.bodies.iter().zip(&snapshot.poses).enumerate() {
        // Some pixel near the body's origin has its colour (shaded: a multiple of it).
        let c = camera.project(*p + Vec3::new(0.1, 0.1, 0.0)).unwrap();
        let found = (-6..=6)
            .flat_map(|dy| (-6..=6).map(move |dx| (dx, dy)))
            .any(|(dx, dy)| {
                let q = pixel(&picture, c.x + dx as f32, c.y + dy as f32);
                let base = body.colour.0;
                let k = f32::from(q[0]) / f32::from(base[0].max(1));
                q != BACKGROUND.0
                    && (0..3).all(|j| (f32::from(base[j]) * k - f32::from(q[j])).abs() < 12.0)
            });
        assert!(found, "body {i} ({:?}) not drawn", body.colour);
    }
}
