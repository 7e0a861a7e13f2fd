//! Pictures to files: PNG (png crate), animated GIF (gif crate, a palette per frame by
//! NeuQuant), a folder of numbered PNGs, or MP4 through an `ffmpeg` on the PATH.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use tiny_skia::Pixmap;

/// Where and how frames are written, chosen by the output path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Output {
    /// One picture, `.png`: the last frame.
    Png(PathBuf),
    /// An animated `.gif`.
    Gif(PathBuf),
    /// An `.mp4` video (needs ffmpeg).
    Mp4(PathBuf),
    /// A folder (a path without extension, or an existing directory) of
    /// `frame_00000.png`, `frame_00001.png`, ...
    Frames(PathBuf),
}

impl Output {
    /// The kind of output `path` asks for; `Err` names the extensions understood.
    pub fn from_path(path: &Path) -> Result<Output, String> {
        if path.is_dir() {
            return Ok(Output::Frames(path.to_path_buf()));
        }
        let ext = path.extension().map(|e| e.to_string_lossy().to_lowercase());
        match ext.as_deref() {
            Some("png") => Ok(Output::Png(path.to_path_buf())),
            Some("gif") => Ok(Output::Gif(path.to_path_buf())),
            Some("mp4") => Ok(Output::Mp4(path.to_path_buf())),
            None => Ok(Output::Frames(path.to_path_buf())),
            Some(other) => Err(format!(
                "unknown picture format '.{other}' (expected .gif, .png, .mp4, or a folder)"
            )),
        }
    }

    /// The same kind of output, written at `path` instead (a temporary name, say).
    pub fn at(&self, path: &Path) -> Output {
        let path = path.to_path_buf();
        match self {
            Output::Png(_) => Output::Png(path),
            Output::Gif(_) => Output::Gif(path),
            Output::Mp4(_) => Output::Mp4(path),
            Output::Frames(_) => Output::Frames(path),
        }
    }

    /// Whether only the last frame is kept.
    pub fn single_frame(&self) -> bool {
        matches!(self, Output::Png(_))
    }
}

/// A writer of frames, opened for one [`Output`].
pub enum Encoder {
    /// See [`Output::Png`].
    Png(PathBuf),
    /// See [`Output::Gif`].
    Gif(Box<gif::Encoder<BufWriter<File>>>, u16),
    /// See [`Output::Mp4`]: ffmpeg reading raw RGBA on its standard input.
    Mp4(Child),
    /// See [`Output::Frames`], with the count so far.
    Frames(PathBuf, usize),
}

impl Encoder {
    /// Opens `output` for frames of `width` × `height` px shown `fps` a second.
    pub fn create(output: &Output, width: u32, height: u32, fps: f32) -> io::Result<Encoder> {
        Ok(match output {
            Output::Png(p) => Encoder::Png(p.clone()),
            Output::Frames(dir) => {
                std::fs::create_dir_all(dir)?;
                Encoder::Frames(dir.clone(), 0)
            }
            Output::Gif(p) => {
                let file = BufWriter::new(File::create(p)?);
                let mut gif = gif::Encoder::new(file, dim(width)?, dim(height)?, &[])
                    .map_err(io::Error::other)?;
                gif.set_repeat(gif::Repeat::Infinite)
                    .map_err(io::Error::other)?;
                // GIF delays are whole hundredths of a second.
                let delay = (100.0 / fps).round().clamp(2.0, 65535.0) as u16;
                Encoder::Gif(Box::new(gif), delay)
            }
            Output::Mp4(p) => {
                let child = Command::new("ffmpeg")
                    .args([
                        "-loglevel",
                        "error",
                        "-y",
                        "-f",
                        "rawvideo",
                        "-pix_fmt",
                        "rgba",
                    ])
                    .args(["-s", &format!("{width}x{height}"), "-r", &format!("{fps}")])
                    .args(["-i", "-", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2"])
                    .args(["-pix_fmt", "yuv420p", "-movflags", "+faststart"])
                    // Said, not guessed from the name, which may be a temporary one.
                    .args(["-f", "mp4"])
                    .arg(p)
                    .stdin(Stdio::piped())
                    .spawn()
                    .map_err(|e| {
                        io::Error::new(
                            e.kind(),
                            format!("cannot start ffmpeg (.mp4 needs ffmpeg on the PATH): {e}"),
                        )
                    })?;
                Encoder::Mp4(child)
            }
        })
    }

    /// Adds a frame. A PNG keeps only the last one given.
    pub fn frame(&mut self, pixmap: &Pixmap) -> io::Result<()> {
        match self {
            Encoder::Png(p) => write_png(p, pixmap),
            Encoder::Frames(dir, n) => {
                let path = dir.join(frame_name(*n));
                *n += 1;
                write_png(&path, pixmap)
            }
            Encoder::Gif(gif, delay) => {
                let mut rgba = pixmap.data().to_vec();
                let (w, h) = (dim(pixmap.width())?, dim(pixmap.height())?);
                let mut frame = gif::Frame::from_rgba_speed(w, h, &mut rgba, 10);
                frame.delay = *delay;
                gif.write_frame(&frame).map_err(io::Error::other)
            }
            Encoder::Mp4(child) => child
                .stdin
                .as_mut()
                .expect("stdin is piped")
                .write_all(pixmap.data()),
        }
    }

    /// Flushes and closes the output.
    pub fn finish(self) -> io::Result<()> {
        match self {
            Encoder::Gif(gif, _) => gif.into_inner().map_err(io::Error::other)?.flush(),
            Encoder::Mp4(mut child) => {
                drop(child.stdin.take());
                let status = child.wait()?;
                if status.success() {
                    Ok(())
                } else {
                    Err(io::Error::other(format!("ffmpeg failed ({status})")))
                }
            }
            Encoder::Png(_) | Encoder::Frames(..) => Ok(()),
        }
    }
}

/// The file name of frame `k` in a folder of frames: `frame_00000.png`, ...
pub fn frame_name(k: usize) -> String {
    format!("frame_{k:05}.png")
}

fn dim(x: u32) -> io::Result<u16> {
    u16::try_from(x).map_err(|_| io::Error::other("a GIF is at most 65535 px a side"))
}

/// Writes an opaque picture as an 8-bit RGBA PNG. tiny-skia stores premultiplied
/// colour, which equals straight colour where every pixel is opaque, as here.
pub fn write_png(path: &Path, pixmap: &Pixmap) -> io::Result<()> {
    write_png_rgba(path, pixmap.width(), pixmap.height(), pixmap.data())
}

/// Writes `rgba` (width × height × 4 bytes) as a PNG.
pub fn write_png_rgba(path: &Path, width: u32, height: u32, rgba: &[u8]) -> io::Result<()> {
    let file = BufWriter::new(File::create(path)?);
    let mut png = png::Encoder::new(file, width, height);
    png.set_color(png::ColorType::Rgba);
    png.set_depth(png::BitDepth::Eight);
    let mut writer = png.write_header().map_err(io::Error::other)?;
    writer.write_image_data(rgba).map_err(io::Error::other)?;
    writer.finish().map_err(io::Error::other)
}

/// Reads a PNG back as (width, height, RGBA bytes): for tests and tools.
pub fn read_png(path: &Path) -> io::Result<(u32, u32, Vec<u8>)> {
    let mut decoder = png::Decoder::new(io::BufReader::new(File::open(path)?));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::ALPHA);
    let mut reader = decoder.read_info().map_err(io::Error::other)?;
    let mut buf = vec![0; reader.output_buffer_size().unwrap_or(0)];
    let info = reader.next_frame(&mut buf).map_err(io::Error::other)?;
    buf.truncate(info.buffer_size());
    let rgba = match info.color_type {
        png::ColorType::Rgba => buf,
        png::ColorType::Rgb => buf
            .chunks(3)
            .flat_map(|c| [c[0], c[1], c[2], 255])
            .collect(),
        other => {
            return Err(io::Error::other(format!(
                "unexpected PNG colour type {other:?}"
            )))
        }
    };
    Ok((info.width, info.height, rgba))
}
