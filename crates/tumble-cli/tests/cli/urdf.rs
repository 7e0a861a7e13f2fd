//! `tumble run/render/export-html model.urdf`: a URDF file is run directly, by its
//! extension, with z-up gravity and its base fixed; a bad one is one line, exit status 2.

use crate::common::{ok, path, refused, scratch};

const PENDULUM: &str = r#"<?xml version="1.0"?>
<robot name="pendulum">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.05"/></geometry></collision></link>
  <link name="arm">
    <inertial><origin xyz="0 0 -1"/><mass value="1"/>
      <inertia ixx="0.0004" iyy="0.0004" izz="0.0004" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 -1"/><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <joint name="pivot" type="continuous">
    <parent link="base"/><child link="arm"/><origin rpy="0 0.5 0"/><axis xyz="0 1 0"/>
  </joint>
</robot>
"#;

/// The bob (1 m along the arm's −z) from a trajectory row's position and quaternion.
fn bob(row: &[f64]) -> [f64; 3] {
    let (p, [x, y, z, w]) = ([row[0], row[1], row[2]], [row[3], row[4], row[5], row[6]]);
    // R·(0, 0, −1) is minus R's third column.
    let col = [
        2.0 * (x * z + w * y),
        2.0 * (y * z - w * x),
        1.0 - 2.0 * (x * x + y * y),
    ];
    [p[0] - col[0], p[1] - col[1], p[2] - col[2]]
}

#[test]
fn tumble_run_pendulum_urdf_swings_the_pendulum_under_z_up_gravity() {
    // Released 0.5 rad from hanging (the joint's origin turns the arm), the bob stays on
    // its 1 m circle about the fixed base, swings through the bottom to the other side,
    // and never rises above its release height (energy; 1 mm for the soft joint's stretch).
    let dir = scratch("urdf-run");
    let file = dir.join("pendulum.urdf");
    std::fs::write(&file, PENDULUM).unwrap();
    let csv = dir.join("run.csv");
    let summary = ok(&[
        "run",
        path(&file),
        "--out",
        path(&csv),
        "--dt",
        "0.005",
        "--duration",
        "2",
    ]);
    assert!(
        summary.is_empty() || summary.contains("pendulum"),
        "{summary}"
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .filter(|l| l.split(',').nth(1) == Some("arm"))
        .map(|l| {
            l.split(',')
                .skip(2)
                .take(7)
                .map(|x| x.parse().unwrap())
                .collect()
        })
        .collect();
    assert!(rows.len() >= 400, "{} rows", rows.len());
    let release = -(0.5f64).cos();
    let (mut lo, mut hi) = (f64::MAX, f64::MIN);
    for row in &rows {
        let b = bob(row);
        let r = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
        assert!((r - 1.0).abs() < 1e-3, "bob {r} m from the pivot");
        assert!(b[2] < release + 1e-3, "bob rose to {}", b[2]);
        lo = lo.min(b[0]);
        hi = hi.max(b[0]);
    }
    // From x = −sin 0.5 to +sin 0.5 = ±0.479 m and back.
    assert!(lo < -0.47 && hi > 0.47, "swing from {lo} to {hi}");
}

#[test]
fn render_and_export_html_take_a_urdf_too() {
    let dir = scratch("urdf-render");
    let file = dir.join("pendulum.urdf");
    std::fs::write(&file, PENDULUM).unwrap();
    let gif = dir.join("robot.gif");
    ok(&[
        "render",
        path(&file),
        "--out",
        path(&gif),
        "--width",
        "64",
        "--height",
        "48",
        "--quiet",
    ]);
    assert!(std::fs::read(&gif).unwrap().starts_with(b"GIF89a"));
    let html = dir.join("robot.html");
    ok(&["export-html", path(&file), "--out", path(&html), "--quiet"]);
    assert!(std::fs::read_to_string(&html).unwrap().contains("arm"));
}

#[test]
fn a_bad_urdf_is_one_line_naming_file_line_and_element() {
    let dir = scratch("urdf-bad");
    let file = dir.join("bad.urdf");
    std::fs::write(&file, PENDULUM.replace("value=\"1\"", "value=\"-2\"")).unwrap();
    let line = refused(&["run", path(&file)]);
    assert_eq!(
        line,
        format!(
            "{}:4: <link name=\"arm\">: inertial.mass: must be >= 0, got -2",
            path(&file)
        )
    );
}

#[test]
fn a_z_up_model_is_drawn_standing_up() {
    // A 1 m pole hanging along −z, 10 cm thick: with the picture's up against gravity it
    // is at least three times taller than wide on the picture (seen from the side it is
    // ten times; the default view's slant shortens that). Seen as a y-up world would
    // be, from +z, it would point at the camera and come out squat.
    let dir = scratch("urdf-upright");
    let file = dir.join("mast.urdf");
    let mast = r#"<robot name="mast"><link name="base"/>
  <link name="pole"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 -0.5"/><geometry><box size="0.1 0.1 1"/></geometry></collision></link>
  <joint name="j" type="continuous"><parent link="base"/><child link="pole"/><axis xyz="0 1 0"/></joint>
</robot>"#;
    std::fs::write(&file, mast).unwrap();
    let png = dir.join("mast.png");
    ok(&[
        "render",
        path(&file),
        "--out",
        path(&png),
        "--duration",
        "0",
        "--width",
        "120",
        "--height",
        "120",
    ]);
    let (w, h, rgba) = tumble_render::encode::read_png(&png).unwrap();
    let (mut x0, mut x1, mut y0, mut y1) = (u32::MAX, 0, u32::MAX, 0);
    for y in 0..h {
        for x in 0..w {
            let i = 4 * (y * w + x) as usize;
            // The body's colour is saturated; background, grid and text are greys.
            let p = &rgba[i..i + 3];
            let saturated = p.iter().max().unwrap() - p.iter().min().unwrap() > 40;
            if saturated {
                (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
            }
        }
    }
    assert!(x1 >= x0, "nothing drawn");
    let (width, height) = (x1 - x0 + 1, y1 - y0 + 1);
    assert!(
        height >= 3 * width,
        "the pole is {width} px wide and {height} px tall"
    );
}
