//! `tumble render`, `plot` and `analyze --plot` end to end: the pictures are read back and
//! checked pixel by pixel.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use tumble_render::encode::read_png;

fn tumble(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tumble"))
        .args(args)
        .output()
        .expect("tumble starts")
}

fn ok(args: &[&str]) -> String {
    let out = tumble(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "tumble {args:?}: {err}");
    // Not a terminal here: no progress bar, nothing on stderr.
    assert!(err.is_empty(), "stderr: {err}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn refused(args: &[&str]) -> String {
    let out = tumble(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "tumble {args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "not one line: {err:?}");
    err.trim_end().to_string()
}

fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tumble-visual-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A red ball dropped from 2 m above a ground plane.
const FALLING: &str = r##"{"dt": 0.01, "duration": 0.5, "bodies": [
  {"name": "ground", "kind": "static", "shape": {"type": "plane", "normal": [0, 1, 0]}},
  {"name": "ball", "color": "#ff0000", "shape": {"type": "sphere", "radius": 0.25}, "position": [0, 2, 0]}
]}"##;

fn red_rows(rgba: &[u8], width: u32) -> (f64, usize) {
    let (mut sum, mut n) = (0.0, 0);
    for (i, p) in rgba.chunks(4).enumerate() {
        if p[0] > 50 && p[1] < 30 && p[2] < 30 {
            sum += (i / width as usize) as f64;
            n += 1;
        }
    }
    (sum / n.max(1) as f64, n)
}

#[test]
fn render_to_a_folder_shows_the_ball_falling_frame_by_frame() {
    let dir = scratch("frames");
    let scene = dir.join("falling.json");
    std::fs::write(&scene, FALLING).unwrap();
    let frames = dir.join("frames");
    let said = ok(&[
        "render",
        s(&scene),
        "--out",
        s(&frames),
        "--fps",
        "10",
        "--width",
        "96",
        "--height",
        "72",
        "--camera",
        "0,1.5,6",
        "--target",
        "0,1,0",
    ]);
    assert!(said.contains("(6 frames, 96x72 px)"), "{said}");
    let mut last = f64::NEG_INFINITY;
    for k in 0..6 {
        let (w, h, rgba) = read_png(&frames.join(format!("frame_{k:05}.png"))).unwrap();
        assert_eq!((w, h), (96, 72));
        let (y, n) = red_rows(&rgba, w);
        assert!(n > 20, "frame {k}: {n} red pixels");
        assert!(y > last, "frame {k}: red centroid row {y} not below {last}");
        last = y;
        // The top corners are background, the bottom ones ground: neither red.
        assert_eq!(&rgba[..3], &tumble_render::BACKGROUND.0);
    }
    assert!(!frames.join("frame_00006.png").exists());
}

#[test]
fn render_gif_and_png() {
    let dir = scratch("gif");
    let gif_path = dir.join("ff.gif");
    ok(&[
        "render",
        "free_fall",
        "--out",
        s(&gif_path),
        "--duration",
        "0.3",
        "--width",
        "64",
        "--height",
        "48",
        "-q",
    ]);
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options
        .read_info(std::fs::File::open(&gif_path).unwrap())
        .unwrap();
    let mut frames = 0;
    let mut coloured = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert_eq!((frame.width, frame.height), (64, 48));
        frames += 1;
        // The ball is the only saturated thing in the picture.
        coloured.push(
            frame
                .buffer
                .chunks(4)
                .filter(|p| p[0].abs_diff(p[2]) > 60)
                .count(),
        );
    }
    assert_eq!(frames, 10, "0.3 s at 30 fps: frames at 0, 1/30, ..., 0.3 s");
    assert!(coloured.iter().all(|n| *n > 3), "{coloured:?}");

    let png = dir.join("last.png");
    let said = ok(&[
        "render",
        "resting",
        "--out",
        s(&png),
        "--duration",
        "0",
        "--width",
        "80",
        "--height",
        "60",
        "--contacts",
        "--joints",
    ]);
    assert!(said.contains("1 picture"), "{said}");
    let (w, h, rgba) = read_png(&png).unwrap();
    assert_eq!((w, h, rgba.len()), (80, 60, 80 * 60 * 4));
}

#[test]
fn render_refuses_bad_options_in_one_line() {
    let dir = scratch("refusals");
    let out = dir.join("a.gif");
    let out = s(&out);
    assert!(refused(&["render", "free_fall", "--out", "x.bmp"])
        .starts_with("out: unknown picture format '.bmp'"));
    assert!(
        refused(&["render", "free_fall", "--out", out, "--camera", "1,2"])
            .starts_with("camera: expected three numbers")
    );
    assert!(
        refused(&["render", "free_fall", "--out", out, "--target", "a,b,c"])
            .starts_with("target: ")
    );
    assert!(refused(&[
        "render",
        "free_fall",
        "--out",
        out,
        "--camera",
        "1,1,1",
        "--target",
        "1,1,1"
    ])
    .starts_with("camera: "));
    assert!(refused(&["render", "free_fall", "--out", out, "--fps", "0"]).starts_with("fps: "));
    assert!(refused(&["render", "free_fall", "--out", out, "--width", "4"]).starts_with("width: "));
    assert!(
        refused(&["render", "free_fall", "--out", out, "--duration", "-1"])
            .starts_with("duration: ")
    );
    assert!(
        refused(&["render", "free_fall", "--out", "/nonexistent/dir/a.gif"])
            .starts_with("out: cannot create")
    );
    let bad = dir.join("bad.json");
    std::fs::write(
        &bad,
        r#"{"bodies": [{"color": "red", "shape": {"type": "sphere", "radius": 1}}]}"#,
    )
    .unwrap();
    assert_eq!(
        refused(&["render", s(&bad), "--out", out]),
        "bodies[0].color: expected \"#rrggbb\", got 'red'"
    );
}

#[test]
fn run_stays_quiet_off_a_terminal() {
    let out = tumble(&["run", "dzhanibekov", "--quiet"]);
    assert!(out.status.success());
    assert!(out.stdout.is_empty() && out.stderr.is_empty());
}

/// (count, mean row, mean column) of the pixels of exactly this colour.
fn pixels_of(
    rgba: &[u8],
    width: u32,
    colour: (u8, u8, u8),
    columns: std::ops::Range<u32>,
) -> (usize, f64) {
    let (mut n, mut rows) = (0, 0.0);
    for (i, p) in rgba.chunks(4).enumerate() {
        let x = i as u32 % width;
        if columns.contains(&x) && (p[0], p[1], p[2]) == colour {
            n += 1;
            rows += (i as u32 / width) as f64;
        }
    }
    (n, rows / n.max(1) as f64)
}

#[test]
fn plot_draws_each_column_as_its_own_line() {
    let dir = scratch("plot");
    let csv = dir.join("diag.csv");
    let mut text = String::from("time,kinetic,total\n");
    for k in 0..=50 {
        let t = k as f64 * 0.1;
        text.push_str(&format!("{t},{},{}\n", 2.0 * t, 10.0 - 0.5 * t));
    }
    std::fs::write(&csv, text).unwrap();
    let png = dir.join("energy.png");
    let said = ok(&[
        "plot",
        s(&csv),
        "--out",
        s(&png),
        "--width",
        "400",
        "--height",
        "300",
    ]);
    assert!(said.contains("2 columns against time"), "{said}");
    let (w, h, rgba) = read_png(&png).unwrap();
    assert_eq!((w, h), (400, 300));
    let [kinetic, total] = [0, 1].map(|i| tumble_render::plot::SERIES_COLOURS[i]);
    // Kinetic energy rises: its pixels sit lower (larger rows) on the left than on the
    // right. Total energy falls slowly: the other way round.
    let (nl, left) = pixels_of(&rgba, w, kinetic, 100..200);
    let (nr, right) = pixels_of(&rgba, w, kinetic, 200..380);
    assert!(
        nl > 20 && nr > 20 && left > right + 20.0,
        "kinetic: {left} vs {right}"
    );
    let (nl, left) = pixels_of(&rgba, w, total, 100..200);
    let (nr, right) = pixels_of(&rgba, w, total, 200..380);
    assert!(
        nl > 20 && nr > 20 && left < right,
        "total: {left} vs {right}"
    );

    assert!(refused(&[
        "plot",
        s(&csv),
        "--out",
        s(&png),
        "--columns",
        "kinetic,nope"
    ])
    .starts_with("columns: no column 'nope'"));
    assert!(refused(&["plot", s(&csv), "--out", "x.jpg"]).starts_with("out: "));
    std::fs::write(&csv, "time,body\n0,ball\n").unwrap();
    assert_eq!(
        refused(&["plot", s(&csv), "--out", s(&png)]),
        "file: row 2, column 'body': 'ball' is not a number"
    );
}

#[test]
fn analyze_plot_draws_the_seven_integrators() {
    let dir = scratch("analyze");
    let png = dir.join("convergence.png");
    let said = ok(&["analyze", "--plot", s(&png)]);
    assert!(said.contains("wrote '"), "{said}");
    let (w, _, rgba) = read_png(&png).unwrap();
    for (i, colour) in tumble_render::plot::SERIES_COLOURS[..7].iter().enumerate() {
        let (n, _) = pixels_of(&rgba, w, *colour, 0..w);
        assert!(n > 200, "integrator {i}: {n} pixels of its colour");
    }
    assert_eq!(
        refused(&["analyze", "--plot", "c.svg"]),
        "plot: must be a .png file"
    );
}

/// The JSON recorded into a page.
fn page_data(html: &str) -> serde_json::Value {
    let start = html.find(r#"type="application/json">"#).unwrap() + 24;
    let end = start + html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..end]).unwrap()
}

#[test]
fn export_html_writes_one_offline_page_with_the_run() {
    let dir = scratch("html");
    let scene = dir.join("falling.json");
    std::fs::write(&scene, FALLING.replace("\"ball\"", "\"</script><b>ball\"")).unwrap();
    let html_path = dir.join("sim.html");
    let said = ok(&[
        "export-html",
        s(&scene),
        "--out",
        s(&html_path),
        "--fps",
        "10",
    ]);
    assert!(said.contains("opens offline"), "{said}");
    let html = std::fs::read_to_string(&html_path).unwrap();
    // Self-contained: no script, style or module is fetched from anywhere.
    for needle in ["<script src", "<link", "import(\"http", "from\"http"] {
        assert!(!html.contains(needle), "page refers to {needle}");
    }
    assert_eq!(
        html.matches("</script>").count(),
        2,
        "a body name closed a script early"
    );
    let data = page_data(&html);
    let times = data["times"].as_array().unwrap();
    assert_eq!(times.len(), 6);
    assert_eq!(data["bodies"][1]["color"], "#ff0000");
    assert_eq!(data["bodies"][1]["name"], "</script><b>ball");
    assert!(data["bodies"][0]["plane"].is_object());
    assert!(data["bodies"][1]["mesh"].as_array().unwrap().len() > 300);
    // The ball falls ½ g t²: y at frame k is 2 - 4.9 (k/10)².
    let positions = data["frames"]["position"].as_array().unwrap();
    for (k, p) in positions.iter().enumerate() {
        let y = p[4].as_f64().unwrap();
        let t = k as f64 / 10.0;
        assert!((y - (2.0 - 4.9 * t * t)).abs() < 0.03, "frame {k}: y = {y}");
    }
    // Energy is conserved in free fall (symplectic Euler: to within one step's worth).
    let total: Vec<f64> = data["energy"]["total"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!(
        total
            .iter()
            .all(|e| (e - total[0]).abs() < 0.02 * total[0].abs()),
        "{total:?}"
    );
    assert!(refused(&[
        "export-html",
        "free_fall",
        "--out",
        s(&html_path),
        "--fps",
        "-1"
    ])
    .starts_with("fps: "));
    assert!(
        refused(&["export-html", "free_fall", "--out", "/nonexistent/x.html"])
            .starts_with("out: cannot create")
    );
}

#[test]
fn view_serves_the_page_on_localhost() {
    use std::io::{BufRead, BufReader, Read, Write};
    let mut child = Command::new(env!("CARGO_BIN_EXE_tumble"))
        .args([
            "view",
            "free_fall",
            "--duration",
            "0.2",
            "--no-open",
            "--requests",
            "2",
            "-q",
        ])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.as_mut().unwrap())
        .read_line(&mut line)
        .unwrap();
    let url = line.split_whitespace().nth(1).unwrap().to_string();
    let host = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    assert!(host.starts_with("127.0.0.1:"), "{line}");
    let get = |path: &str| {
        let mut stream = std::net::TcpStream::connect(&host).unwrap();
        let request = format!("GET {path} HTTP/1.1\r\nHost: {host}\r\n\r\n");
        stream.write_all(request.as_bytes()).unwrap();
        let mut reply = String::new();
        stream.read_to_string(&mut reply).unwrap();
        reply
    };
    let page = get("/");
    assert!(page.starts_with("HTTP/1.1 200 OK"), "{}", &page[..60]);
    assert_eq!(page_data(&page)["times"].as_array().unwrap().len(), 7);
    assert!(get("/favicon.ico").starts_with("HTTP/1.1 404"));
    assert!(child.wait().unwrap().success());
}
