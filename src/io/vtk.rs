//! VTK files: reading 2D image data (XML `.vti` and legacy `.vtk` `STRUCTURED_POINTS`) and
//! writing `.vti` image data and `.vtp` poly data that ParaView and VTK open.
//!
//! The XML reader is our own (quick-xml for the markup): it reads every layout VTK writes,
//! including raw appended data, which vtkio cannot read. Legacy files are parsed with vtkio;
//! their origin and spacing are re-read from the header text as f64 because vtkio keeps them
//! as f32. The writers are our own too, because vtkio stores origin and spacing as f32: ours
//! write them as the shortest decimal text that reads back to the same double, and every
//! array as Float64, zlib-compressed, base64-encoded inline (header type UInt64), so values
//! round-trip bit for bit.
//!
//! Spacing is written as given, negative included: VTK 9 reads a negative spacing as a grid
//! laid out in the negative direction of that axis (older readers may refuse it).

use super::{stage, Staged};
use crate::domain::Grid2d;
use crate::error::{Error, Result};
use std::io::{Read, Write};
use std::path::Path;

/// A 2D image read from a VTK file: `nx × ny` points, x fastest (flat index `row · nx + col`,
/// row 0 = the lowest y index of the extent).
#[derive(Clone, Debug, PartialEq)]
pub struct ImageData {
    /// Points along x.
    pub nx: usize,
    /// Points along y.
    pub ny: usize,
    /// Spacing along x and y.
    pub spacing: [f64; 2],
    /// Position of point (row 0, column 0): the file's origin shifted by the extent's start.
    pub origin: [f64; 2],
    /// Point data arrays, in file order.
    pub arrays: Vec<PointArray>,
}

/// One point data array, converted to f64.
#[derive(Clone, Debug, PartialEq)]
pub struct PointArray {
    /// The array's name (`Name` attribute, or the legacy attribute name).
    pub name: String,
    /// Components per point.
    pub components: usize,
    /// `nx · ny · components` values, components interleaved.
    pub values: Vec<f64>,
}

impl PointArray {
    /// Component `k` of every point.
    pub fn component(&self, k: usize) -> Vec<f64> {
        self.values.iter().skip(k).step_by(self.components.max(1)).copied().collect()
    }

    /// Euclidean norm of each point's tuple.
    pub fn magnitude(&self) -> Vec<f64> {
        self.values.chunks(self.components.max(1)).map(|t| t.iter().map(|v| v * v).sum::<f64>().sqrt()).collect()
    }
}

impl ImageData {
    /// Names of the point arrays, in file order.
    pub fn names(&self) -> Vec<&str> {
        self.arrays.iter().map(|a| a.name.as_str()).collect()
    }

    /// The point array called `name`.
    ///
    /// # Errors
    /// An input error listing the available names when there is none of that name.
    pub fn array(&self, name: &str) -> Result<&PointArray> {
        self.arrays.iter().find(|a| a.name == name).ok_or_else(|| {
            Error::input(format!("no point array named `{name}`; the file has: {}", list_names(&self.names())))
        })
    }

    /// The image's grid.
    ///
    /// # Errors
    /// A spacing or origin that [`Grid2d::with_geometry`] refuses (zero or non-finite).
    pub fn grid(&self) -> Result<Grid2d> {
        Grid2d::with_geometry(self.nx, self.ny, self.spacing, self.origin)
    }
}

fn list_names(names: &[&str]) -> String {
    if names.is_empty() {
        "no point arrays".into()
    } else {
        names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
    }
}

fn input(path: &Path, msg: impl Into<String>) -> Error {
    Error::input(msg).in_file(path)
}

/// Reads a 2D image: VTK XML ImageData (`.vti`; ascii, inline binary, appended base64 or raw;
/// uncompressed or `vtkZLibDataCompressor`; UInt32 or UInt64 headers; either byte order; any
/// numeric type) or a legacy `.vtk` `STRUCTURED_POINTS` data set (ASCII or big-endian BINARY;
/// `SCALARS`, `VECTORS`, `NORMALS`, `TEXTURE_COORDINATES`, `TENSORS`, `FIELD` point data). The
/// format is recognised from the content, not the extension. Only point data is read.
///
/// # Errors
/// Input errors naming the file: not a VTK file, a data set that is not image data, more than
/// one point along z, fewer than 2 points along x or y, several pieces, truncated or corrupt
/// data, array sizes that do not match the extent, an unsupported compressor or data type,
/// non-numeric values, cell data only. I/O errors for an unreadable file.
pub fn read_image(path: &Path) -> Result<ImageData> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    let head = bytes[start..].strip_prefix(b"\xef\xbb\xbf").unwrap_or(&bytes[start..]);
    let result = if head.starts_with(b"# vtk DataFile") {
        read_legacy(&bytes)
    } else if head.starts_with(b"<") {
        read_xml(&bytes)
    } else {
        Err(Error::input(
            "neither a VTK XML file (`<?xml ...` / `<VTKFile ...`) nor a legacy VTK file (`# vtk DataFile ...`)",
        ))
    };
    result.map_err(|e| e.in_file(path))
}

// ---------------------------------------------------------------------------------------------
// XML reader

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
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
struct Encoding {
    big_endian: bool,
    /// Bytes per header word: 4 (UInt32) or 8 (UInt64).
    header: usize,
    zlib: bool,
}

#[derive(Debug)]
enum Format {
    Ascii,
    Binary,
    Appended(usize),
}

#[derive(Debug)]
struct ArrayDecl {
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
const CAPACITY: usize = 1 << 24;

fn attrs(e: &quick_xml::events::BytesStart) -> Result<Vec<(String, String)>> {
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

fn get<'a>(attrs: &'a [(String, String)], key: &str) -> Option<&'a str> {
    attrs.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
}

fn parse_numbers<const N: usize, T: std::str::FromStr>(s: &str, what: &str) -> Result<[T; N]> {
    let parts: Vec<&str> = s.split_whitespace().collect();
    let parsed: Option<Vec<T>> = parts.iter().map(|p| p.parse::<T>().ok()).collect();
    match parsed {
        Some(v) if v.len() == N => Ok(v.try_into().unwrap_or_else(|_| unreachable!())),
        _ => Err(Error::input(format!("{what} must be {N} numbers, found `{s}`"))),
    }
}

fn read_xml(bytes: &[u8]) -> Result<ImageData> {
    use quick_xml::events::Event;
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
        let event = reader
            .read_event()
            .map_err(|e| Error::input(format!("malformed XML near byte {}: {e}", reader.error_position())))?;
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
                            let ty_text = get(&a, "type").unwrap_or("");
                            let ty = Scalar::parse(ty_text);
                            let ty_text = ty_text.to_string();
                            let components = match get(&a, "NumberOfComponents") {
                                None => 1,
                                Some(c) => c.trim().parse::<usize>().ok().filter(|&c| c > 0).ok_or_else(|| {
                                    Error::input(format!(
                                        "point array `{arr_name}`: NumberOfComponents `{c}` is not a positive integer"
                                    ))
                                })?,
                            };
                            let format = match get(&a, "format").unwrap_or("ascii") {
                                "ascii" => Format::Ascii,
                                "binary" => Format::Binary,
                                "appended" => {
                                    let off = get(&a, "offset").unwrap_or("0");
                                    Format::Appended(off.trim().parse().map_err(|_| {
                                        Error::input(format!(
                                            "point array `{arr_name}`: offset `{off}` is not an integer"
                                        ))
                                    })?)
                                }
                                f => {
                                    return Err(Error::input(format!(
                                        "point array `{arr_name}` has unknown format `{f}`"
                                    )))
                                }
                            };
                            let decl = ArrayDecl { name: arr_name, ty, ty_text, components, format, text: Vec::new() };
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
    let file_attrs = file_attrs.ok_or_else(|| Error::input("no <VTKFile> element: not a VTK XML file"))?;
    let image_attrs = image_attrs.ok_or_else(|| Error::input("no <ImageData> element (truncated file?)"))?;
    let enc = Encoding {
        big_endian: match get(&file_attrs, "byte_order").unwrap_or("LittleEndian") {
            "LittleEndian" => false,
            "BigEndian" => true,
            o => return Err(Error::input(format!("unknown byte_order `{o}`"))),
        },
        header: match get(&file_attrs, "header_type").unwrap_or("UInt32") {
            "UInt32" => 4,
            "UInt64" => 8,
            h => return Err(Error::input(format!("unsupported header_type `{h}` (VTK writes UInt32 or UInt64)"))),
        },
        zlib: match get(&file_attrs, "compressor").map(str::trim).unwrap_or("") {
            "" => false,
            "vtkZLibDataCompressor" => true,
            c => {
                return Err(Error::input(format!(
                    "data compressed with `{c}`, which is not supported: only vtkZLibDataCompressor or no compression \
                     (re-save it from ParaView with another compressor)"
                )))
            }
        },
    };
    if piece_extents.is_empty() {
        return Err(Error::input("the image has no <Piece> (truncated file?)"));
    }
    if piece_extents.len() > 1 {
        return Err(Error::input(format!(
            "the image is split into {} pieces; only single-piece files are supported",
            piece_extents.len()
        )));
    }
    let whole = get(&image_attrs, "WholeExtent").ok_or_else(|| Error::input("<ImageData> has no WholeExtent"))?;
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
    let origin3: [f64; 3] = match get(&image_attrs, "Origin") {
        Some(o) => parse_numbers(o, "Origin")?,
        None => [0.0; 3],
    };
    let spacing3: [f64; 3] = match get(&image_attrs, "Spacing") {
        Some(s) => parse_numbers(s, "Spacing")?,
        None => [1.0; 3],
    };
    let spacing = [spacing3[0], spacing3[1]];
    let origin = [origin3[0] + ext[0] as f64 * spacing[0], origin3[1] + ext[2] as f64 * spacing[1]];
    if point_arrays.is_empty() && !cell_names.is_empty() {
        let names: Vec<&str> = cell_names.iter().map(String::as_str).collect();
        return Err(Error::input(format!(
            "the file has cell data only ({}); point data is needed (ParaView: Cell Data to Point Data)",
            list_names(&names)
        )));
    }
    let n = nx.checked_mul(ny).ok_or_else(|| Error::input(format!("the extent `{extent_text}` is too large")))?;
    let mut arrays = Vec::with_capacity(point_arrays.len());
    for decl in point_arrays {
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
                    .ok_or_else(|| Error::input(format!("{what} is appended but the file has no <AppendedData>")))?;
                let data = appended_start(bytes, start)?;
                let raw = match appended_encoding.as_deref().unwrap_or("raw") {
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
                    e => {
                        return Err(Error::input(format!(
                            "unknown AppendedData encoding `{e}` (expected raw or base64)"
                        )))
                    }
                };
                ty.decode(&raw, enc.big_endian)
            }
        };
        arrays.push(PointArray { name: decl.name, components: decl.components, values });
    }
    if arrays.is_empty() {
        return Err(Error::input("the file has no point data arrays"));
    }
    Ok(ImageData { nx, ny, spacing, origin, arrays })
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// The appended data after the `_` marker that follows the `<AppendedData>` tag ending at `close`.
fn appended_start(bytes: &[u8], close: usize) -> Result<&[u8]> {
    let rest = &bytes[close..];
    let skip = rest.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(rest.len());
    match rest.get(skip) {
        Some(b'_') => Ok(&rest[skip + 1..]),
        Some(_) => Err(Error::input("the appended data does not start with the `_` marker")),
        None => Err(Error::input("truncated: the file ends before the appended data")),
    }
}

fn parse_ascii(text: &[u8], count: usize, what: &str) -> Result<Vec<f64>> {
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
trait ByteSource {
    /// Exactly `n` bytes, or an error saying the data ends early.
    fn take(&mut self, n: usize) -> Result<Vec<u8>>;
}

struct RawStream<'a> {
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
struct Base64Stream<'a> {
    text: &'a [u8],
    pos: usize,
    pending: Vec<u8>,
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

fn header_word(src: &mut dyn ByteSource, enc: Encoding) -> Result<usize> {
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
fn read_block(
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

// ---------------------------------------------------------------------------------------------
// Legacy reader

fn read_legacy(bytes: &[u8]) -> Result<ImageData> {
    use vtkio::model::{Attribute, DataSet, ElementType, Extent, Piece};
    let vtk = vtkio::Vtk::parse_legacy_be(bytes).map_err(|e| {
        Error::input(format!(
            "cannot parse the legacy VTK file ({e}): it is truncated, malformed or uses a feature vtkio cannot read"
        ))
    })?;
    let DataSet::ImageData { extent, origin, spacing, pieces, .. } = vtk.data else {
        return Err(Error::input("the legacy data set is not STRUCTURED_POINTS; only image data is supported"));
    };
    let dims = match extent {
        Extent::Dims(d) => d.map(|v| v as usize),
        Extent::Ranges(r) => [r[0].clone(), r[1].clone(), r[2].clone()].map(|r| {
            if r.end() >= r.start() {
                (r.end() - r.start() + 1) as usize
            } else {
                0
            }
        }),
    };
    let [nx, ny, nz] = dims;
    if nz > 1 {
        return Err(Error::input(format!(
            "DIMENSIONS {nx} {ny} {nz}: only 2D images (one point along z) are supported"
        )));
    }
    if nx < 2 || ny < 2 || nz < 1 {
        return Err(Error::input(format!("DIMENSIONS {nx} {ny} {nz}: a 2D image needs at least 2 × 2 points")));
    }
    // vtkio keeps origin and spacing as f32: read them again as f64 from the header text
    let (origin64, spacing64) = legacy_geometry(bytes);
    let origin = origin64.unwrap_or([f64::from(origin[0]), f64::from(origin[1])]);
    let spacing = spacing64.unwrap_or([f64::from(spacing[0]), f64::from(spacing[1])]);
    let n = nx * ny;
    let mut arrays = Vec::new();
    let mut cell_names = Vec::new();
    for piece in pieces {
        let Piece::Inline(piece) = piece else {
            return Err(Error::input("the legacy file refers to external pieces"));
        };
        for attr in &piece.data.cell {
            cell_names.push(attr.name().to_string());
        }
        for attr in piece.data.point {
            let mut push = |name: String, comps: usize, buf: &vtkio::IOBuffer| -> Result<()> {
                let values = buf.cast_into::<f64>().ok_or_else(|| {
                    Error::input(format!("point array `{name}` has a data type that cannot be read as numbers"))
                })?;
                if values.len() != n * comps {
                    return Err(Error::input(format!(
                        "point array `{name}` holds {} values, but {n} points × {comps} components need {}",
                        values.len(),
                        n * comps
                    )));
                }
                arrays.push(PointArray { name, components: comps, values });
                Ok(())
            };
            match attr {
                Attribute::DataArray(da) => {
                    if matches!(da.elem, ElementType::LookupTable) {
                        continue; // a colour table, not per-point data
                    }
                    push(da.name.clone(), da.elem.num_comp() as usize, &da.data)?;
                }
                Attribute::Field { data_array, .. } => {
                    for fa in data_array {
                        push(fa.name.clone(), fa.elem as usize, &fa.data)?;
                    }
                }
            }
        }
    }
    if arrays.is_empty() {
        if cell_names.is_empty() {
            return Err(Error::input("the file has no point data"));
        }
        let names: Vec<&str> = cell_names.iter().map(String::as_str).collect();
        return Err(Error::input(format!(
            "the file has cell data only ({}); point data is needed (ParaView: Cell Data to Point Data)",
            list_names(&names)
        )));
    }
    Ok(ImageData { nx, ny, spacing, origin, arrays })
}

/// `ORIGIN` and `SPACING` (or `ASPECT_RATIO`) x and y from a legacy header, as f64.
fn legacy_geometry(bytes: &[u8]) -> (Option<[f64; 2]>, Option<[f64; 2]>) {
    let (mut origin, mut spacing) = (None, None);
    for line in bytes.split(|&b| b == b'\n').take(64) {
        let Ok(line) = std::str::from_utf8(line) else { continue };
        let mut tok = line.split_whitespace();
        let key = tok.next().unwrap_or("").to_ascii_uppercase();
        let xy = || {
            let v: Vec<f64> = line.split_whitespace().skip(1).filter_map(|t| t.parse().ok()).collect();
            (v.len() == 3).then(|| [v[0], v[1]])
        };
        match key.as_str() {
            "ORIGIN" => origin = xy(),
            "SPACING" | "ASPECT_RATIO" => spacing = xy(),
            "POINT_DATA" | "CELL_DATA" => break,
            _ => {}
        }
    }
    (origin, spacing)
}

// ---------------------------------------------------------------------------------------------
// Writers

const BLOCK: usize = 1 << 15;

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn b64_encode(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let v =
            (u32::from(c[0]) << 16) | (u32::from(*c.get(1).unwrap_or(&0)) << 8) | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                out.push(T[(v >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// The base64 text of one zlib-compressed array in VTK's layout (UInt64 header words,
/// little-endian): the header `[blocks, block size, last block size, compressed sizes...]`
/// encoded on its own, then the compressed blocks.
/// zlib level 1: Float64 fields gain little from harder compression (level 6 took 4.6× longer
/// on a 25,600-vertex mesh, 0.115 s against 0.025 s, for a file 4.5 % smaller).
fn compressed_b64(raw: &[u8]) -> std::io::Result<String> {
    let blocks: Vec<Vec<u8>> = raw
        .chunks(BLOCK)
        .map(|chunk| {
            let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
            z.write_all(chunk)?;
            z.finish()
        })
        .collect::<std::io::Result<_>>()?;
    let last = if raw.is_empty() { 0 } else { raw.len() - (raw.len() - 1) / BLOCK * BLOCK };
    let mut header: Vec<u64> = vec![blocks.len() as u64, BLOCK as u64, if last == BLOCK { 0 } else { last as u64 }];
    header.extend(blocks.iter().map(|b| b.len() as u64));
    let header: Vec<u8> = header.iter().flat_map(|v| v.to_le_bytes()).collect();
    Ok(b64_encode(&header) + &b64_encode(&blocks.concat()))
}

fn f64_bytes(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn i64_bytes(values: &[usize]) -> Vec<u8> {
    values.iter().flat_map(|&v| (v as i64).to_le_bytes()).collect()
}

fn write_array(w: &mut dyn Write, indent: &str, ty: &str, name: &str, comps: usize, raw: &[u8]) -> std::io::Result<()> {
    let name = if name.is_empty() { String::new() } else { format!(" Name=\"{}\"", xml_escape(name)) };
    writeln!(w, "{indent}<DataArray type=\"{ty}\"{name} NumberOfComponents=\"{comps}\" format=\"binary\">")?;
    writeln!(w, "{indent}  {}", compressed_b64(raw)?)?;
    writeln!(w, "{indent}</DataArray>")
}

const XML_HEAD: &str = "<?xml version=\"1.0\"?>";

fn file_open(kind: &str) -> String {
    format!(
        "<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" \
         compressor=\"vtkZLibDataCompressor\">"
    )
}

fn check_name(path: &Path, name: &str, seen: &mut Vec<String>) -> Result<()> {
    if name.chars().any(char::is_control) {
        return Err(input(path, format!("array name {name:?} contains control characters")));
    }
    if seen.iter().any(|s| s == name) {
        return Err(input(path, format!("two arrays are named `{name}`")));
    }
    seen.push(name.to_string());
    Ok(())
}

/// Stages a `.vti` image of `nx × ny` points (x fastest, row 0 at `origin`) with one Float64
/// scalar point array per entry of `arrays`, zlib-compressed and base64-encoded inline; the
/// first array is marked as the active scalars. Values (NaN included) round-trip bit for bit
/// through [`read_image`] and VTK. Spacing is written as given (see the module notes on
/// negative spacing).
///
/// # Errors
/// Input errors naming the file: fewer than 1 point along an axis, an array whose length is
/// not `nx · ny`, duplicate names, non-finite spacing or origin. I/O errors while writing.
pub fn stage_vti(
    path: &Path,
    nx: usize,
    ny: usize,
    spacing: [f64; 2],
    origin: [f64; 2],
    arrays: &[(&str, &[f64])],
) -> Result<Staged> {
    if nx == 0 || ny == 0 {
        return Err(input(path, format!("cannot write an image of {nx} × {ny} points")));
    }
    if spacing.iter().chain(&origin).any(|v| !v.is_finite()) {
        return Err(input(path, format!("spacing {spacing:?} and origin {origin:?} must be finite")));
    }
    let mut seen = Vec::new();
    for (name, values) in arrays {
        check_name(path, name, &mut seen)?;
        if values.len() != nx * ny {
            return Err(input(path, format!("array `{name}` has {} values for {nx} × {ny} points", values.len())));
        }
    }
    let f = super::format_f64;
    stage(path, |w| {
        writeln!(w, "{XML_HEAD}")?;
        writeln!(w, "{}", file_open("ImageData"))?;
        let extent = format!("0 {} 0 {} 0 0", nx - 1, ny - 1);
        writeln!(
            w,
            "  <ImageData WholeExtent=\"{extent}\" Origin=\"{} {} 0\" Spacing=\"{} {} 1\" Direction=\"1 0 0 0 1 0 0 0 1\">",
            f(origin[0]),
            f(origin[1]),
            f(spacing[0]),
            f(spacing[1])
        )?;
        writeln!(w, "    <Piece Extent=\"{extent}\">")?;
        match arrays.first() {
            Some((first, _)) => writeln!(w, "      <PointData Scalars=\"{}\">", xml_escape(first))?,
            None => writeln!(w, "      <PointData>")?,
        }
        for (name, values) in arrays {
            write_array(w, "        ", "Float64", name, 1, &f64_bytes(values))?;
        }
        writeln!(w, "      </PointData>")?;
        writeln!(w, "      <CellData>")?;
        writeln!(w, "      </CellData>")?;
        writeln!(w, "    </Piece>")?;
        writeln!(w, "  </ImageData>")?;
        writeln!(w, "</VTKFile>")
    })
}

/// Points, vertex cells and polylines to write as VTK XML PolyData (`.vtp`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolyData {
    /// Point positions.
    pub points: Vec<[f64; 3]>,
    /// One vertex cell per entry: the index of its point.
    pub verts: Vec<usize>,
    /// One polyline cell per entry: its point indices in order (at least one).
    pub lines: Vec<Vec<usize>>,
    /// Triangles.
    pub polys: Vec<[usize; 3]>,
    /// Scalar point data: one value per point.
    pub point_arrays: Vec<(String, Vec<f64>)>,
    /// Scalar cell data in VTK's cell order: one value per vertex cell, then one per line,
    /// then one per triangle.
    pub cell_arrays: Vec<(String, Vec<f64>)>,
}

/// Stages a `.vtp` file of `poly`: Float64 points and data arrays, Int64 connectivity and
/// offsets, zlib-compressed and base64-encoded inline.
///
/// # Errors
/// Input errors naming the file: a cell referring to a missing point, an empty line, an
/// array of the wrong length, duplicate array names, a non-finite coordinate. I/O errors.
pub fn stage_vtp(path: &Path, poly: &PolyData) -> Result<Staged> {
    let n = poly.points.len();
    if let Some(i) = poly.points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(input(path, format!("point {i} has a non-finite coordinate {:?}", poly.points[i])));
    }
    if let Some(&v) = poly.verts.iter().find(|&&v| v >= n) {
        return Err(input(path, format!("a vertex cell refers to point {v}, but there are {n} points")));
    }
    for (k, line) in poly.lines.iter().enumerate() {
        if line.is_empty() {
            return Err(input(path, format!("line {k} has no points")));
        }
        if let Some(&v) = line.iter().find(|&&v| v >= n) {
            return Err(input(path, format!("line {k} refers to point {v}, but there are {n} points")));
        }
    }
    if let Some((k, t)) = poly.polys.iter().enumerate().find(|(_, t)| t.iter().any(|&v| v >= n)) {
        return Err(input(path, format!("triangle {k} = {t:?} refers to a missing point (there are {n} points)")));
    }
    let cells = poly.verts.len() + poly.lines.len() + poly.polys.len();
    let mut seen = Vec::new();
    for (name, values) in &poly.point_arrays {
        check_name(path, name, &mut seen)?;
        if values.len() != n {
            return Err(input(path, format!("point array `{name}` has {} values for {n} points", values.len())));
        }
    }
    let mut seen = Vec::new();
    for (name, values) in &poly.cell_arrays {
        check_name(path, name, &mut seen)?;
        if values.len() != cells {
            return Err(input(
                path,
                format!(
                    "cell array `{name}` has {} values for {cells} cells ({} vertices + {} lines + {} triangles)",
                    values.len(),
                    poly.verts.len(),
                    poly.lines.len(),
                    poly.polys.len()
                ),
            ));
        }
    }
    let coords: Vec<f64> = poly.points.iter().flatten().copied().collect();
    let vert_offsets: Vec<usize> = (1..=poly.verts.len()).collect();
    let line_conn: Vec<usize> = poly.lines.concat();
    let line_offsets: Vec<usize> = poly
        .lines
        .iter()
        .scan(0, |acc, l| {
            *acc += l.len();
            Some(*acc)
        })
        .collect();
    stage(path, |w| {
        writeln!(w, "{XML_HEAD}")?;
        writeln!(w, "{}", file_open("PolyData"))?;
        writeln!(w, "  <PolyData>")?;
        writeln!(
            w,
            "    <Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{}\" NumberOfLines=\"{}\" NumberOfStrips=\"0\" NumberOfPolys=\"{}\">",
            poly.verts.len(),
            poly.lines.len(),
            poly.polys.len()
        )?;
        for (tag, arrays) in [("PointData", &poly.point_arrays), ("CellData", &poly.cell_arrays)] {
            match arrays.first() {
                Some((first, _)) => writeln!(w, "      <{tag} Scalars=\"{}\">", xml_escape(first))?,
                None => writeln!(w, "      <{tag}>")?,
            }
            for (name, values) in arrays {
                write_array(w, "        ", "Float64", name, 1, &f64_bytes(values))?;
            }
            writeln!(w, "      </{tag}>")?;
        }
        writeln!(w, "      <Points>")?;
        write_array(w, "        ", "Float64", "Points", 3, &f64_bytes(&coords))?;
        writeln!(w, "      </Points>")?;
        // empty cell lists are left out (VTK reads that as none; vtkio fails on empty arrays)
        let poly_conn: Vec<usize> = poly.polys.iter().flatten().copied().collect();
        let poly_offsets: Vec<usize> = (1..=poly.polys.len()).map(|k| 3 * k).collect();
        for (tag, conn, offsets) in [
            ("Verts", &poly.verts, &vert_offsets),
            ("Lines", &line_conn, &line_offsets),
            ("Polys", &poly_conn, &poly_offsets),
        ] {
            if conn.is_empty() {
                continue;
            }
            writeln!(w, "      <{tag}>")?;
            write_array(w, "        ", "Int64", "connectivity", 1, &i64_bytes(conn))?;
            write_array(w, "        ", "Int64", "offsets", 1, &i64_bytes(offsets))?;
            writeln!(w, "      </{tag}>")?;
        }
        writeln!(w, "    </Piece>")?;
        writeln!(w, "  </PolyData>")?;
        writeln!(w, "</VTKFile>")
    })
}

/// Stages a `.vtu` unstructured grid of triangles (VTK_TRIANGLE cells) with one Float64
/// scalar point array per entry of `arrays` (the first marked active), zlib-compressed and
/// base64-encoded inline; values round-trip bit for bit.
///
/// # Errors
/// Input errors naming the file: a triangle referring to a missing point, an array of the
/// wrong length, duplicate names, a non-finite coordinate. I/O errors.
pub fn stage_vtu(
    path: &Path,
    points: &[[f64; 3]],
    triangles: &[[usize; 3]],
    arrays: &[(&str, &[f64])],
) -> Result<Staged> {
    let n = points.len();
    if let Some(i) = points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(input(path, format!("point {i} has a non-finite coordinate {:?}", points[i])));
    }
    if let Some((k, t)) = triangles.iter().enumerate().find(|(_, t)| t.iter().any(|&v| v >= n)) {
        return Err(input(path, format!("triangle {k} = {t:?} refers to a missing point (there are {n} points)")));
    }
    let mut seen = Vec::new();
    for (name, values) in arrays {
        check_name(path, name, &mut seen)?;
        if values.len() != n {
            return Err(input(path, format!("point array `{name}` has {} values for {n} points", values.len())));
        }
    }
    let coords: Vec<f64> = points.iter().flatten().copied().collect();
    let conn: Vec<usize> = triangles.iter().flatten().copied().collect();
    let offsets: Vec<usize> = (1..=triangles.len()).map(|k| 3 * k).collect();
    let types = vec![5u8; triangles.len()];
    stage(path, |w| {
        writeln!(w, "{XML_HEAD}")?;
        writeln!(w, "{}", file_open("UnstructuredGrid"))?;
        writeln!(w, "  <UnstructuredGrid>")?;
        writeln!(w, "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{}\">", triangles.len())?;
        match arrays.first() {
            Some((first, _)) => writeln!(w, "      <PointData Scalars=\"{}\">", xml_escape(first))?,
            None => writeln!(w, "      <PointData>")?,
        }
        for (name, values) in arrays {
            write_array(w, "        ", "Float64", name, 1, &f64_bytes(values))?;
        }
        writeln!(w, "      </PointData>")?;
        writeln!(w, "      <Points>")?;
        write_array(w, "        ", "Float64", "Points", 3, &f64_bytes(&coords))?;
        writeln!(w, "      </Points>")?;
        writeln!(w, "      <Cells>")?;
        write_array(w, "        ", "Int64", "connectivity", 1, &i64_bytes(&conn))?;
        write_array(w, "        ", "Int64", "offsets", 1, &i64_bytes(&offsets))?;
        write_array(w, "        ", "UInt8", "types", 1, &types)?;
        writeln!(w, "      </Cells>")?;
        writeln!(w, "    </Piece>")?;
        writeln!(w, "  </UnstructuredGrid>")?;
        writeln!(w, "</VTKFile>")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir() -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("toposmooth-vtk-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn example1() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/karman_vortex_street_ttk_example1.vti")
    }

    /// Example 3 lives in the shared data folder beside the repository (or in datasets/).
    fn example3() -> Option<std::path::PathBuf> {
        let name = "uncertain_karman_vortex_street_ttk_example3.vti";
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        [root.join("datasets").join(name), root.join("../shared/data").join(name)].into_iter().find(|p| p.exists())
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    fn values(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        (0..n)
            .map(|i| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                match i % 11 {
                    0 => -0.0,
                    1 => 5e-324,
                    2 => f64::MAX,
                    _ => f64::from_bits(s >> 2) * if s & 1 == 0 { 1.0 } else { -1.0 },
                }
            })
            .collect()
    }

    #[test]
    fn reads_karman_example1() {
        let img = read_image(&example1()).unwrap();
        assert_eq!((img.nx, img.ny), (513, 65));
        assert_eq!((img.spacing, img.origin), ([1.0, 1.0], [0.0, 0.0]));
        assert_eq!(img.names(), ["Vectors_"]);
        let v = img.array("Vectors_").unwrap();
        assert_eq!(v.components, 3);
        assert_eq!(v.values.len(), 513 * 65 * 3);
        assert!(v.component(2).iter().all(|&z| z == 0.0), "z velocity is 0 in a 2D flow");
        assert!(v.values.iter().all(|x| x.is_finite()));
        let mag = v.magnitude();
        // the obstacle: velocity exactly 0 on the block x = 30..=35, y = 30..=35 less its 4
        // corners (a rounded cylinder), and nowhere else
        let zero: Vec<(usize, usize)> = (0..mag.len()).filter(|&k| mag[k] == 0.0).map(|k| (k % 513, k / 513)).collect();
        let corner = |x: usize, y: usize| (x == 30 || x == 35) && (y == 30 || y == 35);
        let block: Vec<(usize, usize)> =
            (30..=35).flat_map(|y| (30..=35).map(move |x| (x, y))).filter(|&(x, y)| !corner(x, y)).collect();
        assert_eq!(zero, block);
        // values as decoded independently (Python zlib + base64)
        let k = (32 * 513 + 100) * 3;
        assert_eq!((v.values[k], v.values[k + 1]), (0.8997898101806641, -0.32171547412872314));
        assert!((v.values.iter().sum::<f64>() - 33401.93146558964).abs() < 1e-8);
        // the free stream moves
        assert!(mag[32 * 513 + 500] > 0.1 && mag[5 * 513 + 5] > 0.1);
        // max velocity within the RangeMax the file advertises
        let max = mag.iter().cloned().fold(0.0, f64::max);
        assert!((max - 1.3748271724).abs() < 1e-9, "{max}");
        assert!(img.grid().is_ok());
        let e = img.array("vorticity").unwrap_err().to_string();
        assert!(e.contains("`vorticity`") && e.contains("`Vectors_`"), "{e}");
    }

    #[test]
    fn reads_uncertain_example3() {
        let Some(p) = example3() else {
            eprintln!(
                "skipped: uncertain_karman_vortex_street_ttk_example3.vti is not in datasets/ or ../shared/data/"
            );
            return;
        };
        let img = read_image(&p).unwrap();
        assert_eq!((img.nx, img.ny), (513, 65));
        assert_eq!(img.names(), ["lowerBoundField", "upperBoundField"]);
        let lo = img.array("lowerBoundField").unwrap();
        let hi = img.array("upperBoundField").unwrap();
        assert_eq!((lo.components, hi.components), (1, 1));
        assert_eq!(lo.values.len(), 513 * 65);
        assert!(lo.values.iter().zip(&hi.values).all(|(l, h)| l <= h), "lower ≤ upper everywhere");
        assert!(lo.values.iter().zip(&hi.values).any(|(l, h)| l < h), "the bounds are not all equal");
        // Float32 data: every value is exactly an f32
        assert!(lo.values.iter().all(|&v| (v as f32) as f64 == v));
        assert_eq!(lo.values[0] as f32, f32::from_le_bytes([0x0f, 0x00, 0x80, 0x3f]));
    }

    #[test]
    fn vti_round_trip_bits_and_geometry() {
        let d = dir();
        let (nx, ny) = (37, 23); // 851 doubles: several zlib blocks
        let a = values(nx * ny, 1);
        let mut b = values(nx * ny, 2);
        b[5] = f64::NAN;
        let many = values(5000, 3)[..5000].to_vec();
        for (name, spacing, origin) in [("g.vti", [0.1, 0.3], [-1.7, 1e-9]), ("neg.vti", [-0.5, 2.0], [3.0, 0.0])] {
            let p = d.join(name);
            let staged = stage_vti(&p, nx, ny, spacing, origin, &[("f & <g>", &a), ("b", &b)]).unwrap();
            assert!(!p.exists());
            staged.commit().unwrap();
            let img = read_image(&p).unwrap();
            assert_eq!((img.nx, img.ny, img.spacing, img.origin), (nx, ny, spacing, origin));
            assert_eq!(img.names(), ["f & <g>", "b"]);
            assert_eq!(bits(&img.arrays[0].values), bits(&a));
            assert_eq!(bits(&img.arrays[1].values), bits(&b));
            // vtkio reads our file too, with the same data
            let vtk = vtkio::Vtk::parse_xml(std::io::BufReader::new(std::fs::File::open(&p).unwrap())).unwrap();
            let vtkio::model::DataSet::ImageData { pieces, .. } = vtk.data else { panic!("not image data") };
            let vtkio::model::Piece::Inline(piece) = &pieces[0] else { panic!("not inline") };
            let vtkio::model::Attribute::DataArray(arr) = &piece.data.point[0] else { panic!("no array") };
            assert_eq!(arr.name, "f & <g>");
            assert_eq!(bits(&arr.data.cast_into::<f64>().unwrap()), bits(&a));
        }
        // a large array over many blocks
        let p = d.join("big.vti");
        stage_vti(&p, 100, 50, [1.0, 1.0], [0.0, 0.0], &[("m", &many)]).unwrap().commit().unwrap();
        assert_eq!(bits(&read_image(&p).unwrap().arrays[0].values), bits(&many));
        // argument errors
        let e = stage_vti(&p, 10, 10, [1.0, 1.0], [0.0, 0.0], &[("m", &many)]).err().unwrap().to_string();
        assert!(e.contains("big.vti") && e.contains("`m`"), "{e}");
        let e = stage_vti(&p, 100, 50, [f64::NAN, 1.0], [0.0, 0.0], &[]).err().unwrap().to_string();
        assert!(e.contains("finite"), "{e}");
    }

    // ---- hand-built .vti files in every layout -------------------------------------------

    #[derive(Clone, Copy, Debug)]
    enum Layout {
        Ascii,
        Binary,
        Base64Appended,
        RawAppended,
    }

    #[derive(Clone, Copy, Debug)]
    struct Spec {
        big: bool,
        header64: bool,
        zlib: bool,
        layout: Layout,
        /// Header and data base64-encoded as one stream instead of two.
        joint: bool,
    }

    fn encode(ty: &str, v: f64, big: bool) -> Vec<u8> {
        macro_rules! e {
            ($t:ty) => {
                if big {
                    (v as $t).to_be_bytes().to_vec()
                } else {
                    (v as $t).to_le_bytes().to_vec()
                }
            };
        }
        match ty {
            "Int8" => e!(i8),
            "UInt8" => e!(u8),
            "Int16" => e!(i16),
            "UInt16" => e!(u16),
            "Int32" => e!(i32),
            "UInt32" => e!(u32),
            "Int64" => e!(i64),
            "UInt64" => e!(u64),
            "Float32" => e!(f32),
            "Float64" => e!(f64),
            _ => panic!("{ty}"),
        }
    }

    fn block(s: Spec, raw: &[u8]) -> (Vec<u8>, Vec<u8>) {
        let word = |v: usize| match (s.header64, s.big) {
            (true, true) => (v as u64).to_be_bytes().to_vec(),
            (true, false) => (v as u64).to_le_bytes().to_vec(),
            (false, true) => (v as u32).to_be_bytes().to_vec(),
            (false, false) => (v as u32).to_le_bytes().to_vec(),
        };
        if !s.zlib {
            return (word(raw.len()), raw.to_vec());
        }
        let bs = 64;
        let blocks: Vec<Vec<u8>> = raw
            .chunks(bs)
            .map(|c| {
                let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
                z.write_all(c).unwrap();
                z.finish().unwrap()
            })
            .collect();
        let last = raw.len() % bs;
        let mut header = [word(blocks.len()), word(bs), word(last)].concat();
        for b in &blocks {
            header.extend(word(b.len()));
        }
        (header, blocks.concat())
    }

    fn vti(s: Spec, extent: &str, arrays: &[(&str, &str, usize, &[f64])]) -> Vec<u8> {
        let mut x = String::from("<?xml version=\"1.0\"?>\n");
        x += &format!(
            "<VTKFile type=\"ImageData\" version=\"{}\" byte_order=\"{}\"{}{}>\n",
            if s.header64 { "1.0" } else { "0.1" },
            if s.big { "BigEndian" } else { "LittleEndian" },
            if s.header64 { " header_type=\"UInt64\"" } else { "" },
            if s.zlib { " compressor=\"vtkZLibDataCompressor\"" } else { "" },
        );
        x += &format!("<ImageData WholeExtent=\"{extent}\" Origin=\"10 20 0\" Spacing=\"0.5 0.25 1\">\n");
        x += &format!("<Piece Extent=\"{extent}\">\n<PointData>\n");
        let mut appended: Vec<u8> = Vec::new();
        for (ty, name, comps, vals) in arrays {
            let raw: Vec<u8> = vals.iter().flat_map(|&v| encode(ty, v, s.big)).collect();
            let (header, data) = block(s, &raw);
            let b64 = if s.joint {
                b64_encode(&[header.clone(), data.clone()].concat())
            } else {
                b64_encode(&header) + &b64_encode(&data)
            };
            let open = format!("<DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{comps}\"");
            match s.layout {
                Layout::Ascii => {
                    let text: Vec<String> = vals
                        .iter()
                        .map(|v| if ty.starts_with("Float") { format!("{v:?}") } else { format!("{}", *v as i64) })
                        .collect();
                    x += &format!("{open} format=\"ascii\">\n  {}\n</DataArray>\n", text.join(" "));
                }
                Layout::Binary => x += &format!("{open} format=\"binary\">\n  {b64}\n</DataArray>\n"),
                Layout::Base64Appended => {
                    x += &format!("{open} format=\"appended\" offset=\"{}\"/>\n", appended.len());
                    appended.extend(b64.as_bytes());
                }
                Layout::RawAppended => {
                    x += &format!("{open} format=\"appended\" offset=\"{}\"/>\n", appended.len());
                    appended.extend(header);
                    appended.extend(data);
                }
            }
        }
        x += "</PointData>\n<CellData>\n</CellData>\n</Piece>\n</ImageData>\n";
        let mut out = x.into_bytes();
        if matches!(s.layout, Layout::Base64Appended | Layout::RawAppended) {
            let enc = if matches!(s.layout, Layout::RawAppended) { "raw" } else { "base64" };
            out.extend(format!("<AppendedData encoding=\"{enc}\">\n   _").as_bytes());
            out.extend(appended);
            out.extend(b"\n</AppendedData>\n");
        }
        out.extend(b"</VTKFile>\n");
        out
    }

    #[test]
    fn reads_every_vti_layout_and_type() {
        let d = dir();
        let (nx, ny) = (5, 3);
        let n = nx * ny;
        let f64s = values(n, 9);
        let f32s: Vec<f64> = (0..n).map(|i| i as f64 * 0.5 - 3.0).collect();
        let ints: Vec<f64> = (0..n * 2).map(|i| i as f64 * 3.0 - 40.0).collect(); // fits in Int8
        let small: Vec<f64> = (0..n).map(|i| (i * 17 % 256) as f64).collect();
        let big_u: Vec<f64> = (0..n).map(|i| (1u64 << 40) as f64 + i as f64).collect();
        let types = ["Int8", "Int16", "Int32", "Int64"];
        let mut k = 0;
        for layout in [Layout::Ascii, Layout::Binary, Layout::Base64Appended, Layout::RawAppended] {
            for big in [false, true] {
                for header64 in [false, true] {
                    for zlib in [false, true] {
                        for joint in [false, true] {
                            if joint && matches!(layout, Layout::Ascii | Layout::RawAppended) {
                                continue;
                            }
                            let s = Spec { big, header64, zlib, layout, joint };
                            let ity = types[k % 4];
                            k += 1;
                            let arrays: [(&str, &str, usize, &[f64]); 6] = [
                                ("Float64", "d", 1, &f64s),
                                ("Float32", "s", 1, &f32s),
                                (ity, "i", 2, &ints),
                                ("UInt8", "u8", 1, &small),
                                ("UInt16", "u16", 1, &small),
                                ("UInt64", "u64", 1, &big_u),
                            ];
                            let arrays = if matches!(layout, Layout::Ascii) { &arrays[1..] } else { &arrays[..] };
                            let p = d.join(format!("layout{k}.vti"));
                            std::fs::write(&p, vti(s, "2 6 -1 1 0 0", arrays)).unwrap();
                            let img = read_image(&p).unwrap_or_else(|e| panic!("{s:?}: {e}"));
                            assert_eq!((img.nx, img.ny), (nx, ny), "{s:?}");
                            // the extent starts at (2, -1): the first point is shifted
                            assert_eq!(img.origin, [11.0, 19.75], "{s:?}");
                            assert_eq!(img.spacing, [0.5, 0.25]);
                            for (arr, (_, name, comps, vals)) in img.arrays.iter().zip(arrays) {
                                assert_eq!((&arr.name[..], arr.components), (*name, *comps), "{s:?}");
                                assert_eq!(bits(&arr.values), bits(vals), "{s:?} {name}");
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn reads_legacy_structured_points() {
        let d = dir();
        let head = "# vtk DataFile Version 3.0\nlegacy test\n";
        let geometry = "DATASET STRUCTURED_POINTS\nDIMENSIONS 3 2 1\nORIGIN 0.1 -2.5 0\nSPACING 0.1 0.3 1\n";
        let ascii = format!(
            "{head}ASCII\n{geometry}POINT_DATA 6\nSCALARS height double 1\nLOOKUP_TABLE default\n\
             1.5 2 3 4 5 6.25\nVECTORS vel float\n1 0 0 2 0 0 3 0 0 4 0 0 5 0 0 6 0 0\n\
             FIELD FieldData 1\ntemp 2 6 int\n1 2 3 4 5 6 7 8 9 10 11 12\n"
        );
        let p = d.join("a.vtk");
        std::fs::write(&p, ascii).unwrap();
        let img = read_image(&p).unwrap();
        assert_eq!((img.nx, img.ny, img.origin, img.spacing), (3, 2, [0.1, -2.5], [0.1, 0.3]));
        assert_eq!(img.names(), ["height", "vel", "temp"]);
        assert_eq!(img.arrays[0].values, vec![1.5, 2.0, 3.0, 4.0, 5.0, 6.25]);
        assert_eq!(img.arrays[1].components, 3);
        assert_eq!(img.arrays[1].component(0), vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!((img.arrays[2].components, img.arrays[2].values[11]), (2, 12.0));

        let h: Vec<f64> = values(6, 4);
        let mut bin =
            format!("{head}BINARY\n{geometry}POINT_DATA 6\nSCALARS h double\nLOOKUP_TABLE default\n").into_bytes();
        bin.extend(h.iter().flat_map(|v| v.to_be_bytes()));
        bin.extend(b"\n");
        let p = d.join("b.vtk");
        std::fs::write(&p, &bin).unwrap();
        let img = read_image(&p).unwrap();
        assert_eq!(bits(&img.array("h").unwrap().values), bits(&h));
        // errors: truncated binary data, 3D dimensions, cell data only
        let p = d.join("cut.vtk");
        std::fs::write(&p, &bin[..bin.len() - 20]).unwrap();
        let e = read_image(&p).unwrap_err().to_string();
        assert!(e.contains("cut.vtk") && e.contains("truncated"), "{e}");
        let p = d.join("3d.vtk");
        std::fs::write(&p, format!("{head}ASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\nORIGIN 0 0 0\nSPACING 1 1 1\nPOINT_DATA 8\nSCALARS s float\nLOOKUP_TABLE default\n1 2 3 4 5 6 7 8\n")).unwrap();
        let e = read_image(&p).unwrap_err().to_string();
        assert!(e.contains("3d.vtk") && e.contains("along z"), "{e}");
        let p = d.join("cells.vtk");
        std::fs::write(&p, format!("{head}ASCII\n{geometry}CELL_DATA 2\nSCALARS c float\nLOOKUP_TABLE default\n1 2\n"))
            .unwrap();
        let e = read_image(&p).unwrap_err().to_string();
        assert!(e.contains("cells.vtk") && e.contains("`c`"), "{e}");
    }

    fn edited(name: &str, from: &str, to: &str) -> std::path::PathBuf {
        let text = std::fs::read_to_string(example1()).unwrap();
        assert!(text.contains(from), "{from}");
        let p = dir().join(name);
        std::fs::write(&p, text.replace(from, to)).unwrap();
        p
    }

    fn error_of(p: &Path) -> String {
        let e = read_image(p).unwrap_err().to_string();
        let name = p.file_name().unwrap().to_str().unwrap();
        assert!(e.contains(name), "the error names the file: {e}");
        e
    }

    #[test]
    fn bad_vti_files_give_clear_errors() {
        let d = dir();
        // truncated: Example 1 (appended base64) cut in half
        let bytes = std::fs::read(example1()).unwrap();
        let p = d.join("half.vti");
        std::fs::write(&p, &bytes[..bytes.len() / 2]).unwrap();
        assert!(error_of(&p).contains("truncated"));
        // truncated inline binary data, and raw appended data
        let n = 6 * 4;
        let v = values(n, 5);
        let s = Spec { big: false, header64: true, zlib: true, layout: Layout::Binary, joint: false };
        let file = vti(s, "0 5 0 3 0 0", &[("Float64", "v", 1, &v)]);
        let p = d.join("inline-half.vti");
        std::fs::write(&p, &file[..file.len() * 3 / 5]).unwrap();
        assert!(error_of(&p).contains("truncated"));
        let s = Spec { layout: Layout::RawAppended, zlib: false, ..s };
        let file = vti(s, "0 5 0 3 0 0", &[("Float64", "v", 1, &v)]);
        let cut = file.len() - "\n</AppendedData>\n</VTKFile>\n".len() - 9;
        let p = d.join("raw-half.vti");
        std::fs::write(&p, &file[..cut]).unwrap();
        assert!(error_of(&p).contains("truncated"));
        // wrong sizes: components or extent edited
        let p = edited("comps.vti", "NumberOfComponents=\"3\"", "NumberOfComponents=\"2\"");
        let e = error_of(&p);
        assert!(e.contains("`Vectors_`") && e.contains("bytes"), "{e}");
        let p = edited("extent.vti", "0 512 0 64 0 0", "0 511 0 64 0 0");
        let e = error_of(&p);
        assert!(e.contains("33280 points") && e.contains("`Vectors_`"), "{e}");
        // unknown compressor
        let p = edited("lz4.vti", "vtkZLibDataCompressor", "vtkLZ4DataCompressor");
        assert!(error_of(&p).contains("vtkLZ4DataCompressor"));
        // 3D extent, too thin
        let p = edited("3d.vti", "0 512 0 64 0 0", "0 512 0 64 0 3");
        assert!(error_of(&p).contains("along z"));
        let p = edited("thin.vti", "0 512 0 64 0 0", "0 512 0 0 0 0");
        assert!(error_of(&p).contains("2 × 2"));
        // corrupt base64, non-numeric ascii, string array, cell data only, not VTK, not ImageData
        let p = edited("b64.vti", "_GQAAAACAAAAY", "_GQAAAAC*AAAY");
        assert!(error_of(&p).contains("base64"));
        let s = Spec { big: false, header64: false, zlib: false, layout: Layout::Ascii, joint: false };
        let text = String::from_utf8(vti(s, "0 1 0 1 0 0", &[("Float64", "a", 1, &[1.0, 2.0, 3.0, 4.0])])).unwrap();
        let p = d.join("text.vti");
        std::fs::write(&p, text.replace("3.0", "x3")).unwrap();
        let e = error_of(&p);
        assert!(e.contains("`x3`") && e.contains("`a`"), "{e}");
        let p = d.join("short-ascii.vti");
        std::fs::write(&p, text.replace("3.0 4.0", "3.0")).unwrap();
        assert!(error_of(&p).contains("3 values"));
        let p = d.join("string.vti");
        std::fs::write(&p, text.replace("type=\"Float64\"", "type=\"String\"")).unwrap();
        assert!(error_of(&p).contains("String"));
        let p = d.join("cells.vti");
        std::fs::write(
            &p,
            text.replace("<PointData>", "<PointData>\n</PointData>\n<CellData>").replacen(
                "</PointData>\n<CellData>\n</CellData>",
                "</CellData>",
                1,
            ),
        )
        .unwrap();
        let e = error_of(&p);
        assert!(e.contains("cell data only") && e.contains("`a`"), "{e}");
        let p = d.join("poly.vti");
        std::fs::write(&p, text.replace("type=\"ImageData\"", "type=\"PolyData\"")).unwrap();
        assert!(error_of(&p).contains("PolyData"));
        let p = d.join("junk.vti");
        std::fs::write(&p, b"hello").unwrap();
        assert!(error_of(&p).contains("VTK"));
        // missing file: an I/O error naming it
        let e = read_image(&d.join("missing.vti")).unwrap_err();
        assert!(matches!(e, Error::Io { .. }) && e.to_string().contains("missing.vti"), "{e}");
    }

    #[test]
    fn vtp_is_valid_poly_data() {
        use vtkio::model::{Attribute, DataSet, Piece, VertexNumbers};
        let poly = PolyData {
            points: vec![[0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [2.0, 0.25, 1.0], [0.1, 0.2, 0.3]],
            verts: vec![0, 3],
            lines: vec![vec![0, 1, 2], vec![3, 1]],
            point_arrays: vec![("value".into(), vec![1.0, 2.0, 3.0, 4.0])],
            cell_arrays: vec![("kind".into(), vec![0.0, 2.0, 7.0, 8.0])],
            polys: Vec::new(),
        };
        let p = dir().join("mesh.vtp");
        stage_vtp(&p, &poly).unwrap().commit().unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        for needle in ["type=\"PolyData\"", "NumberOfVerts=\"2\"", "NumberOfLines=\"2\"", "<Verts>", "<Lines>"] {
            assert!(text.contains(needle), "{needle}");
        }
        let vtk = vtkio::Vtk::parse_xml(std::io::BufReader::new(std::fs::File::open(&p).unwrap())).unwrap();
        let DataSet::PolyData { pieces, .. } = vtk.data else { panic!("not poly data") };
        let Piece::Inline(piece) = &pieces[0] else { panic!("not inline") };
        assert_eq!(piece.points.cast_into::<f64>().unwrap(), poly.points.concat());
        let topo = |t: &Option<VertexNumbers>| match t.clone().unwrap() {
            VertexNumbers::XML { connectivity, offsets } => (connectivity, offsets),
            VertexNumbers::Legacy { .. } => panic!("legacy"),
        };
        assert_eq!(topo(&piece.verts), (vec![0, 3], vec![1, 2]));
        assert_eq!(topo(&piece.lines), (vec![0, 1, 2, 3, 1], vec![3, 5]));
        let Attribute::DataArray(a) = &piece.data.point[0] else { panic!() };
        assert_eq!((a.name.as_str(), a.data.cast_into::<f64>().unwrap()), ("value", poly.point_arrays[0].1.clone()));
        let Attribute::DataArray(c) = &piece.data.cell[0] else { panic!() };
        assert_eq!((c.name.as_str(), c.data.cast_into::<f64>().unwrap()), ("kind", poly.cell_arrays[0].1.clone()));
        // empty cell lists are valid too
        let only_points = PolyData { points: poly.points.clone(), ..Default::default() };
        let q = dir().join("points.vtp");
        stage_vtp(&q, &only_points).unwrap().commit().unwrap();
        vtkio::Vtk::parse_xml(std::io::BufReader::new(std::fs::File::open(&q).unwrap())).unwrap();
        // argument errors
        let bad = PolyData { lines: vec![vec![0, 9]], ..poly.clone() };
        let e = stage_vtp(&p, &bad).err().unwrap().to_string();
        assert!(e.contains("mesh.vtp") && e.contains("point 9"), "{e}");
        let bad = PolyData { cell_arrays: vec![("kind".into(), vec![1.0])], ..poly };
        let e = stage_vtp(&p, &bad).err().unwrap().to_string();
        assert!(e.contains("`kind`") && e.contains("4 cells"), "{e}");
    }
}
