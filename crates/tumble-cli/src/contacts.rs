//! `tumble contacts SCENE`: the contact points of a scene's initial state, as CSV.

use std::io::{self, Write};

use clap::Args;

use crate::record::{csv_text, Num};
use crate::{stdout_failure, Failure};

/// Header of the contacts table.
pub const CONTACTS_HEADER: &str = "body_a,body_b,x,y,z,nx,ny,nz,separation";

/// Options of `tumble contacts`.
#[derive(Args, Debug)]
pub struct ContactsArgs {
    /// Scene: a built-in name (see `tumble scenes`), a JSON scene file, or a URDF model
    /// (`.urdf`: z-up gravity, base fixed).
    #[arg(value_name = "SCENE")]
    pub scene: String,
}

/// Prints one row per manifold point: the bodies (names, or indices if unnamed), the
/// point midway between the two surfaces (m), the unit normal from body_a to body_b, and
/// the separation along it (m, negative when penetrating). Gaps narrower than the
/// speculative margin are listed too, with positive separation.
pub fn contacts(args: &ContactsArgs) -> Result<(), Failure> {
    let mut scene = crate::load_scene(&args.scene)?;
    let names = scene.body_names.clone();
    let ids: Vec<tumble::BodyId> = scene.world.body_ids().to_vec();
    let label = |id: tumble::BodyId| {
        ids.iter()
            .position(|i| *i == id)
            .and_then(|i| names.get(i).cloned())
            .unwrap_or_default()
    };
    let mut out = io::stdout().lock();
    writeln!(out, "{CONTACTS_HEADER}").map_err(stdout_failure)?;
    for c in scene.world.update_contacts() {
        let n = c.manifold.normal;
        for p in c.manifold.points() {
            let m = (p.point_a + p.point_b) * 0.5;
            writeln!(
                out,
                "{},{},{},{},{},{},{},{},{}",
                csv_text(&label(c.body_a)),
                csv_text(&label(c.body_b)),
                Num(m.x),
                Num(m.y),
                Num(m.z),
                Num(n.x),
                Num(n.y),
                Num(n.z),
                Num(p.separation)
            )
            .map_err(stdout_failure)?;
        }
    }
    Ok(())
}
