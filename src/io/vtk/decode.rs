//! Decoding VTK data arrays: the numeric types, ascii text, base64, and the binary block
//! layout (a header of UInt32 or UInt64 words, then the data, raw or in compressed blocks:
//! zlib, lz4 or lzma), in either byte order.
//!
//! Every size a file declares is checked against the bytes present before anything of that
//! size is allocated, and every decompression is capped by the declared sizes: a 1 kB file
//! that declares a gigabyte is refused after at most a few kilobytes of allocation.

use crate::error::{Error, Result};
use std::io::Read;

/// A numeric element type of a VTK array: arrays are read as f64 and written back in the
/// type they came in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scalar {
    /// `Int8`
    I8,
    /// `UInt8`
    U8,
    /// `Int16`
    I16,
    /// `UInt16`
    U16,
    /// `Int32`
    I32,
    /// `UInt32`
    U32,
    /// `Int64`
    I64,
    /// `UInt64`
    U64,
    /// `Float32`
    F32,
    /// `Float64`
    F64,
}

impl Scalar {
    /// The XML name VTK writes (`Float64`, `Int32`, ...).
    pub fn xml_name(self) -> &'static str {
        match self {
            Scalar::I8 => "Int8",
            Scalar::U8 => "UInt8",
            Scalar::I16 => "Int16",
            Scalar::U16 => "UInt16",
            Scalar::I32 => "Int32",
            Scalar::U32 => "UInt32",
            Scalar::I64 => "Int64",
            Scalar::U64 => "UInt64",
            Scalar::F32 => "Float32",
            Scalar::F64 => "Float64",
        }
    }

    /// The legacy format's name as VTK's legacy writer gives it (`double`, `int`,
    /// `vtktypeint64`, ...): the names its reader takes for attributes and field arrays.
    pub fn legacy_name(self) -> &'static str {
        match self {
            Scalar::I8 => "signed_char",
            Scalar::U8 => "unsigned_char",
            Scalar::I16 => "short",
            Scalar::U16 => "unsigned_short",
            Scalar::I32 => "int",
            Scalar::U32 => "unsigned_int",
            Scalar::I64 => "vtktypeint64",
            Scalar::U64 => "vtktypeuint64",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    /// Appends `values` (read from an array of this type, so each is exact in it) as bytes,
    /// little-endian or big-endian.
    pub fn encode(self, values: &[f64], big_endian: bool, out: &mut Vec<u8>) {
        macro_rules! put {
            ($t:ty) => {
                for &v in values {
                    let x = v as $t;
                    out.extend_from_slice(&if big_endian { x.to_be_bytes() } else { x.to_le_bytes() });
                }
            };
        }
        match self {
            Scalar::I8 => put!(i8),
            Scalar::U8 => put!(u8),
            Scalar::I16 => put!(i16),
            Scalar::U16 => put!(u16),
            Scalar::I32 => put!(i32),
            Scalar::U32 => put!(u32),
            Scalar::I64 => put!(i64),
            Scalar::U64 => put!(u64),
            Scalar::F32 => put!(f32),
            Scalar::F64 => put!(f64),
        }
    }

    /// The type from its XML name (`Float64`, and the old names `Double`, `Int`, ... that
    /// early VTK versions wrote).
    pub(crate) fn from_xml(s: &str) -> Option<Scalar> {
        Some(match s {
            "Int8" | "Char" | "SignedChar" => Scalar::I8,
            "UInt8" | "UnsignedChar" => Scalar::U8,
            "Int16" | "Short" => Scalar::I16,
            "UInt16" | "UnsignedShort" => Scalar::U16,
            "Int32" | "Int" => Scalar::I32,
            "UInt32" | "UnsignedInt" => Scalar::U32,
            "Int64" | "Long" | "LongLong" | "IdType" => Scalar::I64,
            "UInt64" | "UnsignedLong" | "UnsignedLongLong" => Scalar::U64,
            "Float32" | "Float" => Scalar::F32,
            "Float64" | "Double" => Scalar::F64,
            _ => return None,
        })
    }

    /// The type from its legacy name (`double`, `vtktypeint64`, ...), as VTK's legacy reader
    /// sizes them in binary files (`long` is 8 bytes on the 64-bit Unix systems VTK writes
    /// from; `vtkIdType` 4 bytes, as the legacy writer stores ids).
    pub(crate) fn from_legacy(s: &str) -> Option<Scalar> {
        Some(match s.to_ascii_lowercase().as_str() {
            "char" | "signed_char" | "vtktypeint8" => Scalar::I8,
            "unsigned_char" | "vtktypeuint8" => Scalar::U8,
            "short" | "vtktypeint16" => Scalar::I16,
            "unsigned_short" | "vtktypeuint16" => Scalar::U16,
            "int" | "vtkidtype" | "vtktypeint32" => Scalar::I32,
            "unsigned_int" | "vtktypeuint32" => Scalar::U32,
            "long" | "long_long" | "__int64" | "vtktypeint64" => Scalar::I64,
            "unsigned_long" | "unsigned_long_long" | "unsigned___int64" | "vtktypeuint64" => Scalar::U64,
            "float" | "vtktypefloat32" => Scalar::F32,
            "double" | "vtktypefloat64" => Scalar::F64,
            _ => return None,
        })
    }

    /// Bytes per element.
    pub(crate) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }

    fn is_signed(self) -> bool {
        matches!(self, Scalar::I8 | Scalar::I16 | Scalar::I32 | Scalar::I64)
    }

    /// Converts raw bytes (a whole number of elements) to numbers.
    pub(crate) fn decode(self, bytes: &[u8], big_endian: bool) -> Numbers {
        macro_rules! conv {
            ($t:ty, $n:expr, $as:ty) => {
                bytes
                    .chunks_exact($n)
                    .map(|c| {
                        let mut a = [0u8; $n];
                        a.copy_from_slice(c);
                        (if big_endian { <$t>::from_be_bytes(a) } else { <$t>::from_le_bytes(a) }) as $as
                    })
                    .collect()
            };
        }
        match self {
            Scalar::I8 => Numbers::Int(bytes.iter().map(|&b| i64::from(b as i8)).collect()),
            Scalar::U8 => Numbers::UInt(bytes.iter().map(|&b| u64::from(b)).collect()),
            Scalar::I16 => Numbers::Int(conv!(i16, 2, i64)),
            Scalar::U16 => Numbers::UInt(conv!(u16, 2, u64)),
            Scalar::I32 => Numbers::Int(conv!(i32, 4, i64)),
            Scalar::U32 => Numbers::UInt(conv!(u32, 4, u64)),
            Scalar::I64 => Numbers::Int(conv!(i64, 8, i64)),
            Scalar::U64 => Numbers::UInt(conv!(u64, 8, u64)),
            Scalar::F32 => Numbers::Float(conv!(f32, 4, f64)),
            Scalar::F64 => Numbers::Float(conv!(f64, 8, f64)),
        }
    }
}

/// An array's values as the file stores them: floats, or integers kept exact.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Numbers {
    Float(Vec<f64>),
    Int(Vec<i64>),
    UInt(Vec<u64>),
}

impl Numbers {
    pub(crate) fn len(&self) -> usize {
        match self {
            Numbers::Float(v) => v.len(),
            Numbers::Int(v) => v.len(),
            Numbers::UInt(v) => v.len(),
        }
    }

    /// The values as f64. Integers that a double cannot hold exactly (beyond 2⁵³, not a
    /// multiple of the spacing of doubles there) are an error: the certificate compares
    /// values bit for bit.
    pub(crate) fn into_f64(self, what: &str) -> Result<Vec<f64>> {
        let inexact = |k: usize, v: &dyn std::fmt::Display| {
            Error::input(format!(
                "{what}: value {} ({v}) is an integer that Float64 cannot hold exactly (beyond 2^53); \
                 convert the array to floating point first",
                k + 1
            ))
        };
        match self {
            Numbers::Float(v) => Ok(v),
            Numbers::Int(v) => v
                .iter()
                .enumerate()
                .map(|(k, &i)| {
                    let f = i as f64;
                    // i64::MAX rounds up to 2^63, which `as i64` saturates back: compare in i128
                    if f as i128 == i128::from(i) {
                        Ok(f)
                    } else {
                        Err(inexact(k, &i))
                    }
                })
                .collect(),
            Numbers::UInt(v) => v
                .iter()
                .enumerate()
                .map(|(k, &u)| {
                    let f = u as f64;
                    if f as u128 == u128::from(u) && f < 18_446_744_073_709_551_616.0 {
                        Ok(f)
                    } else {
                        Err(inexact(k, &u))
                    }
                })
                .collect(),
        }
    }

    /// The values as indices (connectivity, offsets, counts): integers ≥ 0 only.
    pub(crate) fn into_indices(self, what: &str) -> Result<Vec<usize>> {
        let big = |k: usize, v: &dyn std::fmt::Display| {
            Error::input(format!("{what}: value {} ({v}) is not a valid index", k + 1))
        };
        match self {
            Numbers::Float(_) => {
                Err(Error::input(format!("{what}: the array is floating point, indices must be integers")))
            }
            Numbers::Int(v) => v.iter().enumerate().map(|(k, &i)| usize::try_from(i).map_err(|_| big(k, &i))).collect(),
            Numbers::UInt(v) => {
                v.iter().enumerate().map(|(k, &u)| usize::try_from(u).map_err(|_| big(k, &u))).collect()
            }
        }
    }
}

/// Parses `count` whitespace-separated numbers of type `ty` from ascii data (all there are
/// when `count` is `None`). Integers are parsed as integers (exact beyond 2⁵³); `nan`, `inf`
/// and `-inf` are accepted for floats, as VTK writes them.
pub(crate) fn parse_ascii(ty: Scalar, text: &[u8], count: Option<usize>, what: &str) -> Result<Numbers> {
    let text = std::str::from_utf8(text).map_err(|_| Error::input(format!("{what}: the ascii data is not text")))?;
    let (numbers, end) = parse_tokens(ty, text, count.unwrap_or(usize::MAX), what)?;
    if let Some(count) = count {
        let found = numbers.len() + text[end..].split_ascii_whitespace().count();
        if found != count {
            return Err(Error::input(format!("{what} holds {found} values, {count} are needed")));
        }
    }
    Ok(numbers)
}

/// Parses at most `limit` numbers of type `ty` from the start of `text`; returns them and the
/// byte offset after the last one read (fewer than `limit` if the text ends first).
pub(crate) fn parse_tokens(ty: Scalar, text: &str, limit: usize, what: &str) -> Result<(Numbers, usize)> {
    // a number takes at least 2 bytes with its separator: never reserve more than that allows
    let cap = limit.min(text.len() / 2 + 1);
    let bad = |k: usize, tok: &str| Error::input(format!("{what}: value {} (`{tok}`) is not a number", k + 1));
    let range = |k: usize, tok: &str| {
        Error::input(format!("{what}: value {} (`{tok}`) is out of range for the array's type", k + 1))
    };
    let bits = 8 * ty.size() as u32;
    let (lo, hi) =
        if ty.is_signed() { (-(1i128 << (bits - 1)), (1i128 << (bits - 1)) - 1) } else { (0, (1i128 << bits) - 1) };
    let mut numbers = if ty.is_float() {
        Numbers::Float(Vec::with_capacity(cap))
    } else if ty.is_signed() {
        Numbers::Int(Vec::with_capacity(cap))
    } else {
        Numbers::UInt(Vec::with_capacity(cap))
    };
    let mut end = 0;
    for (k, tok) in text.split_ascii_whitespace().take(limit).enumerate() {
        match &mut numbers {
            // a Float32 array holds the float nearest the text, as VTK reads it
            Numbers::Float(v) if ty == Scalar::F32 => v.push(f64::from(tok.parse::<f32>().map_err(|_| bad(k, tok))?)),
            Numbers::Float(v) => v.push(tok.parse::<f64>().map_err(|_| bad(k, tok))?),
            ints => {
                let x = tok.parse::<i128>().map_err(|_| bad(k, tok))?;
                if x < lo || x > hi {
                    return Err(range(k, tok));
                }
                match ints {
                    Numbers::Int(v) => v.push(x as i64),
                    Numbers::UInt(v) => v.push(x as u64),
                    Numbers::Float(_) => {}
                }
            }
        }
        end = tok.as_ptr() as usize - text.as_ptr() as usize + tok.len();
    }
    Ok((numbers, end))
}

/// The compressor of a VTK XML file's binary data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Compressor {
    None,
    Zlib,
    Lz4,
    Lzma,
}

/// How a VTK XML file encodes binary data.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Encoding {
    pub(crate) big_endian: bool,
    /// Bytes per header word: 4 (UInt32) or 8 (UInt64).
    pub(crate) header: usize,
    pub(crate) compressor: Compressor,
}

/// What an array must hold, for the size checks and their messages.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shape<'a> {
    /// Tuples the array must hold; `None` when the data itself says (cell connectivity).
    pub(crate) tuples: Option<usize>,
    pub(crate) components: usize,
    pub(crate) ty: Scalar,
    /// What the tuples are: "points", "cells", "values".
    pub(crate) of: &'a str,
}

/// The most values one array may hold (2²⁹, 4 GiB as f64): far beyond what can be smoothed
/// on one machine, and a bound on what a small compressed file can make the reader allocate.
pub(crate) const MAX_VALUES: usize = 1 << 29;

impl Shape<'_> {
    /// Values in all (tuples × components) when the shape fixes them, or an error if that
    /// exceeds [`MAX_VALUES`].
    pub(crate) fn count(&self, what: &str) -> Result<Option<usize>> {
        let Some(tuples) = self.tuples else { return Ok(None) };
        tuples.checked_mul(self.components).filter(|&c| c <= MAX_VALUES).map(Some).ok_or_else(|| {
            Error::input(format!(
                "{what}: {tuples} {} × {} components is more than the {MAX_VALUES} values an array may hold",
                self.of, self.components
            ))
        })
    }

    /// Checks that `got` bytes are what the shape needs.
    fn check_bytes(&self, what: &str, got: usize) -> Result<()> {
        let elem = self.ty.size() * self.components;
        if got / self.ty.size() > MAX_VALUES {
            return Err(Error::input(format!(
                "{what} holds {got} bytes, more than the {MAX_VALUES} values an array may hold"
            )));
        }
        let need = self.count(what)?.map(|c| c * self.ty.size());
        if need.is_some_and(|n| n != got) || !got.is_multiple_of(elem) {
            let need = match (need, self.tuples) {
                (Some(n), Some(t)) => format!("{t} {} × {} components need {n} bytes", self.of, self.components),
                _ => format!("{}-byte tuples need a multiple of {elem}", self.components),
            };
            return Err(Error::input(format!(
                "{what} holds {got} bytes ({} values), but {need}",
                got / self.ty.size()
            )));
        }
        Ok(())
    }
}

/// A source of decoded bytes: raw appended data or base64 text.
pub(crate) trait ByteSource {
    /// Exactly `n` bytes, or an error saying the data ends early (checked before allocating).
    fn take(&mut self, n: usize) -> Result<Vec<u8>>;
}

/// Raw binary bytes.
pub(crate) struct RawStream<'a> {
    pub(crate) data: &'a [u8],
    pub(crate) pos: usize,
}

impl ByteSource for RawStream<'_> {
    fn take(&mut self, n: usize) -> Result<Vec<u8>> {
        let left = self.data.len() - self.pos;
        if n > left {
            return Err(Error::input(format!("truncated: {n} bytes needed, {left} left")));
        }
        let out = self.data[self.pos..self.pos + n].to_vec();
        self.pos += n;
        Ok(out)
    }
}

/// Base64 text decoded group by group, so that streams encoded separately and concatenated
/// (VTK encodes the header and the data apart, each padded) decode as well as one stream.
/// The text ends at its end or at a `<`.
pub(crate) struct Base64Stream<'a> {
    text: &'a [u8],
    pos: usize,
    pending: Vec<u8>,
}

impl<'a> Base64Stream<'a> {
    pub(crate) fn new(text: &'a [u8]) -> Self {
        let end = text.iter().position(|&b| b == b'<').unwrap_or(text.len());
        Base64Stream { text: &text[..end], pos: 0, pending: Vec::new() }
    }

    /// Decodes the next group of 4 characters (skipping whitespace) into `pending`.
    fn next_group(&mut self) -> Result<bool> {
        let mut group = [0u8; 4];
        let mut k = 0;
        while k < 4 {
            match self.text.get(self.pos) {
                None => return if k == 0 { Ok(false) } else { Err(Error::input("truncated base64 data")) },
                Some(c) if c.is_ascii_whitespace() => self.pos += 1,
                Some(&c) => {
                    group[k] = c;
                    k += 1;
                    self.pos += 1;
                }
            }
        }
        let pad = group.iter().rev().take_while(|&&c| c == b'=').count();
        if pad > 2 {
            return Err(Error::input("invalid base64 data (`===`)"));
        }
        let mut v = 0u32;
        for (i, &c) in group.iter().enumerate() {
            let d = if i >= 4 - pad {
                0
            } else {
                b64_value(c).ok_or_else(|| Error::input(format!("invalid base64 character `{}`", c.escape_ascii())))?
            };
            v = (v << 6) | u32::from(d);
        }
        let b = v.to_be_bytes();
        self.pending.extend_from_slice(&b[1..4 - pad]);
        Ok(true)
    }
}

fn b64_value(c: u8) -> Option<u8> {
    match c {
        b'A'..=b'Z' => Some(c - b'A'),
        b'a'..=b'z' => Some(c - b'a' + 26),
        b'0'..=b'9' => Some(c - b'0' + 52),
        b'+' => Some(62),
        b'/' => Some(63),
        _ => None,
    }
}

impl ByteSource for Base64Stream<'_> {
    fn take(&mut self, n: usize) -> Result<Vec<u8>> {
        // at most 3 bytes per 4 characters left: refuse absurd sizes before allocating
        let left = (self.text.len() - self.pos) / 4 * 3 + self.pending.len();
        if n > left {
            return Err(Error::input(format!("truncated: {n} bytes needed, at most {left} left")));
        }
        while self.pending.len() < n {
            if !self.next_group()? {
                return Err(Error::input(format!("truncated: {n} bytes needed, {} left", self.pending.len())));
            }
        }
        let rest = self.pending.split_off(n);
        Ok(std::mem::replace(&mut self.pending, rest))
    }
}

fn words(bytes: &[u8], enc: Encoding) -> Vec<u64> {
    bytes
        .chunks_exact(enc.header)
        .map(|c| match (enc.header, enc.big_endian) {
            (4, false) => u64::from(u32::from_le_bytes([c[0], c[1], c[2], c[3]])),
            (4, true) => u64::from(u32::from_be_bytes([c[0], c[1], c[2], c[3]])),
            (_, false) => u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]),
            (_, true) => u64::from_be_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]),
        })
        .collect()
}

/// `n` header words.
fn header_words(src: &mut dyn ByteSource, enc: Encoding, n: usize) -> Result<Vec<u64>> {
    let bytes = n.checked_mul(enc.header).ok_or_else(|| Error::input(format!("a header of {n} words is too large")))?;
    Ok(words(&src.take(bytes)?, enc))
}

fn to_size(v: u64, what: &str) -> Result<usize> {
    usize::try_from(v).map_err(|_| Error::input(format!("{what}: header value {v} is too large")))
}

/// Reads one array's binary block (header then data, compressed or not) holding `shape`,
/// and returns its values.
pub(crate) fn read_block(src: &mut dyn ByteSource, enc: Encoding, shape: Shape, what: &str) -> Result<Numbers> {
    let ctx = |m: &dyn std::fmt::Display| Error::input(format!("{what}: {m}"));
    let raw = if enc.compressor == Compressor::None {
        let nbytes = to_size(header_words(src, enc, 1).map_err(|e| ctx(&e))?[0], what)?;
        shape.check_bytes(what, nbytes)?;
        src.take(nbytes).map_err(|e| ctx(&e))?
    } else {
        read_compressed(src, enc, shape, what)?
    };
    Ok(shape.ty.decode(&raw, enc.big_endian))
}

/// The compressed layout: `[blocks, block size, last block size, compressed sizes...]`, then
/// the blocks.
fn read_compressed(src: &mut dyn ByteSource, enc: Encoding, shape: Shape, what: &str) -> Result<Vec<u8>> {
    let ctx = |m: &dyn std::fmt::Display| Error::input(format!("{what}: {m}"));
    let head = header_words(src, enc, 3).map_err(|e| ctx(&e))?;
    let blocks = to_size(head[0], what)?;
    let block_size = to_size(head[1], what)?;
    let last_size = to_size(head[2], what)?;
    if blocks == 0 {
        shape.check_bytes(what, 0)?;
        return Ok(Vec::new());
    }
    if block_size == 0 || last_size > block_size {
        return Err(ctx(&format!("corrupt compression header (block size {block_size}, last block {last_size})")));
    }
    let last = if last_size == 0 { block_size } else { last_size };
    let total = (blocks - 1)
        .checked_mul(block_size)
        .and_then(|t| t.checked_add(last))
        .ok_or_else(|| ctx(&"corrupt compression header (the sizes overflow)"))?;
    shape.check_bytes(what, total)?;
    // the compressed sizes are read in one piece, which checks they are all present
    let sizes = header_words(src, enc, blocks).map_err(|e| ctx(&e))?;
    let mut out = Vec::new();
    for (i, &cs) in sizes.iter().enumerate() {
        let want = if i + 1 == blocks { last } else { block_size };
        let cs = to_size(cs, what)?;
        let compressed = src.take(cs).map_err(|e| ctx(&e))?;
        let before = out.len();
        let fail = |m: &dyn std::fmt::Display| ctx(&format!("block {} of {blocks} does not decompress: {m}", i + 1));
        match enc.compressor {
            Compressor::Zlib => {
                flate2::read::ZlibDecoder::new(&compressed[..])
                    .take(want as u64 + 1)
                    .read_to_end(&mut out)
                    .map_err(|e| fail(&e))?;
            }
            Compressor::Lz4 => {
                // an lz4 block expands at most 255-fold: refuse a larger claim before allocating
                if want > compressed.len().saturating_mul(255).saturating_add(16) {
                    return Err(ctx(&format!(
                        "block {} of {blocks} claims {want} bytes from {} compressed bytes, more than lz4 can give",
                        i + 1,
                        compressed.len()
                    )));
                }
                out.resize(before + want, 0);
                let n = lz4_flex::block::decompress_into(&compressed, &mut out[before..]).map_err(|e| fail(&e))?;
                out.truncate(before + n);
            }
            Compressor::Lzma => {
                let mut sink = Capped { out: &mut out, cap: before + want };
                lzma_rs::xz_decompress(&mut &compressed[..], &mut sink).map_err(|e| fail(&e))?;
            }
            // not called uncompressed; a stored block would be its own bytes
            Compressor::None => out.extend_from_slice(&compressed[..compressed.len().min(want + 1)]),
        }
        if out.len() - before != want {
            return Err(ctx(&format!(
                "block {} of {blocks} decompresses to {}{} bytes instead of {want}",
                i + 1,
                if out.len() - before > want { "more than " } else { "" },
                (out.len() - before).min(want)
            )));
        }
    }
    Ok(out)
}

/// A writer that refuses to grow past `cap` bytes.
struct Capped<'a> {
    out: &'a mut Vec<u8>,
    cap: usize,
}

impl std::io::Write for Capped<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.out.len() + buf.len() > self.cap {
            // one byte past the cap shows the block is larger than declared
            let room = self.cap + 1 - self.out.len().min(self.cap + 1);
            self.out.extend_from_slice(&buf[..room.min(buf.len())]);
            return Err(std::io::Error::other("the block is larger than its header declares"));
        }
        self.out.extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_beyond_2_53_are_refused_unless_exact() {
        let exact = Numbers::Int(vec![1 << 60, -(1 << 53), 7]).into_f64("a").unwrap();
        assert_eq!(exact, vec![2f64.powi(60), -(2f64.powi(53)), 7.0]);
        let e = Numbers::Int(vec![0, (1 << 53) + 1]).into_f64("point array `a`").unwrap_err().to_string();
        assert!(e.contains("value 2") && e.contains("9007199254740993") && e.contains("2^53"), "{e}");
        assert!(Numbers::UInt(vec![u64::MAX]).into_f64("a").is_err());
        assert!(Numbers::Int(vec![i64::MAX]).into_f64("a").is_err());
        assert_eq!(Numbers::UInt(vec![1 << 63]).into_f64("a").unwrap(), vec![2f64.powi(63)]);
    }

    #[test]
    fn ascii_integers_are_exact_and_range_checked() {
        let n = parse_ascii(Scalar::I64, b" 9007199254740993\n-4 ", None, "a").unwrap();
        assert_eq!(n, Numbers::Int(vec![9_007_199_254_740_993, -4]));
        assert!(parse_ascii(Scalar::U8, b"256", Some(1), "a").unwrap_err().to_string().contains("out of range"));
        assert!(parse_ascii(Scalar::I8, b"-129", Some(1), "a").is_err());
        let e = parse_ascii(Scalar::F64, b"1 2 3", Some(2), "point array `f`").unwrap_err().to_string();
        assert!(e.contains("holds 3 values, 2 are needed"), "{e}");
        let f = parse_ascii(Scalar::F32, b"nan inf -inf 0.7", Some(4), "a").unwrap();
        let Numbers::Float(f) = f else { panic!("floats") };
        assert!(f[0].is_nan() && f[1] == f64::INFINITY && f[2] == f64::NEG_INFINITY);
        assert_eq!(f[3], f64::from(0.7f32), "a Float32 array holds the nearest float");
    }

    #[test]
    fn a_huge_declared_block_is_refused_before_allocating() {
        // uncompressed: 1 GB declared, 12 bytes present
        let enc = Encoding { big_endian: false, header: 8, compressor: Compressor::None };
        let mut data = (1u64 << 30).to_le_bytes().to_vec();
        data.extend_from_slice(&[0; 12]);
        let shape = Shape { tuples: Some(1 << 27), components: 1, ty: Scalar::F64, of: "points" };
        let e = read_block(&mut RawStream { data: &data, pos: 0 }, enc, shape, "a").unwrap_err().to_string();
        assert!(e.contains("truncated"), "{e}");
        // zlib: 2^27 blocks of 8 bytes declared, no sizes present
        let enc = Encoding { compressor: Compressor::Zlib, ..enc };
        let mut data = Vec::new();
        for w in [1u64 << 27, 8, 8] {
            data.extend_from_slice(&w.to_le_bytes());
        }
        let e = read_block(&mut RawStream { data: &data, pos: 0 }, enc, shape, "a").unwrap_err().to_string();
        assert!(e.contains("truncated"), "{e}");
        // lz4: one block of 1 GB claimed from 10 bytes
        let enc = Encoding { compressor: Compressor::Lz4, ..enc };
        let mut data = Vec::new();
        for w in [1u64, 1 << 30, 1 << 30, 10] {
            data.extend_from_slice(&w.to_le_bytes());
        }
        data.extend_from_slice(&[0; 10]);
        let e = read_block(&mut RawStream { data: &data, pos: 0 }, enc, shape, "a").unwrap_err().to_string();
        assert!(e.contains("more than lz4 can give"), "{e}");
    }
}
