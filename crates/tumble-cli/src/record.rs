//! The CSV files a run writes: the trajectory (`--out`), the diagnostics
//! (`--diagnostics`), contacts, joints and sensor events. Numbers are printed so that they read back bit for bit, and the
//! same run always writes the same bytes.

use std::fmt;

use tumble::{JointCoordinate, Real, World};

use crate::output::{Target, Writer};
use crate::Failure;

/// Header of the trajectory file.
pub const TRAJECTORY_HEADER: &str = "time,body,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz";
/// Header of the contacts file.
pub const CONTACT_IMPULSES_HEADER: &str =
    "time,body_a,body_b,x,y,z,nx,ny,nz,normal_impulse,tangent_impulse";
/// Header of the joints file.
pub const JOINT_REACTIONS_HEADER: &str = "time,joint,body,other,fx,fy,fz,tx,ty,tz,broken,\
position,velocity,position_x,position_y,position_z,velocity_x,velocity_y,velocity_z";
/// Header of the sensor events file.
pub const SENSOR_EVENTS_HEADER: &str = "time,sensor,body,began";
/// Header of the diagnostics file.
pub const DIAGNOSTICS_HEADER: &str = "time,kinetic,potential,total,px,py,pz,lx,ly,lz";

/// The output label of each body id: its name, or its index in the scene's `bodies`.
fn labeller<'a>(world: &World, labels: &'a [String]) -> impl Fn(tumble::BodyId) -> &'a str {
    let index: std::collections::BTreeMap<tumble::BodyId, usize> = world
        .body_ids()
        .iter()
        .enumerate()
        .map(|(i, id)| (*id, i))
        .collect();
    move |id| {
        index
            .get(&id)
            .and_then(|i| labels.get(*i))
            .map_or("", String::as_str)
    }
}

/// A number printed with the fewest digits that read back to the same value (Rust's
/// shortest round-trip formatting), in exponent form when plain digits would run long.
pub struct Num(pub Real);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = self.0.abs();
        // Plain `{}` never uses an exponent: 1e-300 would be 300 zeros.
        if a != 0.0 && a.is_finite() && !(1e-5..1e16).contains(&a) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

/// A joint's coordinate and rate as the joints file's last eight fields (see
/// `CsvFile::joints`).
struct Coordinates(Option<JointCoordinate>, Option<JointCoordinate>);

impl fmt::Display for Coordinates {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use JointCoordinate::{Scalar, Vector};
        match (self.0, self.1) {
            (Some(Scalar(q)), Some(Scalar(v))) => write!(f, "{},{},,,,,,", Num(q), Num(v)),
            (Some(Vector(q)), Some(Vector(v))) => write!(
                f,
                ",,{},{},{},{},{},{}",
                Num(q.x),
                Num(q.y),
                Num(q.z),
                Num(v.x),
                Num(v.y),
                Num(v.z)
            ),
            _ => write!(f, ",,,,,,,"),
        }
    }
}

/// A CSV file being written (under its partial name until [`CsvFile::finish`]).
pub struct CsvFile {
    out: Writer,
    /// Data rows written so far.
    pub rows: u64,
}

impl CsvFile {
    /// Creates the file and writes its header.
    pub fn create(target: Target, header: &str) -> Result<CsvFile, Failure> {
        let mut out = Writer::create(target)?;
        out.write(format_args!("{header}\n"))?;
        out.flush_if_direct()?;
        Ok(CsvFile { out, rows: 0 })
    }

    /// The file's path as it was given.
    pub fn shown(&self) -> &str {
        self.out.target().shown()
    }

    /// One row: the time, then the other fields already joined by commas.
    fn row(&mut self, time: Real, rest: fmt::Arguments<'_>) -> Result<(), Failure> {
        self.rows += 1;
        self.out.write(format_args!("{},{rest}\n", Num(time)))
    }

    /// A row per body: label, position of the body frame, orientation, velocities.
    pub fn trajectory(
        &mut self,
        time: Real,
        world: &World,
        labels: &[String],
    ) -> Result<(), Failure> {
        for ((_, body), label) in world.bodies().zip(labels) {
            let (p, q) = (body.position(), body.orientation());
            let (v, w) = (body.linear_velocity(), body.angular_velocity());
            self.row(
                time,
                format_args!(
                    "{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                    csv_text(label),
                    Num(p.x),
                    Num(p.y),
                    Num(p.z),
                    Num(q.x),
                    Num(q.y),
                    Num(q.z),
                    Num(q.w),
                    Num(v.x),
                    Num(v.y),
                    Num(v.z),
                    Num(w.x),
                    Num(w.y),
                    Num(w.z)
                ),
            )?;
        }
        Ok(())
    }

    /// A row per contact point of the last step: bodies, the point midway between the
    /// surfaces, the normal from body_a to body_b, and the impulses applied over the step
    /// (N·s; the friction impulse as its magnitude).
    pub fn contacts(
        &mut self,
        time: Real,
        world: &World,
        labels: &[String],
    ) -> Result<(), Failure> {
        let label = labeller(world, labels);
        for c in world.contacts() {
            let n = c.manifold.normal;
            for p in c.manifold.points() {
                let m = (p.point_a + p.point_b) * 0.5;
                self.row(
                    time,
                    format_args!(
                        "{},{},{},{},{},{},{},{},{},{}",
                        csv_text(label(c.body_a)),
                        csv_text(label(c.body_b)),
                        Num(m.x),
                        Num(m.y),
                        Num(m.z),
                        Num(n.x),
                        Num(n.y),
                        Num(n.z),
                        Num(p.total_normal_impulse),
                        Num(p.total_tangent_impulse.length())
                    ),
                )?;
            }
        }
        Ok(())
    }

    /// A row per sensor event of the last step: its time, the sensor's and the body's
    /// labels, and 1 if the overlap began, 0 if it ended.
    pub fn sensors(&mut self, world: &World, labels: &[String]) -> Result<(), Failure> {
        let events = world.sensor_events();
        if events.is_empty() {
            return Ok(());
        }
        let label = labeller(world, labels);
        for e in events {
            self.row(
                e.time,
                format_args!(
                    "{},{},{}",
                    csv_text(label(e.sensor)),
                    csv_text(label(e.body)),
                    u8::from(e.began)
                ),
            )?;
        }
        Ok(())
    }

    /// A row per joint: its label (name, or index in creation order), its bodies (`world`
    /// for none), and the force and torque it applied to `other` over the last step
    /// (N, N·m; the force on `body` is the opposite), whether it has broken, and its
    /// coordinate and rate: `position,velocity` for hinges, sliders and distance joints
    /// (the `_x,_y,_z` columns empty), `position_x..velocity_z` for ball and fixed joints
    /// (rotation vector and relative angular velocity; `position,velocity` empty).
    pub fn joints(&mut self, time: Real, world: &World, labels: &[String]) -> Result<(), Failure> {
        let body_label = labeller(world, labels);
        let label = |id: Option<tumble::BodyId>| id.map_or("world", &body_label);
        for (k, (id, j)) in world.joints().enumerate() {
            let (f, t) = (j.reaction_force(), j.reaction_torque());
            let name = j.name().map_or_else(|| k.to_string(), str::to_string);
            self.row(
                time,
                format_args!(
                    "{},{},{},{},{},{},{},{},{},{},{}",
                    csv_text(&name),
                    csv_text(label(Some(j.body()))),
                    csv_text(label(j.other())),
                    Num(f.x),
                    Num(f.y),
                    Num(f.z),
                    Num(t.x),
                    Num(t.y),
                    Num(t.z),
                    u8::from(j.is_broken()),
                    Coordinates(world.joint_position(id).ok(), world.joint_velocity(id).ok())
                ),
            )?;
        }
        Ok(())
    }

    /// One row of energies (J) and momenta from `World::diagnostics`.
    pub fn diagnostics(&mut self, time: Real, world: &World) -> Result<(), Failure> {
        let d = world.diagnostics();
        let (p, l) = (d.linear_momentum, d.angular_momentum);
        self.row(
            time,
            format_args!(
                "{},{},{},{},{},{},{},{},{}",
                Num(d.kinetic),
                Num(d.potential),
                Num(d.total),
                Num(p.x),
                Num(p.y),
                Num(p.z),
                Num(l.x),
                Num(l.y),
                Num(l.z)
            ),
        )
    }

    /// Flushes the buffer and puts the file in place; a late write error must not pass
    /// silently.
    pub fn finish(self) -> Result<u64, Failure> {
        self.out.finish()?;
        Ok(self.rows)
    }
}

/// A body label as a CSV field: quoted (RFC 4180) only if it needs to be.
pub fn csv_text(label: &str) -> std::borrow::Cow<'_, str> {
    if label.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", label.replace('"', "\"\"")).into()
    } else {
        label.into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_back_exactly_and_stay_short() {
        for x in [
            0.1,
            -2.5,
            1e-7,
            123_456.75,
            1e20,
            -0.0,
            5.0,
            Real::MIN_POSITIVE,
        ] {
            let text = Num(x).to_string();
            assert_eq!(
                text.parse::<Real>().unwrap().to_bits(),
                x.to_bits(),
                "{text}"
            );
            assert!(text.len() < 26, "{text}");
        }
        assert_eq!(Num(0.5).to_string(), "0.5");
        assert_eq!(Num(1e-7).to_string(), "1e-7");
    }

    #[test]
    fn labels_are_quoted_only_when_needed() {
        assert_eq!(csv_text("ball"), "ball");
        assert_eq!(csv_text("a,b"), "\"a,b\"");
        assert_eq!(csv_text("say \"hi\""), "\"say \"\"hi\"\"\"");
    }
}
