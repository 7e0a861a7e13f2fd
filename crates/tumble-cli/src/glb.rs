//! glTF 2.0's two containers, written by hand with serde_json: the binary `.glb` (a
//! 12-byte header, a JSON chunk, a BIN chunk) and the text `.gltf` with its one buffer
//! embedded as a base64 data URI. No glTF crate: the writer needs only the few rules below.
//!
//! Rules of the specification (glTF 2.0, sections 3.6 and 4.4) this file keeps:
//! - every chunk is 4-byte aligned: the JSON chunk is padded with spaces (0x20), the BIN
//!   chunk with zeros; the header's `length` is the whole file's, in a u32;
//! - the buffer of a GLB has no `uri`, and its `byteLength` is the BIN data's length
//!   before padding (at most 3 bytes less than the chunk);
//! - every buffer view starts at a multiple of 4 (all data here is f32 or u32, so it
//!   does), and an accessor's `count` × its element size fills its view exactly;
//! - accessors of vertex positions and of animation inputs carry `min` and `max` (this
//!   writer gives every accessor its bounds), computed from the f32 values written.

use serde_json::{json, Value};

/// `glTF` as a little-endian u32: the first word of every GLB.
const MAGIC: u32 = 0x4654_6C67;
/// The container version (glTF 2.0).
const VERSION: u32 = 2;
/// Chunk types: `JSON` and `BIN\0` as little-endian u32.
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;
/// `bufferView.target` of vertex attributes (ARRAY_BUFFER).
pub const ARRAY_BUFFER: u32 = 34962;
/// `bufferView.target` of vertex indices (ELEMENT_ARRAY_BUFFER).
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
/// `accessor.componentType` FLOAT and UNSIGNED_INT.
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;

/// The binary data of a document being built, with the buffer views and accessors that
/// describe it.
#[derive(Debug, Default)]
pub struct Buffer {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Buffer {
    /// Appends `data`, f32 elements of `kind` ("SCALAR", "VEC3", "VEC4"), as its own
    /// buffer view (with `target` when given) and an accessor with `min` and `max`;
    /// returns the accessor's index. `data` must hold at least one whole element.
    pub fn floats(&mut self, data: &[f32], kind: &str, target: Option<u32>) -> usize {
        let n = match kind {
            "SCALAR" => 1,
            "VEC3" => 3,
            _ => 4,
        };
        debug_assert!(
            !data.is_empty() && data.len() % n == 0,
            "{kind}: {}",
            data.len()
        );
        let mut min = vec![f32::INFINITY; n];
        let mut max = vec![f32::NEG_INFINITY; n];
        for element in data.chunks_exact(n) {
            for (i, x) in element.iter().enumerate() {
                min[i] = min[i].min(*x);
                max[i] = max[i].max(*x);
            }
        }
        let bytes = data.iter().flat_map(|x| x.to_le_bytes());
        let accessor = json!({
            "componentType": FLOAT,
            "count": data.len() / n,
            "type": kind,
            "min": min,
            "max": max,
        });
        self.push(bytes, target, accessor)
    }

    /// Appends vertex indices (u32, three per triangle) as their own buffer view and an
    /// accessor; returns the accessor's index. `data` must not be empty.
    pub fn indices(&mut self, data: &[u32]) -> usize {
        let (min, max) = (data.iter().min(), data.iter().max());
        let accessor = json!({
            "componentType": UNSIGNED_INT,
            "count": data.len(),
            "type": "SCALAR",
            "min": [min],
            "max": [max],
        });
        let bytes = data.iter().flat_map(|i| i.to_le_bytes());
        self.push(bytes, Some(ELEMENT_ARRAY_BUFFER), accessor)
    }

    /// `bytes` as a new buffer view, described by `accessor` (all but its view).
    fn push(
        &mut self,
        bytes: impl Iterator<Item = u8>,
        target: Option<u32>,
        mut accessor: Value,
    ) -> usize {
        // Every element here is 4 bytes, so every view starts 4-byte aligned.
        let offset = self.bytes.len();
        self.bytes.extend(bytes);
        let mut view = json!({
            "buffer": 0,
            "byteOffset": offset,
            "byteLength": self.bytes.len() - offset,
        });
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        self.views.push(view);
        accessor["bufferView"] = json!(self.views.len() - 1);
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Bytes of binary data so far.
    pub fn len(&self) -> usize {
        self.bytes.len()
    }

    /// Puts the views and accessors into `doc` (and the buffer's entry, whose `uri` is
    /// `uri` when given), and returns the binary data.
    fn finish(self, doc: &mut Value, uri: Option<String>) -> Vec<u8> {
        if self.bytes.is_empty() {
            // glTF wants at least one element in every array it has: none at all then.
            return self.bytes;
        }
        let mut buffer = json!({"byteLength": self.bytes.len()});
        if let Some(uri) = uri {
            buffer["uri"] = json!(uri);
        }
        doc["accessors"] = Value::Array(self.accessors);
        doc["bufferViews"] = Value::Array(self.views);
        doc["buffers"] = json!([buffer]);
        self.bytes
    }
}

/// The whole `.glb` file of `doc` and its binary data; `Err` says why it cannot be one
/// (a GLB's length is a u32).
pub fn glb(mut doc: Value, buffer: Buffer) -> Result<Vec<u8>, String> {
    let bin = buffer.finish(&mut doc, None);
    let mut json = doc.to_string().into_bytes();
    pad(&mut json, b' ');
    let mut bin_padded = bin;
    pad(&mut bin_padded, 0);
    let chunks = 8
        + json.len()
        + if bin_padded.is_empty() {
            0
        } else {
            8 + bin_padded.len()
        };
    let total = 12 + chunks;
    let too_large = || format!("{total} bytes; a .glb holds at most {} bytes", u32::MAX);
    let total32 = u32::try_from(total).map_err(|_| too_large())?;
    let len32 = |n: usize| u32::try_from(n).map_err(|_| too_large());
    let mut out = Vec::with_capacity(total);
    for word in [MAGIC, VERSION, total32, len32(json.len())?, CHUNK_JSON] {
        out.extend(word.to_le_bytes());
    }
    out.extend(json);
    if !bin_padded.is_empty() {
        out.extend(len32(bin_padded.len())?.to_le_bytes());
        out.extend(CHUNK_BIN.to_le_bytes());
        out.extend(bin_padded);
    }
    Ok(out)
}

/// The whole `.gltf` file of `doc`: JSON with the binary data as a base64 data URI.
pub fn gltf(mut doc: Value, buffer: Buffer) -> Vec<u8> {
    let uri = (buffer.len() > 0).then(|| {
        // The bytes are needed before `finish` consumes the buffer.
        format!(
            "data:application/octet-stream;base64,{}",
            base64(&buffer.bytes)
        )
    });
    buffer.finish(&mut doc, uri);
    let mut text = doc.to_string();
    text.push('\n');
    text.into_bytes()
}

/// Pads `bytes` with `fill` to a multiple of 4.
fn pad(bytes: &mut Vec<u8>, fill: u8) {
    while bytes.len() % 4 != 0 {
        bytes.push(fill);
    }
}

/// Standard base64 (RFC 4648, with `=` padding), as data URIs use it.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for group in bytes.chunks(3) {
        let b = [
            group[0],
            *group.get(1).unwrap_or(&0),
            *group.get(2).unwrap_or(&0),
        ];
        let word = u32::from(b[0]) << 16 | u32::from(b[1]) << 8 | u32::from(b[2]);
        for i in 0..4 {
            if i <= group.len() {
                out.push(ALPHABET[(word >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        // RFC 4648, section 10.
        let cases = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (plain, coded) in cases {
            assert_eq!(base64(plain.as_bytes()), coded, "{plain:?}");
        }
    }

    #[test]
    fn a_glb_is_aligned_and_its_lengths_add_up() {
        let mut buffer = Buffer::default();
        let a = buffer.floats(
            &[1.0, -2.0, 3.0, 0.5, 4.0, -6.0],
            "VEC3",
            Some(ARRAY_BUFFER),
        );
        let doc = json!({"asset": {"version": "2.0"}, "x": "odd length"});
        let bytes = glb(doc, buffer).unwrap();
        let word = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap()) as usize;
        assert_eq!(word(0), MAGIC as usize);
        assert_eq!(word(8), bytes.len());
        let json_len = word(12);
        assert_eq!(json_len % 4, 0);
        let json: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
        let bin_at = 20 + json_len;
        assert_eq!(word(bin_at), 24);
        assert_eq!(word(bin_at + 4), CHUNK_BIN as usize);
        assert_eq!(bin_at + 8 + 24, bytes.len());
        assert_eq!(json["buffers"][0]["byteLength"], 24);
        assert_eq!(json["accessors"][a]["count"], 2);
        assert_eq!(json["accessors"][a]["min"], json!([0.5, -2.0, -6.0]));
        assert_eq!(json["accessors"][a]["max"], json!([1.0, 4.0, 3.0]));
    }
}
