//! The VTK XML reader: image data (`.vti`), poly data (`.vtp`) and unstructured grids
//! (`.vtu`), in every layout VTK writes: ascii, inline base64, appended base64 or raw;
//! uncompressed, zlib, lz4 or lzma; UInt32 or UInt64 headers; either byte order.
//!
//! quick-xml reads the markup up to the `<AppendedData>` tag (raw appended data is not XML);
//! the arrays are decoded by [`super::decode`], whose size checks run before any allocation.

use super::data::{CellTypes, Dataset, ImageGeometry, PointArray, PolySection};
use super::decode::{parse_ascii, read_block, Base64Stream, Compressor, Encoding, Numbers, RawStream, Scalar, Shape};
use crate::error::{Error, Location, Result};

type Attrs = Vec<(String, String)>;

pub(super) fn attrs(e: &quick_xml::events::BytesStart) -> Result<Attrs> {
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
    match parsed.map(<[T; N]>::try_from) {
        Some(Ok(v)) => Ok(v),
        _ => Err(Error::input(format!("{what} must be {N} numbers, found `{s}`"))),
    }
}

/// The sections of a piece that hold data arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Section {
    PointData,
    CellData,
    Points,
    Cells,
    Poly(PolySection),
}

impl Section {
    fn of(tag: &[u8]) -> Option<Section> {
        Some(match tag {
            b"PointData" => Section::PointData,
            b"CellData" => Section::CellData,
            b"Points" => Section::Points,
            b"Cells" => Section::Cells,
            b"Verts" => Section::Poly(PolySection::Verts),
            b"Lines" => Section::Poly(PolySection::Lines),
            b"Polys" => Section::Poly(PolySection::Polys),
            b"Strips" => Section::Poly(PolySection::Strips),
            _ => return None,
        })
    }
}

#[derive(Debug)]
enum Format {
    Ascii,
    Binary,
    Appended(usize),
}

/// A `<DataArray>` as declared, with its inline text.
#[derive(Debug)]
struct ArrayDecl {
    name: String,
    /// None for a type that is not numeric (String, Bit).
    ty: Option<Scalar>,
    /// The `type` attribute as written.
    ty_text: String,
    components: usize,
    format: Format,
    text: Vec<u8>,
}

/// A `<Piece>`: its attributes and its arrays, by section.
#[derive(Debug, Default)]
struct PieceDecl {
    attrs: Attrs,
    arrays: Vec<(Section, ArrayDecl)>,
    /// The `Scalars` attribute of `<PointData>`: the active scalars.
    active_scalars: Option<String>,
}

impl PieceDecl {
    fn array(&self, section: Section, name: &str) -> Option<&ArrayDecl> {
        self.arrays.iter().find(|(s, a)| *s == section && a.name == name).map(|(_, a)| a)
    }

    fn first(&self, section: Section) -> Option<&ArrayDecl> {
        self.arrays.iter().find(|(s, _)| *s == section).map(|(_, a)| a)
    }

    /// A count attribute (`NumberOfPoints`, ...); absent means 0.
    fn count(&self, key: &str) -> Result<usize> {
        match get(&self.attrs, key) {
            None => Ok(0),
            Some(v) => v
                .trim()
                .parse()
                .map_err(|_| Error::input(format!("<Piece> attribute {key}=\"{v}\" is not a non-negative integer"))),
        }
    }
}

/// The markup: the `<VTKFile>` and data set attributes, and the pieces.
struct Markup {
    file_attrs: Option<Attrs>,
    kind: String,
    dataset_attrs: Attrs,
    pieces: Vec<PieceDecl>,
    appended_encoding: Option<String>,
}

/// Where the appended data is and how it is encoded.
struct Appended<'a> {
    /// The bytes after the `_` marker, if there is appended data.
    data: Option<&'a [u8]>,
    base64: bool,
}

/// Reads a VTK XML file of image data, poly data or an unstructured grid.
pub(super) fn read_xml(bytes: &[u8]) -> Result<Dataset> {
    // Appended data may be raw binary, which is not XML: parse the markup up to and including
    // the <AppendedData ...> start tag only.
    let (markup, after) = match find(bytes, b"<AppendedData") {
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
    let m = scan_markup(markup)?;
    let file_attrs = m.file_attrs.as_deref().ok_or_else(|| Error::input("no <VTKFile> element: not a VTK XML file"))?;
    let enc = encoding_of(file_attrs)?;
    let appended = Appended {
        data: after.map(|close| appended_start(bytes, close)).transpose()?,
        base64: match m.appended_encoding.as_deref().unwrap_or("raw") {
            "raw" => false,
            "base64" => true,
            e => return Err(Error::input(format!("unknown AppendedData encoding `{e}` (expected raw or base64)"))),
        },
    };
    let reader = Decoder { enc, appended };
    if m.pieces.is_empty() {
        return Err(Error::input(format!("the {} has no <Piece> (truncated file?)", m.kind)));
    }
    match m.kind.as_str() {
        "ImageData" => image(&m, &reader),
        "PolyData" | "UnstructuredGrid" => {
            let mut ds = Dataset::default();
            for (k, piece) in m.pieces.iter().enumerate() {
                let at = if m.pieces.len() > 1 { format!("piece {}: ", k + 1) } else { String::new() };
                mesh_piece(piece, m.kind == "PolyData", &reader, &mut ds).map_err(|e| prefix(e, &at))?;
            }
            Ok(ds)
        }
        other => Err(Error::input(format!("unexpected data set <{other}>"))),
    }
}

fn prefix(e: Error, at: &str) -> Error {
    match e {
        Error::Input { path, at: loc, message } if !at.is_empty() => {
            Error::Input { path, at: loc, message: format!("{at}{message}") }
        }
        e => e,
    }
}

/// Decodes the declared arrays.
struct Decoder<'a> {
    enc: Encoding,
    appended: Appended<'a>,
}

impl Decoder<'_> {
    fn numbers(&self, decl: &ArrayDecl, tuples: Option<usize>, of: &str, what: &str) -> Result<Numbers> {
        let ty = decl.ty.ok_or_else(|| {
            Error::input(if decl.ty_text.is_empty() {
                format!("{what} has no `type`")
            } else {
                format!("{what} has type {}, which is not numeric", decl.ty_text)
            })
        })?;
        let shape = Shape { tuples, components: decl.components, ty, of };
        match decl.format {
            Format::Ascii => parse_ascii(ty, &decl.text, shape.count(what)?, what),
            Format::Binary => read_block(&mut Base64Stream::new(&decl.text), self.enc, shape, what),
            Format::Appended(offset) => {
                let data = self
                    .appended
                    .data
                    .ok_or_else(|| Error::input(format!("{what} is appended but the file has no <AppendedData>")))?;
                let rest = data.get(offset..).ok_or_else(|| {
                    Error::input(format!(
                        "truncated: {what} starts at offset {offset}, past the end of the appended data"
                    ))
                })?;
                if self.appended.base64 {
                    read_block(&mut Base64Stream::new(rest), self.enc, shape, what)
                } else {
                    read_block(&mut RawStream { data: rest, pos: 0 }, self.enc, shape, what)
                }
            }
        }
    }

    /// A point or cell data array (`tuples` of them), as f64.
    fn data_array(&self, decl: &ArrayDecl, tuples: usize, of: &str) -> Result<PointArray> {
        let what = format!("{} array `{}`", if of == "cells" { "cell" } else { "point" }, decl.name);
        let values = self.numbers(decl, Some(tuples), of, &what)?.into_f64(&what)?;
        Ok(PointArray {
            name: decl.name.clone(),
            components: decl.components,
            values,
            ty: decl.ty.unwrap_or(Scalar::F64),
        })
    }

    /// The arrays of a data section that are numeric, and the names of those that are not.
    fn section(
        &self,
        piece: &PieceDecl,
        section: Section,
        tuples: usize,
        of: &str,
        ds_skipped: &mut Vec<String>,
    ) -> Result<Vec<PointArray>> {
        let mut out = Vec::new();
        for (s, decl) in &piece.arrays {
            if *s != section {
                continue;
            }
            if decl.ty.is_none() {
                ds_skipped.push(format!("`{}` ({})", decl.name, decl.ty_text));
                continue;
            }
            out.push(self.data_array(decl, tuples, of)?);
        }
        Ok(out)
    }

    fn indices(&self, decl: &ArrayDecl, tuples: Option<usize>, what: &str) -> Result<Vec<usize>> {
        self.numbers(decl, tuples, "values", what)?.into_indices(what)
    }
}

fn image(m: &Markup, reader: &Decoder) -> Result<Dataset> {
    if m.pieces.len() > 1 {
        return Err(Error::input(format!(
            "the image is split into {} pieces; only single-piece files are supported",
            m.pieces.len()
        )));
    }
    let piece = &m.pieces[0];
    let a = &m.dataset_attrs;
    let extent_text = get(&piece.attrs, "Extent")
        .or_else(|| get(a, "WholeExtent"))
        .ok_or_else(|| Error::input("<ImageData> has no WholeExtent"))?;
    let extent: [i64; 6] = parse_numbers(extent_text, "the extent")?;
    let origin = match get(a, "Origin") {
        Some(o) => parse_numbers(o, "Origin")?,
        None => [0.0; 3],
    };
    let spacing = match get(a, "Spacing") {
        Some(s) => parse_numbers(s, "Spacing")?,
        None => [1.0; 3],
    };
    let direction = match get(a, "Direction") {
        Some(d) => parse_numbers(d, "Direction")?,
        None => [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
    };
    let geometry = ImageGeometry { extent, origin, spacing, direction };
    let [nx, ny, nz] = geometry.dims();
    let n = nx
        .checked_mul(ny)
        .and_then(|v| v.checked_mul(nz))
        .ok_or_else(|| Error::input(format!("the extent `{extent_text}` is too large")))?;
    let mut ds = Dataset { image: Some(geometry), ..Dataset::default() };
    ds.point_data = reader.section(piece, Section::PointData, n, "points", &mut ds.skipped)?;
    let cells = [nx, ny, nz].iter().map(|&d| d.saturating_sub(1).max(1)).product();
    ds.cell_data = reader.section(piece, Section::CellData, cells, "cells", &mut ds.skipped)?;
    ds.active_scalars = piece.active_scalars.clone();
    Ok(ds)
}

/// Appends one poly data or unstructured grid piece to `ds`.
fn mesh_piece(piece: &PieceDecl, poly: bool, reader: &Decoder, ds: &mut Dataset) -> Result<()> {
    let n = piece.count("NumberOfPoints")?;
    let base = ds.points.len();
    let cells_before = ds.cells.len();
    if n > 0 {
        let decl =
            piece.first(Section::Points).ok_or_else(|| Error::input("the piece has points but no <Points> array"))?;
        if decl.components != 3 {
            return Err(Error::input(format!("the points have {} components instead of 3", decl.components)));
        }
        let xyz = reader
            .numbers(decl, Some(n), "points", "the array of point coordinates")?
            .into_f64("the array of point coordinates")?;
        ds.points.extend(xyz.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
    }
    if poly {
        for (section, key, name) in [
            // VTK numbers poly data cells in this order
            (PolySection::Verts, "NumberOfVerts", "verts"),
            (PolySection::Lines, "NumberOfLines", "lines"),
            (PolySection::Polys, "NumberOfPolys", "polys"),
            (PolySection::Strips, "NumberOfStrips", "strips"),
        ] {
            let count = piece.count(key)?;
            cell_section(piece, Section::Poly(section), count, CellTypes::PolyData(section), name, base, reader, ds)?;
        }
    } else {
        let count = piece.count("NumberOfCells")?;
        let types = match piece.array(Section::Cells, "types") {
            Some(decl) if count > 0 => {
                let t = reader.indices(decl, Some(count), "the cell types")?;
                let t: Option<Vec<u8>> = t.iter().map(|&v| u8::try_from(v).ok()).collect();
                CellTypes::Each(t.ok_or_else(|| Error::input("the cell types: a type code above 255"))?)
            }
            None if count > 0 => return Err(Error::input("the <Cells> have no `types` array")),
            _ => CellTypes::Each(Vec::new()),
        };
        cell_section(piece, Section::Cells, count, types, "cells", base, reader, ds)?;
    }
    let point_data = reader.section(piece, Section::PointData, n, "points", &mut ds.skipped)?;
    merge_arrays(&mut ds.point_data, point_data, base == 0)?;
    let cell_data =
        reader.section(piece, Section::CellData, ds.cells.len() - cells_before, "cells", &mut ds.skipped)?;
    merge_arrays(&mut ds.cell_data, cell_data, base == 0 && cells_before == 0)?;
    if base == 0 {
        ds.active_scalars = piece.active_scalars.clone();
    }
    Ok(())
}

/// One section of cells: `connectivity` and `offsets` (VTK's end offsets; a leading 0, as
/// some writers add, is accepted).
#[allow(clippy::too_many_arguments)]
fn cell_section(
    piece: &PieceDecl,
    section: Section,
    count: usize,
    types: CellTypes,
    name: &str,
    base: usize,
    reader: &Decoder,
    ds: &mut Dataset,
) -> Result<()> {
    if count == 0 {
        return Ok(());
    }
    let need = |array: &str| {
        piece.array(section, array).ok_or_else(|| Error::input(format!("the {name} have no `{array}` array")))
    };
    let mut ends = reader.indices(need("offsets")?, None, &format!("the {name}' offsets"))?;
    if ends.len() == count + 1 && ends.first() == Some(&0) {
        ends.remove(0);
    }
    if ends.len() != count {
        return Err(Error::input(format!("the {name}' offsets hold {} values for {count} cells", ends.len())));
    }
    let total = ends.last().copied().unwrap_or(0);
    let conn = reader.indices(need("connectivity")?, Some(total), &format!("the {name}' connectivity"))?;
    if let Some((k, &v)) = conn.iter().enumerate().find(|(_, &v)| v >= ds.points.len() - base) {
        return Err(Error::input(format!(
            "the {name}' connectivity: entry {} refers to point {v}, but the piece has {} points",
            k + 1,
            ds.points.len() - base
        )));
    }
    ds.cells.append(&conn, &ends, types, base, &format!("the {name}"))
}

/// Appends a piece's arrays to those of the pieces before (the first piece sets the list).
fn merge_arrays(all: &mut Vec<PointArray>, piece: Vec<PointArray>, first: bool) -> Result<()> {
    if first {
        *all = piece;
        return Ok(());
    }
    let names = |v: &[PointArray]| v.iter().map(|a| format!("{}({})", a.name, a.components)).collect::<Vec<_>>();
    if names(all) != names(&piece) {
        return Err(Error::input(format!(
            "the pieces carry different arrays ({} and {})",
            names(all).join(", "),
            names(&piece).join(", ")
        )));
    }
    for (a, p) in all.iter_mut().zip(piece) {
        if a.ty != p.ty {
            // every value is exact in Float64 (larger integers were refused)
            a.ty = Scalar::F64;
        }
        a.values.extend(p.values);
    }
    Ok(())
}

/// A point array's declaration from its `<DataArray>` attributes.
fn array_decl(a: &[(String, String)]) -> Result<ArrayDecl> {
    let name = get(a, "Name").unwrap_or("").to_string();
    let ty_text = get(a, "type").unwrap_or("").to_string();
    let ty = Scalar::from_xml(&ty_text);
    let components = match get(a, "NumberOfComponents") {
        None => 1,
        Some(c) => c.trim().parse::<usize>().ok().filter(|&c| c > 0).ok_or_else(|| {
            Error::input(format!("array `{name}`: NumberOfComponents `{c}` is not a positive integer"))
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
                    .map_err(|_| Error::input(format!("array `{name}`: offset `{off}` is not an integer")))?,
            )
        }
        f => return Err(Error::input(format!("array `{name}` has unknown format `{f}`"))),
    };
    Ok(ArrayDecl { name, ty, ty_text, components, format, text: Vec::new() })
}

/// Checks the `<VTKFile>` element: the data set type it declares.
fn file_kind(a: &Attrs) -> Result<String> {
    match get(a, "type") {
        Some(t @ ("ImageData" | "PolyData" | "UnstructuredGrid")) => Ok(t.to_string()),
        Some(t) if t.starts_with('P') => {
            Err(Error::input(format!("this is a parallel file ({t}) that only points to piece files: read the pieces")))
        }
        Some(t) => Err(Error::input(format!(
            "the data set is {t}: only ImageData (.vti), PolyData (.vtp) and UnstructuredGrid (.vtu) are read \
             (ParaView: Resample To Image, or Extract Surface then Triangulate)"
        ))),
        None => Err(Error::input("<VTKFile> has no `type`")),
    }
}

/// The state of the markup scan: what has been declared, and where the scan is.
struct Scan {
    m: Markup,
    /// Open elements; text belongs to a `<DataArray>` only when it is the innermost one.
    stack: Vec<Vec<u8>>,
    section: Option<Section>,
    current: Option<(Section, ArrayDecl)>,
}

impl Scan {
    fn start(&mut self, e: &quick_xml::events::BytesStart, empty: bool) -> Result<()> {
        let name = e.name().as_ref().to_vec();
        let m = &mut self.m;
        let parent = self.stack.last().map(Vec::as_slice);
        match name.as_slice() {
            b"VTKFile" => {
                let a = attrs(e)?;
                m.kind = file_kind(&a)?;
                m.file_attrs = Some(a);
            }
            b"Piece" if parent.is_some_and(|p| p == m.kind.as_bytes()) => {
                m.pieces.push(PieceDecl { attrs: attrs(e)?, ..PieceDecl::default() })
            }
            b"AppendedData" => m.appended_encoding = get(&attrs(e)?, "encoding").map(str::to_string),
            b"DataArray" => {
                if let (Some(s), Some(piece)) = (self.section, m.pieces.last_mut()) {
                    let decl = array_decl(&attrs(e)?)?;
                    if empty {
                        piece.arrays.push((s, decl));
                    } else {
                        self.current = Some((s, decl));
                    }
                }
            }
            n if !m.kind.is_empty() && n == m.kind.as_bytes() && parent == Some(b"VTKFile") => {
                m.dataset_attrs = attrs(e)?
            }
            n if parent == Some(b"Piece") => {
                self.section = Section::of(n);
                if self.section == Some(Section::PointData) {
                    let scalars = get(&attrs(e)?, "Scalars").map(str::to_string);
                    if let Some(p) = m.pieces.last_mut() {
                        p.active_scalars = scalars;
                    }
                }
            }
            _ => {}
        }
        if !empty {
            self.stack.push(name);
        }
        Ok(())
    }

    fn text(&mut self, t: &[u8]) {
        if let (Some((_, c)), Some(b"DataArray")) = (self.current.as_mut(), self.stack.last().map(Vec::as_slice)) {
            c.text.extend_from_slice(t);
        }
    }

    fn end(&mut self, name: &[u8]) {
        if self.stack.last().is_some_and(|n| n == name) {
            self.stack.pop();
        }
        let parent = self.stack.last();
        if name == b"DataArray" && parent.is_some_and(|p| Section::of(p).is_some()) {
            if let (Some(c), Some(p)) = (self.current.take(), self.m.pieces.last_mut()) {
                p.arrays.push(c);
            }
        } else if Section::of(name).is_some() && parent.is_some_and(|p| p == b"Piece") {
            self.section = None;
        }
    }
}

/// Reads the markup (up to the `<AppendedData>` start tag).
fn scan_markup(markup: &[u8]) -> Result<Markup> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_reader(markup);
    let m = Markup {
        file_attrs: None,
        kind: String::new(),
        dataset_attrs: Vec::new(),
        pieces: Vec::new(),
        appended_encoding: None,
    };
    let mut scan = Scan { m, stack: Vec::new(), section: None, current: None };
    loop {
        let event = reader.read_event().map_err(|e| {
            let at = reader.error_position();
            let cut = if reader.buffer_position() >= markup.len() as u64 {
                "truncated: the file ends inside the markup; "
            } else {
                ""
            };
            Error::input(format!("{cut}malformed XML near byte {at}: {e}")).at(Location::Byte(at))
        })?;
        match &event {
            Event::Start(e) => scan.start(e, false)?,
            Event::Empty(e) => scan.start(e, true)?,
            Event::Text(t) => scan.text(t),
            Event::CData(t) => scan.text(t),
            Event::End(e) => scan.end(e.name().as_ref()),
            Event::Eof => {
                if let Some((_, c)) = scan.current {
                    return Err(Error::input(format!("truncated: the file ends inside array `{}`", c.name)));
                }
                break;
            }
            _ => {}
        }
    }
    let m = scan.m;
    if m.file_attrs.is_some() && m.dataset_attrs.is_empty() && m.pieces.is_empty() {
        return Err(Error::input(format!("no <{}> element (truncated file?)", m.kind)));
    }
    Ok(m)
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
        compressor: match get(file_attrs, "compressor").map(str::trim).unwrap_or("") {
            "" => Compressor::None,
            "vtkZLibDataCompressor" => Compressor::Zlib,
            "vtkLZ4DataCompressor" => Compressor::Lz4,
            "vtkLZMADataCompressor" => Compressor::Lzma,
            c => {
                return Err(Error::input(format!(
                    "data compressed with `{c}`, which is not supported: VTK's compressors are \
                     vtkZLibDataCompressor, vtkLZ4DataCompressor and vtkLZMADataCompressor"
                )))
            }
        },
    })
}

pub(super) fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
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
