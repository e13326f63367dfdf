//! The VTK XML ImageData reader (`.vti`): every layout VTK writes, raw appended data included.

use super::data::{list_names, ImageData, PointArray};
use crate::error::{Error, Result};
use std::io::Read;

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "Int8" | "Char" => Scalar::I8,
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

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }

    /// Converts raw bytes (a whole number of elements) to f64.
    fn decode(self, bytes: &[u8], big_endian: bool) -> Vec<f64> {
        macro_rules! conv {
            ($t:ty, $n:expr) => {
                bytes
                    .chunks_exact($n)
                    .map(|c| {
                        let a: [u8; $n] = c.try_into().expect("chunk size");
                        (if big_endian { <$t>::from_be_bytes(a) } else { <$t>::from_le_bytes(a) }) as f64
                    })
                    .collect()
            };
        }
        match self {
            Scalar::I8 => bytes.iter().map(|&b| b as i8 as f64).collect(),
            Scalar::U8 => bytes.iter().map(|&b| b as f64).collect(),
            Scalar::I16 => conv!(i16, 2),
            Scalar::U16 => conv!(u16, 2),
            Scalar::I32 => conv!(i32, 4),
            Scalar::U32 => conv!(u32, 4),
            Scalar::I64 => conv!(i64, 8),
            Scalar::U64 => conv!(u64, 8),
            Scalar::F32 => conv!(f32, 4),
            Scalar::F64 => conv!(f64, 8),
        }
    }
}

#[derive(Clone, Copy, Debug)]
pub(super) struct Encoding {
    big_endian: bool,
    /// Bytes per header word: 4 (UInt32) or 8 (UInt64).
    header: usize,
    zlib: bool,
}

#[derive(Debug)]
pub(super) enum Format {
    Ascii,
    Binary,
    Appended(usize),
}

#[derive(Debug)]
pub(super) struct ArrayDecl {
    name: String,
    /// None for a type that is not numeric (an error only if the array is read).
    ty: Option<Scalar>,
    /// The `type` attribute as written.
    ty_text: String,
    components: usize,
    format: Format,
    text: Vec<u8>,
}

/// Largest allocation made on the word of a file's header before the data is seen to exist.
pub(super) const CAPACITY: usize = 1 << 24;

pub(super) fn attrs(e: &quick_xml::events::BytesStart) -> Result<Vec<(String, String)>> {
    let tag = String::from_utf8_lossy(e.name().as_ref()).into_owned();
    e.attributes()
        .map(|a| {
            let a = a.map_err(|err| Error::input(format!("malformed attribute in <{tag}>: {err}")))?;
            let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
            let value = match a.unescape_value() {
                Ok(v) => v.into_owned(),
                Err(_) => String::from_utf8_lossy(&a.value).into_owned(),
            };
            Ok((key, value))
        })
        .collect()
}

pub(super) fn get<'a>(attrs: &'a [(String, String)], key: &str) -> Option<&'a str> {
    attrs.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
}

pub(super) fn parse_numbers<const N: usize, T: std::str::FromStr>(s: &str, what: &str) -> Result<[T; N]> {
    let parts: Vec<&str> = s.split_whitespace().collect();
    let parsed: Option<Vec<T>> = parts.iter().map(|p| p.parse::<T>().ok()).collect();
    match parsed {
        Some(v) if v.len() == N => Ok(v.try_into().unwrap_or_else(|_| unreachable!())),
        _ => Err(Error::input(format!("{what} must be {N} numbers, found `{s}`"))),
    }
}

pub(super) fn read_xml(bytes: &[u8]) -> Result<ImageData> {
    // Appended data may be raw binary, which is not XML: parse the markup up to and including
    // the <AppendedData ...> start tag only.
    let appended_tag = find(bytes, b"<AppendedData");
    let (markup, appended) = match appended_tag {
        Some(at) => {
            let close = bytes[at..]
                .iter()
                .position(|&b| b == b'>')
                .map(|p| at + p + 1)
                .ok_or_else(|| Error::input("truncated: the file ends inside the <AppendedData> tag"))?;
            (&bytes[..close], Some(close))
        }
        None => (bytes, None),
    };
    let Markup { file_attrs, image_attrs, piece_extents, point_arrays, cell_names, appended_encoding } =
        scan_markup(markup)?;
    let file_attrs = file_attrs.ok_or_else(|| Error::input("no <VTKFile> element: not a VTK XML file"))?;
    let image_attrs = image_attrs.ok_or_else(|| Error::input("no <ImageData> element (truncated file?)"))?;
    let enc = encoding_of(&file_attrs)?;
    let Geometry { nx, ny, spacing, origin, extent_text } = geometry(&image_attrs, &piece_extents)?;
    if point_arrays.is_empty() && !cell_names.is_empty() {
        let names: Vec<&str> = cell_names.iter().map(String::as_str).collect();
        return Err(Error::input(format!(
            "the file has cell data only ({}); point data is needed (ParaView: Cell Data to Point Data)",
            list_names(&names)
        )));
    }
    let n = nx.checked_mul(ny).ok_or_else(|| Error::input(format!("the extent `{extent_text}` is too large")))?;
    let appended = Appended { bytes, start: appended, encoding: appended_encoding.as_deref() };
    let mut arrays = Vec::with_capacity(point_arrays.len());
    for decl in point_arrays {
        arrays.push(decode_array(decl, n, enc, &appended)?);
    }
    if arrays.is_empty() {
        return Err(Error::input("the file has no point data arrays"));
    }
    Ok(ImageData { nx, ny, spacing, origin, arrays })
}

/// A point array's declaration from its `<DataArray>` attributes.
fn array_decl(a: &[(String, String)], arr_name: String) -> Result<ArrayDecl> {
    let ty_text = get(a, "type").unwrap_or("");
    let ty = Scalar::parse(ty_text);
    let ty_text = ty_text.to_string();
    let components = match get(a, "NumberOfComponents") {
        None => 1,
        Some(c) => c.trim().parse::<usize>().ok().filter(|&c| c > 0).ok_or_else(|| {
            Error::input(format!("point array `{arr_name}`: NumberOfComponents `{c}` is not a positive integer"))
        })?,
    };
    let format = match get(a, "format").unwrap_or("ascii") {
        "ascii" => Format::Ascii,
        "binary" => Format::Binary,
        "appended" => {
            let off = get(a, "offset").unwrap_or("0");
            Format::Appended(
                off.trim()
                    .parse()
                    .map_err(|_| Error::input(format!("point array `{arr_name}`: offset `{off}` is not an integer")))?,
            )
        }
        f => return Err(Error::input(format!("point array `{arr_name}` has unknown format `{f}`"))),
    };
    Ok(ArrayDecl { name: arr_name, ty, ty_text, components, format, text: Vec::new() })
}

/// What the markup declares: the `<VTKFile>` and `<ImageData>` attributes, each piece's
/// extent, the point arrays (with their inline text) and the cell arrays' names, and the
/// encoding of the appended data.
struct Markup {
    file_attrs: Option<Vec<(String, String)>>,
    image_attrs: Option<Vec<(String, String)>>,
    piece_extents: Vec<Option<String>>,
    point_arrays: Vec<ArrayDecl>,
    cell_names: Vec<String>,
    appended_encoding: Option<String>,
}

/// Reads the markup (up to the `<AppendedData>` start tag).
fn scan_markup(markup: &[u8]) -> Result<Markup> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_reader(markup);
    let mut file_attrs: Option<Vec<(String, String)>> = None;
    let mut image_attrs: Option<Vec<(String, String)>> = None;
    let mut piece_extents: Vec<Option<String>> = Vec::new();
    let mut section = ""; // "PointData", "CellData" or "" (elsewhere)
    let mut current: Option<ArrayDecl> = None;
    let mut point_arrays: Vec<ArrayDecl> = Vec::new();
    let mut cell_names: Vec<String> = Vec::new();
    let mut appended_encoding: Option<String> = None;
    loop {
        let event = reader.read_event().map_err(|e| {
            let at = reader.error_position();
            Error::input(format!("malformed XML near byte {at}: {e}")).at(crate::error::Location::Byte(at))
        })?;
        let (start, empty) = match &event {
            Event::Start(e) => (Some(e), false),
            Event::Empty(e) => (Some(e), true),
            _ => (None, false),
        };
        if let Some(e) = start {
            let name = e.name().as_ref().to_vec();
            match name.as_slice() {
                b"VTKFile" => {
                    let a = attrs(e)?;
                    match get(&a, "type") {
                        Some("ImageData") => {}
                        Some(t @ "PImageData") => {
                            return Err(Error::input(format!(
                                "this is a parallel file ({t}) that only points to piece files: read the .vti pieces"
                            )))
                        }
                        Some(t) => {
                            return Err(Error::input(format!(
                                "the data set is {t}; only ImageData (.vti) is supported"
                            )))
                        }
                        None => return Err(Error::input("the <VTKFile> element has no `type`")),
                    }
                    file_attrs = Some(a);
                }
                b"ImageData" => image_attrs = Some(attrs(e)?),
                b"Piece" => {
                    let a = attrs(e)?;
                    piece_extents.push(get(&a, "Extent").map(str::to_string));
                }
                b"PointData" | b"CellData" if !empty => {
                    section = if name == b"PointData" { "PointData" } else { "CellData" };
                }
                b"DataArray" => {
                    let a = attrs(e)?;
                    let arr_name = get(&a, "Name").unwrap_or("").to_string();
                    match section {
                        "PointData" => {
                            let decl = array_decl(&a, arr_name)?;
                            if empty {
                                point_arrays.push(decl);
                            } else {
                                current = Some(decl);
                            }
                        }
                        "CellData" => cell_names.push(arr_name),
                        _ => {}
                    }
                }
                b"AppendedData" => {
                    appended_encoding = Some(get(&attrs(e)?, "encoding").unwrap_or("raw").to_string());
                    break;
                }
                _ => {}
            }
            continue;
        }
        match event {
            Event::Text(t) => {
                if let Some(c) = current.as_mut() {
                    c.text.extend_from_slice(&t);
                }
            }
            Event::CData(t) => {
                if let Some(c) = current.as_mut() {
                    c.text.extend_from_slice(&t);
                }
            }
            Event::End(e) => match e.name().as_ref() {
                b"DataArray" => {
                    if let Some(c) = current.take() {
                        point_arrays.push(c);
                    }
                }
                b"PointData" | b"CellData" => section = "",
                _ => {}
            },
            Event::Eof => {
                if let Some(c) = current {
                    return Err(Error::input(format!("truncated: the file ends inside point array `{}`", c.name)));
                }
                break;
            }
            _ => {}
        }
    }
    Ok(Markup { file_attrs, image_attrs, piece_extents, point_arrays, cell_names, appended_encoding })
}

/// The byte order, header size and compressor the `<VTKFile>` attributes declare.
fn encoding_of(file_attrs: &[(String, String)]) -> Result<Encoding> {
    Ok(Encoding {
        big_endian: match get(file_attrs, "byte_order").unwrap_or("LittleEndian") {
            "LittleEndian" => false,
            "BigEndian" => true,
            o => return Err(Error::input(format!("unknown byte_order `{o}`"))),
        },
        header: match get(file_attrs, "header_type").unwrap_or("UInt32") {
            "UInt32" => 4,
            "UInt64" => 8,
            h => return Err(Error::input(format!("unsupported header_type `{h}` (VTK writes UInt32 or UInt64)"))),
        },
        zlib: match get(file_attrs, "compressor").map(str::trim).unwrap_or("") {
            "" => false,
            "vtkZLibDataCompressor" => true,
            c => {
                return Err(Error::input(format!(
                    "data compressed with `{c}`, which is not supported: only vtkZLibDataCompressor or no compression \
                     (re-save it from ParaView with another compressor)"
                )))
            }
        },
    })
}

/// An image's points, spacing and origin, with its extent as written.
struct Geometry {
    nx: usize,
    ny: usize,
    spacing: [f64; 2],
    origin: [f64; 2],
    extent_text: String,
}

/// The image's size, spacing and origin (the piece's extent shifted into the origin), with
/// the extent as written.
fn geometry(image_attrs: &[(String, String)], piece_extents: &[Option<String>]) -> Result<Geometry> {
    if piece_extents.is_empty() {
        return Err(Error::input("the image has no <Piece> (truncated file?)"));
    }
    if piece_extents.len() > 1 {
        return Err(Error::input(format!(
            "the image is split into {} pieces; only single-piece files are supported",
            piece_extents.len()
        )));
    }
    let whole = get(image_attrs, "WholeExtent").ok_or_else(|| Error::input("<ImageData> has no WholeExtent"))?;
    let extent_text = piece_extents[0].clone().unwrap_or_else(|| whole.to_string());
    let ext: [i64; 6] = parse_numbers(&extent_text, "the extent")?;
    let count = |lo: i64, hi: i64| if hi >= lo { (hi - lo + 1) as usize } else { 0 };
    let (nx, ny, nz) = (count(ext[0], ext[1]), count(ext[2], ext[3]), count(ext[4], ext[5]));
    if nz > 1 {
        return Err(Error::input(format!(
            "the extent `{extent_text}` has {nz} points along z: only 2D images (one point along z) are supported"
        )));
    }
    if nx < 2 || ny < 2 || nz < 1 {
        return Err(Error::input(format!(
            "the extent `{extent_text}` gives {nx} × {ny} × {nz} points: a 2D image needs at least 2 × 2 points in the x-y plane"
        )));
    }
    let origin3: [f64; 3] = match get(image_attrs, "Origin") {
        Some(o) => parse_numbers(o, "Origin")?,
        None => [0.0; 3],
    };
    let spacing3: [f64; 3] = match get(image_attrs, "Spacing") {
        Some(s) => parse_numbers(s, "Spacing")?,
        None => [1.0; 3],
    };
    let spacing = [spacing3[0], spacing3[1]];
    let origin = [origin3[0] + ext[0] as f64 * spacing[0], origin3[1] + ext[2] as f64 * spacing[1]];
    Ok(Geometry { nx, ny, spacing, origin, extent_text })
}

/// Where the appended data is and how it is encoded.
struct Appended<'a> {
    bytes: &'a [u8],
    /// The byte after the `<AppendedData ...>` tag, if there is one.
    start: Option<usize>,
    encoding: Option<&'a str>,
}

/// A declared point array's values: `n` tuples, read inline or from the appended data.
fn decode_array(decl: ArrayDecl, n: usize, enc: Encoding, appended: &Appended) -> Result<PointArray> {
    let ty = decl.ty.ok_or_else(|| {
        Error::input(if decl.ty_text.is_empty() {
            format!("point array `{}` has no `type`", decl.name)
        } else {
            format!("point array `{}` has type {}, which is not numeric", decl.name, decl.ty_text)
        })
    })?;
    let what = format!("point array `{}`", decl.name);
    let expected = n
        .checked_mul(decl.components)
        .and_then(|c| c.checked_mul(ty.size()))
        .ok_or_else(|| Error::input(format!("{what} is too large")))?;
    let values = match decl.format {
        Format::Ascii => parse_ascii(&decl.text, n * decl.components, &what)?,
        Format::Binary => {
            let mut src = Base64Stream { text: &decl.text, pos: 0, pending: Vec::new() };
            let raw = read_block(&mut src, enc, expected, ty.size(), n, decl.components, &what)?;
            ty.decode(&raw, enc.big_endian)
        }
        Format::Appended(offset) => {
            let start = appended
                .start
                .ok_or_else(|| Error::input(format!("{what} is appended but the file has no <AppendedData>")))?;
            let data = appended_start(appended.bytes, start)?;
            let raw = match appended.encoding.unwrap_or("raw") {
                "raw" => {
                    let rest = data.get(offset..).ok_or_else(|| {
                        Error::input(format!(
                            "truncated: {what} starts at offset {offset}, past the end of the appended data"
                        ))
                    })?;
                    let mut src = RawStream { data: rest, pos: 0 };
                    read_block(&mut src, enc, expected, ty.size(), n, decl.components, &what)?
                }
                "base64" => {
                    let rest = data.get(offset..).ok_or_else(|| {
                        Error::input(format!(
                            "truncated: {what} starts at offset {offset}, past the end of the appended data"
                        ))
                    })?;
                    let mut src = Base64Stream { text: rest, pos: 0, pending: Vec::new() };
                    read_block(&mut src, enc, expected, ty.size(), n, decl.components, &what)?
                }
                e => return Err(Error::input(format!("unknown AppendedData encoding `{e}` (expected raw or base64)"))),
            };
            ty.decode(&raw, enc.big_endian)
        }
    };
    Ok(PointArray { name: decl.name, components: decl.components, values })
}

pub(super) fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// The appended data after the `_` marker that follows the `<AppendedData>` tag ending at `close`.
pub(super) fn appended_start(bytes: &[u8], close: usize) -> Result<&[u8]> {
    let rest = &bytes[close..];
    let skip = rest.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(rest.len());
    match rest.get(skip) {
        Some(b'_') => Ok(&rest[skip + 1..]),
        Some(_) => Err(Error::input("the appended data does not start with the `_` marker")),
        None => Err(Error::input("truncated: the file ends before the appended data")),
    }
}

pub(super) fn parse_ascii(text: &[u8], count: usize, what: &str) -> Result<Vec<f64>> {
    let text = std::str::from_utf8(text).map_err(|_| Error::input(format!("{what}: ascii data is not text")))?;
    let mut out = Vec::with_capacity(count.min(CAPACITY));
    for (i, tok) in text.split_ascii_whitespace().enumerate() {
        let v = tok
            .parse::<f64>()
            .map_err(|_| Error::input(format!("{what}: value {} (`{tok}`) is not a number", i + 1)))?;
        out.push(v);
    }
    if out.len() != count {
        return Err(Error::input(format!("{what} holds {} values, the extent needs {count}", out.len())));
    }
    Ok(out)
}

/// A source of decoded bytes: raw appended data or base64 text.
pub(super) trait ByteSource {
    /// Exactly `n` bytes, or an error saying the data ends early.
    fn take(&mut self, n: usize) -> Result<Vec<u8>>;
}

pub(super) struct RawStream<'a> {
    data: &'a [u8],
    pos: usize,
}

impl ByteSource for RawStream<'_> {
    fn take(&mut self, n: usize) -> Result<Vec<u8>> {
        let end =
            self.pos.checked_add(n).filter(|&e| e <= self.data.len()).ok_or_else(|| {
                Error::input(format!("truncated: {n} bytes needed, {} left", self.data.len() - self.pos))
            })?;
        let out = self.data[self.pos..end].to_vec();
        self.pos = end;
        Ok(out)
    }
}

/// Base64 text decoded group by group, so that streams encoded separately and concatenated
/// (VTK encodes the header and the data apart, each padded) decode as well as one stream.
pub(super) struct Base64Stream<'a> {
    text: &'a [u8],
    pos: usize,
    pending: Vec<u8>,
}

pub(super) fn b64_value(c: u8) -> Option<u8> {
    match c {
        b'A'..=b'Z' => Some(c - b'A'),
        b'a'..=b'z' => Some(c - b'a' + 26),
        b'0'..=b'9' => Some(c - b'0' + 52),
        b'+' => Some(62),
        b'/' => Some(63),
        _ => None,
    }
}

impl Base64Stream<'_> {
    /// Decodes the next group of 4 characters (skipping whitespace) into `pending`.
    fn next_group(&mut self) -> Result<bool> {
        let mut group = [0u8; 4];
        let mut k = 0;
        while k < 4 {
            match self.text.get(self.pos) {
                None | Some(b'<') => {
                    return if k == 0 { Ok(false) } else { Err(Error::input("truncated base64 data")) };
                }
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

pub(super) fn header_word(src: &mut dyn ByteSource, enc: Encoding) -> Result<usize> {
    let b = src.take(enc.header)?;
    let v = match (enc.header, enc.big_endian) {
        (4, false) => u64::from(u32::from_le_bytes(b[..4].try_into().expect("4 bytes"))),
        (4, true) => u64::from(u32::from_be_bytes(b[..4].try_into().expect("4 bytes"))),
        (_, false) => u64::from_le_bytes(b[..8].try_into().expect("8 bytes")),
        (_, true) => u64::from_be_bytes(b[..8].try_into().expect("8 bytes")),
    };
    usize::try_from(v).map_err(|_| Error::input(format!("header value {v} is too large")))
}

/// Reads one array's block (header then data, compressed or not) and checks it holds
/// `expected` bytes.
pub(super) fn read_block(
    src: &mut dyn ByteSource,
    enc: Encoding,
    expected: usize,
    elem: usize,
    tuples: usize,
    comps: usize,
    what: &str,
) -> Result<Vec<u8>> {
    let ctx = |m: &dyn std::fmt::Display| Error::input(format!("{what}: {m}"));
    let size_err = |got: usize| {
        Error::input(format!(
            "{what} holds {got} bytes ({} values), but {tuples} points × {comps} components need {expected} bytes",
            got / elem
        ))
    };
    if !enc.zlib {
        let nbytes = header_word(src, enc).map_err(|e| ctx(&e))?;
        if nbytes != expected {
            return Err(size_err(nbytes));
        }
        return src.take(nbytes).map_err(|e| ctx(&e));
    }
    let blocks = header_word(src, enc).map_err(|e| ctx(&e))?;
    let block_size = header_word(src, enc).map_err(|e| ctx(&e))?;
    let last_size = header_word(src, enc).map_err(|e| ctx(&e))?;
    if blocks == 0 {
        return if expected == 0 { Ok(Vec::new()) } else { Err(size_err(0)) };
    }
    if block_size == 0 || last_size > block_size {
        return Err(ctx(&format!("corrupt compression header (block size {block_size}, last block {last_size})")));
    }
    let last = if last_size == 0 { block_size } else { last_size };
    let total = (blocks - 1).checked_mul(block_size).and_then(|t| t.checked_add(last));
    if total != Some(expected) {
        return Err(match total {
            Some(t) => size_err(t),
            None => ctx(&"corrupt compression header"),
        });
    }
    let mut sizes = Vec::with_capacity(blocks.min(CAPACITY));
    for _ in 0..blocks {
        sizes.push(header_word(src, enc).map_err(|e| ctx(&e))?);
    }
    let mut out = Vec::with_capacity(expected.min(CAPACITY));
    for (i, &cs) in sizes.iter().enumerate() {
        let want = if i + 1 == blocks { last } else { block_size };
        let compressed = src.take(cs).map_err(|e| ctx(&e))?;
        let before = out.len();
        flate2::read::ZlibDecoder::new(&compressed[..])
            .take(want as u64 + 1)
            .read_to_end(&mut out)
            .map_err(|e| ctx(&format!("block {} of {blocks} does not decompress: {e}", i + 1)))?;
        if out.len() - before != want {
            return Err(ctx(&format!(
                "block {} of {blocks} decompresses to {} bytes instead of {want}",
                i + 1,
                out.len() - before
            )));
        }
    }
    Ok(out)
}
