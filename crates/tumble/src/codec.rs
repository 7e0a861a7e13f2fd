//! A small binary writer and reader for world snapshots (see `pipeline/world/snapshot.rs`).
//!
//! Every value is written little-endian, floats by their bits (`to_le_bytes`), so a value
//! reads back bit-exact. A type that can be written implements [`Code`]; plain structs do
//! it with [`codec_struct!`] in their own module (which sees their private fields), naming
//! the fields that are saved and those that are step scratch, rebuilt as `Default`. The
//! macro builds the struct with a literal, so a field added later and not named in either
//! list is a compile error, never a silent omission.
//!
//! The reader never panics and never allocates more than the bytes left could describe:
//! a length is checked against the remaining bytes before anything is reserved.

use crate::math::{Mat3, Quat, Real, Vec3, Vec4};

/// What is wrong with a snapshot's bytes, and where (it becomes `Error::Snapshot`; a type
/// of its own so that this module, which the handles and limits use, imports no errors).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Malformed(pub String);

/// The result of reading a value.
pub(crate) type Decoded<T> = std::result::Result<T, Malformed>;

/// Bytes being written.
#[derive(Default)]
pub(crate) struct Writer {
    pub bytes: Vec<u8>,
}

impl Writer {
    pub fn raw(&mut self, bytes: &[u8]) {
        self.bytes.extend_from_slice(bytes);
    }

    pub fn len(&mut self, len: usize) {
        self.raw(&(len as u64).to_le_bytes());
    }
}

/// Bytes being read, with the position for error messages.
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Where `bytes` starts in the whole snapshot, for error messages.
    base: usize,
}

impl<'a> Reader<'a> {
    pub fn new(bytes: &'a [u8], base: usize) -> Reader<'a> {
        Reader {
            bytes,
            pos: 0,
            base,
        }
    }

    /// The byte offset in the whole snapshot of the next byte.
    pub fn offset(&self) -> usize {
        self.base + self.pos
    }

    pub fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    pub fn take<const N: usize>(&mut self) -> Decoded<[u8; N]> {
        let end = self.pos + N;
        let Some(slice) = self.bytes.get(self.pos..end) else {
            return Err(Malformed(format!(
                "truncated at byte {}",
                self.base + self.bytes.len()
            )));
        };
        let mut out = [0u8; N];
        out.copy_from_slice(slice);
        self.pos = end;
        Ok(out)
    }

    /// A length of a sequence whose items take at least one byte each: refused if the
    /// bytes left cannot hold that many, before anything is allocated.
    pub fn len(&mut self) -> Decoded<usize> {
        let at = self.offset();
        let n = u64::from_le_bytes(self.take()?);
        if n > self.remaining() as u64 {
            return Err(Malformed(format!(
                "length {n} at byte {at} is more than the {} bytes left",
                self.remaining()
            )));
        }
        Ok(n as usize)
    }

    /// An error for a bad tag of `what` read just before the current position.
    pub fn bad_tag(&self, what: &str, tag: u8) -> Malformed {
        Malformed(format!(
            "{what}: unknown tag {tag} at byte {}",
            self.offset() - 1
        ))
    }
}

/// Refuses a decoded snapshot unless `index < len`: an index the bytes hold is checked
/// against what it indexes before anything is trusted with it. The message names the
/// field (built only on failure) and both numbers: `contacts[3].index_b: body 17 of 5`.
#[inline]
pub(crate) fn check_index(
    index: impl Into<u64>,
    len: usize,
    (field, noun): (impl FnOnce() -> String, &str),
) -> Decoded<()> {
    let index = index.into();
    if index < len as u64 {
        Ok(())
    } else {
        Err(out_of_range(field(), noun, index, len))
    }
}

/// `check_index`'s error, out of line: checks run per node and pair of a large world.
#[cold]
#[inline(never)]
fn out_of_range(field: String, noun: &str, index: u64, len: usize) -> Malformed {
    Malformed(format!("{field}: {noun} {index} of {len}"))
}

/// Refuses a decoded snapshot unless `ok`, saying `what` is wrong (built only on failure).
#[inline]
pub(crate) fn ensure(ok: bool, what: impl FnOnce() -> String) -> Decoded<()> {
    if ok {
        Ok(())
    } else {
        Err(Malformed(what()))
    }
}

/// A value that can be written to and read from a snapshot.
pub(crate) trait Code: Sized {
    fn put(&self, w: &mut Writer);
    fn get(r: &mut Reader<'_>) -> Decoded<Self>;
}

macro_rules! codec_int {
    ($($t:ty),*) => {$(
        impl Code for $t {
            fn put(&self, w: &mut Writer) {
                w.raw(&self.to_le_bytes());
            }
            fn get(r: &mut Reader<'_>) -> Decoded<Self> {
                Ok(<$t>::from_le_bytes(r.take()?))
            }
        }
    )*};
}

codec_int!(u8, u32, u64, Real);

impl Code for usize {
    fn put(&self, w: &mut Writer) {
        (*self as u64).put(w);
    }
    fn get(r: &mut Reader<'_>) -> Decoded<Self> {
        let at = r.offset();
        usize::try_from(u64::get(r)?)
            .map_err(|_| Malformed(format!("count too large at byte {at}")))
    }
}

impl Code for bool {
    fn put(&self, w: &mut Writer) {
        w.raw(&[*self as u8]);
    }
    fn get(r: &mut Reader<'_>) -> Decoded<Self> {
        match u8::get(r)? {
            0 => Ok(false),
            1 => Ok(true),
            t => Err(r.bad_tag("bool", t)),
        }
    }
}

impl<T: Code> Code for Option<T> {
    fn put(&self, w: &mut Writer) {
        match self {
            None => w.raw(&[0]),
            Some(x) => {
                w.raw(&[1]);
                x.put(w);
            }
        }
    }
    fn get(r: &mut Reader<'_>) -> Decoded<Self> {
        match u8::get(r)? {
            0 => Ok(None),
            1 => Ok(Some(T::get(r)?)),
            t => Err(r.bad_tag("option", t)),
        }
    }
}

impl<T: Code> Code for Vec<T> {
    fn put(&self, w: &mut Writer) {
        w.len(self.len());
        for x in self {
            x.put(w);
        }
    }
    fn get(r: &mut Reader<'_>) -> Decoded<Self> {
        let n = r.len()?;
        // At most as many bytes reserved as are left to read: a count that lies is found
        // out by running out of bytes, not by an allocation of gigabytes.
        let fit = r.remaining() / std::mem::size_of::<T>().max(1);
        let mut out = Vec::with_capacity(n.min(fit + 16));
        for _ in 0..n {
            out.push(T::get(r)?);
        }
        Ok(out)
    }
}

impl<T: Code + Default, const N: usize> Code for [T; N] {
    fn put(&self, w: &mut Writer) {
        for x in self {
            x.put(w);
        }
    }
    fn get(r: &mut Reader<'_>) -> Decoded<Self> {
        let mut out: [T; N] = std::array::from_fn(|_| T::default());
        for x in out.iter_mut() {
            *x = T::get(r)?;
        }
        Ok(out)
    }
}

impl<A: Code, B: Code> Code for (A, B) {
    fn put(&self, w: &mut Writer) {
        self.0.put(w);
        self.1.put(w);
    }
    fn get(r: &mut Reader<'_>) -> Decoded<Self> {
        Ok((A::get(r)?, B::get(r)?))
    }
}

impl<A: Code, B: Code, C: Code, D: Code> Code for (A, B, C, D) {
    fn put(&self, w: &mut Writer) {
        self.0.put(w);
        self.1.put(w);
        self.2.put(w);
        self.3.put(w);
    }
    fn get(r: &mut Reader<'_>) -> Decoded<Self> {
        Ok((A::get(r)?, B::get(r)?, C::get(r)?, D::get(r)?))
    }
}

impl Code for String {
    fn put(&self, w: &mut Writer) {
        w.len(self.len());
        w.raw(self.as_bytes());
    }
    fn get(r: &mut Reader<'_>) -> Decoded<Self> {
        let at = r.offset();
        let bytes: Vec<u8> = {
            let n = r.len()?;
            let mut v = Vec::with_capacity(n);
            for _ in 0..n {
                v.push(u8::get(r)?);
            }
            v
        };
        String::from_utf8(bytes).map_err(|_| Malformed(format!("string at byte {at} is not UTF-8")))
    }
}

macro_rules! codec_array_like {
    ($($t:ty: $n:expr, $to:ident, $from:ident);*) => {$(
        impl Code for $t {
            fn put(&self, w: &mut Writer) {
                for x in self.$to() {
                    x.put(w);
                }
            }
            fn get(r: &mut Reader<'_>) -> Decoded<Self> {
                Ok(<$t>::$from(&<[Real; $n]>::get(r)?))
            }
        }
    )*};
}

codec_array_like!(
    Vec3: 3, to_array, from_slice;
    Vec4: 4, to_array, from_slice;
    Quat: 4, to_array, from_slice;
    Mat3: 9, to_cols_array, from_cols_slice
);

/// Implements [`Code`] for a struct: `Type { saved, fields; scratch, fields }`, the saved
/// fields in order, then (after `;`) the fields rebuilt as `Default` (step scratch).
macro_rules! codec_struct {
    ($ty:ident { $($f:ident),* $(,)? $(; $($s:ident),* $(,)?)? }) => {
        impl $crate::codec::Code for $ty {
            fn put(&self, w: &mut $crate::codec::Writer) {
                $( $crate::codec::Code::put(&self.$f, w); )*
            }
            fn get(r: &mut $crate::codec::Reader<'_>) -> $crate::codec::Decoded<Self> {
                Ok($ty {
                    $( $f: $crate::codec::Code::get(r)?, )*
                    $($( $s: Default::default(), )*)?
                })
            }
        }
    };
}

/// Implements [`Code`] for an enum of unit variants, as a one-byte tag in the listed order.
macro_rules! codec_unit_enum {
    ($ty:ident { $($v:ident),* $(,)? }) => {
        impl $crate::codec::Code for $ty {
            fn put(&self, w: &mut $crate::codec::Writer) {
                let all = [$($ty::$v),*];
                let tag = all.iter().position(|v| v == self).unwrap_or(0) as u8;
                $crate::codec::Code::put(&tag, w);
            }
            fn get(r: &mut $crate::codec::Reader<'_>) -> $crate::codec::Decoded<Self> {
                let all = [$($ty::$v),*];
                let tag: u8 = $crate::codec::Code::get(r)?;
                all.get(tag as usize).copied().ok_or_else(|| r.bad_tag(stringify!($ty), tag))
            }
        }
    };
}

pub(crate) use {codec_struct, codec_unit_enum};

// Here rather than in id.rs, which error.rs imports: the handles' fields are public.
use crate::id::{BodyId, ForceId, JointId};
codec_struct!(BodyId { index, generation });
codec_struct!(JointId { index, generation });
codec_struct!(ForceId { index, generation });

/// A 64-bit checksum of `bytes` (FNV-1a over 8-byte words, then the tail bytes): fast
/// enough for megabytes per frame, and any changed byte changes it with overwhelming odds.
pub(crate) fn checksum(bytes: &[u8]) -> u64 {
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut chunks = bytes.chunks_exact(8);
    for c in &mut chunks {
        let mut word = [0u8; 8];
        word.copy_from_slice(c);
        h = (h ^ u64::from_le_bytes(word)).wrapping_mul(PRIME);
        h ^= h >> 29;
    }
    for &b in chunks.remainder() {
        h = (h ^ b as u64).wrapping_mul(PRIME);
    }
    h ^ bytes.len() as u64
}
