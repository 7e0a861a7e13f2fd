//! Scenes that once finished "successfully" with NaN or infinity in their output, and
//! their neighbours that must still run. The file name says what must happen:
//! `refused_*` is refused when loaded (the CLI's exit 2), `stops_*` loads and a step of its
//! run fails, undone, with one line naming the step, the body and the quantity (exit 1),
//! `runs_*` runs its whole duration. No outcome may leave a value that is not finite.

use std::path::PathBuf;
use tumble_scene::load;

fn single_precision() -> bool {
    std::mem::size_of::<tumble::Real>() == 4
}

fn corpus() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/corpus");
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    files
}

/// Loads and runs a scene: Err(line) for a refusal, Ok(Some(line)) for a run that stopped,
/// Ok(None) for one that finished; every body's state is checked finite either way.
fn outcome(path: &std::path::Path) -> Result<Option<String>, String> {
    let mut scene = load(path.to_str().unwrap()).map_err(|e| e.to_string())?;
    let steps = (scene.duration / scene.dt).ceil() as usize;
    let mut stopped = None;
    for _ in 0..steps {
        if let Err(e) = scene.world.step(scene.dt) {
            assert!(matches!(e, tumble::Error::Unstable(_)), "{e}");
            stopped = Some(e.to_string());
            break;
        }
    }
    for (_, b) in scene.world.bodies() {
        let finite = [b.position(), b.linear_velocity(), b.angular_velocity()]
            .iter()
            .all(|v| v.is_finite())
            && b.orientation().is_finite();
        assert!(finite, "{}: a state that is not finite", path.display());
        let limits = scene.world.speed_limits();
        assert!(
            b.linear_velocity().length() <= limits.max_speed,
            "{}",
            path.display()
        );
    }
    Ok(stopped)
}

#[test]
fn every_scene_of_the_corpus_is_refused_stops_or_runs_as_its_name_says() {
    let files = corpus();
    assert!(files.len() >= 20, "{}", files.len());
    for path in files {
        let name = path.file_name().unwrap().to_str().unwrap().to_string();
        let got = outcome(&path);
        let line = match &got {
            Err(l) | Ok(Some(l)) => l.clone(),
            Ok(None) => String::new(),
        };
        assert_eq!(line.lines().count().max(1), 1, "{name}: {line}");
        assert!(line.len() < 300, "{name}: {line}");
        match name.split('_').next().unwrap() {
            "refused" => assert!(got.is_err(), "{name}: {got:?}"),
            "stops" => {
                let l = got.as_ref().ok().and_then(|o| o.as_deref());
                let l = l.unwrap_or_else(|| panic!("{name}: {got:?}"));
                assert!(
                    l.starts_with("step ") && l.contains("bodies[0] \"ball\""),
                    "{name}: {l}"
                );
            }
            // f32 resolves less: a hull 0.1 nm thin is flat to it, and refused.
            "runs" if single_precision() => assert!(got.is_err() || got == Ok(None), "{name}"),
            "runs" => assert_eq!(got, Ok(None), "{name}"),
            other => panic!("{name}: unknown expectation '{other}'"),
        }
    }
}
