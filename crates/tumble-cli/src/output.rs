//! Output files, made safe: every path is checked before the run starts, and a file is
//! written under a temporary name beside its target, `NAME.partial`, and renamed into place
//! only when the command has written all of it.
//!
//! So an existing file is never truncated by a command that then fails (a bad second
//! path, a full disk), and a killed run leaves `NAME.partial`, never a half-written NAME.
//! Special files (devices such as /dev/null and /dev/full, fifos, sockets, anything under
//! /dev or /proc) cannot be renamed over: they are written in place, and their write and
//! flush errors are reported like any other. A folder of frames is written into
//! `FOLDER/frames.partial/` and its frames moved into FOLDER at the end.

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use tumble_scene::printable;

use crate::Failure;

/// What is appended to a target's name while it is being written.
pub const PARTIAL: &str = ".partial";

/// One output path named on the command line, checked.
#[derive(Debug, Clone)]
pub struct Target {
    field: &'static str,
    /// The path as given, for messages.
    shown: String,
    /// Where the output ends up: symlinks resolved, so that renaming replaces the file a
    /// link points to rather than the link. A special file keeps the path as given:
    /// /dev/stdout must be opened as itself, not as the file it resolves to.
    path: PathBuf,
    /// The resolved path, which tells whether two paths name one file.
    real: PathBuf,
    /// A special file, written in place.
    direct: bool,
    /// Device and inode of an existing file, which tell hard links apart from strangers.
    id: Option<(u64, u64)>,
}

impl Target {
    /// An output file for the option `field`: its folder must exist, and it must not be a
    /// folder itself.
    pub fn file(field: &'static str, path: &Path) -> Result<Target, Failure> {
        let shown = printable(&path.display().to_string());
        let refuse =
            |why: String| Failure::Input(format!("{field}: cannot create '{shown}': {why}"));
        match fs::metadata(path) {
            Ok(m) if m.is_dir() => Err(Failure::Input(format!(
                "{field}: '{shown}' is a folder; name a file"
            ))),
            Ok(m) => {
                let direct = !m.is_file() || under_dev(path);
                // /dev/stdout on a pipe resolves to `pipe:[N]`, which is no path.
                let real = match fs::canonicalize(path) {
                    Err(_) if direct => path.to_path_buf(),
                    real => real.map_err(|e| refuse(e.to_string()))?,
                };
                Ok(Target {
                    field,
                    path: if direct {
                        path.to_path_buf()
                    } else {
                        real.clone()
                    },
                    real,
                    direct,
                    id: file_id(&m),
                    shown,
                })
            }
            Err(_) if path.as_os_str().to_string_lossy().ends_with('/') => {
                Err(refuse("a file name cannot end with '/'".into()))
            }
            Err(_) => {
                let real = in_folder(path).map_err(refuse)?;
                Ok(Target {
                    field,
                    path: real.clone(),
                    real,
                    direct: under_dev(path),
                    id: None,
                    shown,
                })
            }
        }
    }

    /// A folder output (render's frames): the folder may exist; if not, its parent must.
    pub fn folder(field: &'static str, path: &Path) -> Result<Target, Failure> {
        let shown = printable(&path.display().to_string());
        let refuse =
            |why: String| Failure::Input(format!("{field}: cannot create '{shown}': {why}"));
        let resolved = match fs::metadata(path) {
            Ok(m) if m.is_dir() => fs::canonicalize(path).map_err(|e| refuse(e.to_string()))?,
            Ok(_) => {
                return Err(Failure::Input(format!(
                    "{field}: '{shown}' is not a folder (frames go into a folder; name a \
                     .gif, .png or .mp4 file for one file)"
                )))
            }
            Err(_) => in_folder(path).map_err(refuse)?,
        };
        Ok(Target {
            field,
            shown,
            path: resolved.clone(),
            real: resolved,
            direct: false,
            id: None,
        })
    }

    /// The path as given, printable.
    pub fn shown(&self) -> &str {
        &self.shown
    }

    /// Where the output is written until it is complete.
    fn partial(&self) -> PathBuf {
        if self.direct {
            return self.path.clone();
        }
        let mut name = self.path.as_os_str().to_owned();
        name.push(PARTIAL);
        PathBuf::from(name)
    }

    /// The one-line failure of writing this output.
    pub fn write_error(&self, e: impl std::fmt::Display) -> Failure {
        Failure::Input(format!(
            "{}: cannot write '{}': {e}",
            self.field, self.shown
        ))
    }

    /// Whether `self` and `other` are the same file (or `self` would be written over it).
    fn same(&self, other: &Path, other_id: Option<(u64, u64)>) -> bool {
        self.real == other || self.partial() == other || (self.id.is_some() && self.id == other_id)
    }
}

/// Refuses outputs that are one file twice, or the file an input is read from (a scene
/// run into itself would be lost). Inputs are `(what, path)`, e.g. `("scene", ...)`.
/// The null device may be named by several outputs: nothing written to it is kept.
pub fn check_distinct(targets: &[&Target], inputs: &[(&str, &Path)]) -> Result<(), Failure> {
    for (i, t) in targets.iter().enumerate() {
        for (what, input) in inputs {
            let (real, id) = match fs::canonicalize(input) {
                Ok(real) => (real, fs::metadata(input).ok().and_then(|m| file_id(&m))),
                Err(_) => continue,
            };
            if t.same(&real, id) {
                return Err(Failure::Input(format!(
                    "{}: '{}' is the {what} being read; name another file",
                    t.field, t.shown
                )));
            }
        }
        let null = t.real == Path::new("/dev/null");
        let clash = |b: &&&Target| t.same(&b.real, b.id) || b.same(&t.real, t.id);
        if let Some(before) = targets[..i].iter().find(clash).filter(|_| !null) {
            return Err(Failure::Input(format!(
                "{}: '{}' is also --{}; name a different file",
                t.field, t.shown, before.field
            )));
        }
    }
    Ok(())
}

/// An output being written: under its partial name until [`Staged::commit`], and removed
/// if dropped before (the command failed, or an error cut it short).
#[derive(Debug)]
pub struct Staged {
    target: Target,
    write_to: PathBuf,
    committed: bool,
}

impl Staged {
    /// Creates the file that will be written (the partial one, or the special file
    /// itself), so that a path that cannot be written is refused before the run.
    pub fn create(target: Target) -> Result<(Staged, File), Failure> {
        let write_to = target.partial();
        let file = if target.direct {
            // A device or fifo is opened as it is: it cannot be created or truncated.
            OpenOptions::new().write(true).open(&write_to)
        } else {
            File::create(&write_to)
        };
        let staged = Staged {
            committed: target.direct,
            target,
            write_to,
        };
        let file = file.map_err(|e| {
            Failure::Input(format!(
                "{}: cannot create '{}': {e}",
                staged.target.field, staged.target.shown
            ))
        })?;
        Ok((staged, file))
    }

    /// Where to write.
    pub fn path(&self) -> &Path {
        &self.write_to
    }

    /// The output's target.
    pub fn target(&self) -> &Target {
        &self.target
    }

    /// Puts the complete file in place: to disk first, so that a crash after the rename
    /// cannot leave an empty file under the target's name.
    pub fn commit(mut self) -> Result<(), Failure> {
        if self.target.direct {
            return Ok(());
        }
        File::open(&self.write_to)
            .and_then(|f| f.sync_all())
            .and_then(|()| fs::rename(&self.write_to, &self.target.path))
            .map_err(|e| self.target.write_error(e))?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            // The target was never touched; the incomplete copy goes.
            let _ = fs::remove_file(&self.write_to);
        }
    }
}

/// A text output written through a buffer, with every write error named.
pub struct Writer {
    staged: Staged,
    out: BufWriter<File>,
}

impl Writer {
    /// Opens `target` (see [`Staged::create`]).
    pub fn create(target: Target) -> Result<Writer, Failure> {
        let (staged, file) = Staged::create(target)?;
        Ok(Writer {
            staged,
            out: BufWriter::new(file),
        })
    }

    /// The output's target.
    pub fn target(&self) -> &Target {
        self.staged.target()
    }

    /// Writes formatted text.
    pub fn write(&mut self, args: std::fmt::Arguments<'_>) -> Result<(), Failure> {
        self.out
            .write_fmt(args)
            .map_err(|e| self.staged.target.write_error(e))
    }

    /// Writes what is buffered. Special files are flushed early (after a header), so that
    /// /dev/full is refused before the run rather than after it.
    pub fn flush_if_direct(&mut self) -> Result<(), Failure> {
        if self.staged.target.direct {
            self.out
                .flush()
                .map_err(|e| self.staged.target.write_error(e))?;
        }
        Ok(())
    }

    /// Flushes and puts the file in place; a late write error must not pass silently.
    pub fn finish(self) -> Result<(), Failure> {
        let Writer { staged, out } = self;
        out.into_inner()
            .map_err(|e| staged.target.write_error(e.error()))?;
        staged.commit()
    }
}

/// A folder of frames written into `FOLDER/frames.partial/` and moved into FOLDER at the
/// end, so that an existing folder's frames are replaced only by a complete set.
#[derive(Debug)]
pub struct StagedFolder {
    target: Target,
    staging: PathBuf,
    /// The folder did not exist before: it goes again if nothing is committed.
    created: bool,
    committed: bool,
}

impl StagedFolder {
    /// Creates the folder if need be, and its staging folder.
    pub fn create(target: Target) -> Result<StagedFolder, Failure> {
        let created = !target.path.is_dir();
        let staging = target.path.join(format!("frames{PARTIAL}"));
        // A killed run's leftovers: the folder is this command's own, by its name.
        let _ = fs::remove_dir_all(&staging);
        let folder = StagedFolder {
            staging,
            created,
            committed: false,
            target,
        };
        fs::create_dir_all(&folder.staging).map_err(|e| {
            Failure::Input(format!(
                "{}: cannot create '{}': {e}",
                folder.target.field, folder.target.shown
            ))
        })?;
        Ok(folder)
    }

    /// Where the frames are written.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// The output's target.
    pub fn target(&self) -> &Target {
        &self.target
    }

    /// Moves the files `names` from the staging folder into the folder, and removes the
    /// staging folder.
    pub fn commit(mut self, names: impl Iterator<Item = String>) -> Result<(), Failure> {
        for name in names {
            fs::rename(self.staging.join(&name), self.target.path.join(&name))
                .map_err(|e| self.target.write_error(e))?;
        }
        let _ = fs::remove_dir(&self.staging);
        self.committed = true;
        Ok(())
    }
}

impl Drop for StagedFolder {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_dir_all(&self.staging);
            if self.created {
                let _ = fs::remove_dir(&self.target.path);
            }
        }
    }
}

/// The file a scene named on the command line is read from: none for a built-in.
pub fn scene_file(name: &str) -> Option<PathBuf> {
    let path = Path::new(name);
    (tumble_scene::builtin(name).is_none() && path.exists()).then(|| path.to_path_buf())
}

/// The scene file as the inputs of [`check_distinct`].
pub fn inputs(scene_file: &Option<PathBuf>) -> Vec<(&'static str, &Path)> {
    scene_file.iter().map(|p| ("scene", p.as_path())).collect()
}

/// A file path that does not exist yet, resolved through its folder, which must exist.
fn in_folder(path: &Path) -> Result<PathBuf, String> {
    let name = path
        .file_name()
        .ok_or_else(|| "not a file name".to_string())?;
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let shown = printable(&parent.display().to_string());
    match fs::metadata(parent) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => return Err(format!("'{shown}' is not a folder")),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Err(format!("the folder '{shown}' does not exist"))
        }
        Err(e) => return Err(e.to_string()),
    }
    let parent = fs::canonicalize(parent).map_err(|e| e.to_string())?;
    Ok(parent.join(name))
}

/// Device files live under /dev (and /proc/self/fd); /dev/stdout may resolve to a regular
/// file when standard output is redirected, and must still be written in place.
fn under_dev(path: &Path) -> bool {
    path.starts_with("/dev") || path.starts_with("/proc")
}

#[cfg(unix)]
fn file_id(m: &fs::Metadata) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    Some((m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn file_id(_: &fs::Metadata) -> Option<(u64, u64)> {
    None
}
