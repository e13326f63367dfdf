//! NIfTI-1 volumes (`.nii`, `.nii.gz`): reading one 3-D scalar volume with its geometry
//! ([`read_nifti`], [`read_nifti_frame`]) and writing a float64 volume ([`write_nifti`],
//! [`stage_nifti`]).
//!
//! # Reading
//! A single-file NIfTI-1 image (magic `n+1`), gzip-compressed or not: compression is
//! recognised from the content (the gzip magic bytes), not from the name. The byte order is
//! the one in which `sizeof_hdr` reads 348. The 348 header bytes are parsed by the `nifti`
//! crate (without its `ndarray` feature); the data are read here, from byte `vox_offset` on
//! (extensions and padding before it are skipped), and converted to f64:
//! uint8, int8, int16, uint16, int32, uint32, float32 and float64 are read, every other
//! datatype is refused by name. `scl_slope`/`scl_inter` are applied (in f64) when the slope is
//! finite and not 0, as the standard says, except the identity (slope 1, intercept 0), which
//! is skipped so that float data (−0.0 included) come back bit for bit.
//!
//! Values are in storage order: voxel `(i, j, k)` is `values[i + nx·(j + ny·k)]`, the order
//! of a VTK image (x fastest). Float data may hold NaN or infinite values: they are returned
//! as they are, for the caller to refuse or fill.
//!
//! The geometry follows the standard's three methods, in its order of precedence:
//! - `sform_code > 0`: the affine is the `srow_x`, `srow_y`, `srow_z` rows;
//! - else `qform_code > 0`: the quaternion (`quatern_b`, `_c`, `_d`, `a` = √(1 − b² − c² − d²))
//!   gives a rotation R, and the affine is R · diag(dx, dy, qfac · dz) with offsets
//!   `qoffset_x`, `_y`, `_z` (`qfac` = −1 when `pixdim[0] < 0`, else 1);
//! - else `diag(dx, dy, dz)` with no translation (the standard's "method 1").
//!
//! Here dx, dy, dz are the spacings |pixdim[1..4]| (SPEC.md: spacings are magnitudes; the
//! affine carries the orientation).
//!
//! # Writing
//! A little-endian single-file NIfTI-1 image of float64 voxels (`scl_slope` 1, `scl_inter` 0),
//! gzip-compressed when the file name ends in `.gz`. The affine is stored as the sform
//! (`sform_code` 1, scanner coordinates) and, when it is a rotation (proper or not) times the
//! diagonal of the spacings, as the matching quaternion qform too (`qform_code` 1); otherwise
//! `qform_code` is 0. `pixdim[1..4]` are the spacings' magnitudes. NIfTI-1 stores the affine
//! and the spacings as float32: they read back exactly when they are float32 numbers, else
//! rounded to the nearest one. The output goes through [`crate::io::staging`] (a temporary
//! file renamed into place).
//!
//! The `nifti` crate's own writer is not used: it needs its `ndarray` feature and writes only
//! to a path it opens itself (changing the name's extension), which the staging machinery
//! cannot hand it. Its object reader is not used either: it chooses gzip by the file name and
//! does not skip the bytes between the header and `vox_offset` when the file has no extension.

use super::Staged;
use crate::error::{Error, Result};
use std::io::{Read, Write};
use std::path::Path;

/// Size of a NIfTI-1 header.
const HEADER_SIZE: usize = 348;
/// Where the data of a file written here start (the header and a 4-byte extender of zeros).
const DATA_OFFSET: usize = 352;
/// Relative tolerance of the geometric tests (obliqueness, a rotation times a diagonal):
/// the header stores float32 numbers (relative precision 6e-8).
const TOLERANCE: f64 = 1e-6;

/// One 3-D volume read from a NIfTI-1 file.
#[derive(Clone, Debug, PartialEq)]
pub struct NiftiVolume {
    /// Voxels along the three index axes (nx, ny, nz); a 2-D file has nz = 1.
    pub dims: [usize; 3],
    /// The number of frames (`dim[4]`) in the file; [`NiftiVolume::values`] holds one.
    pub frames: usize,
    /// The frame read (0-based; 0 for a 3-D file).
    pub frame: usize,
    /// Spacing along the index axes: |pixdim[1]|, |pixdim[2]|, |pixdim[3]| (positive). An axis
    /// beyond the file's dimensions (z of a 2-D file) whose pixdim is 0 or not finite gets 1.
    pub spacing: [f64; 3],
    /// Voxel (i, j, k) to world: `world[r] = affine[r][0]·i + affine[r][1]·j +
    /// affine[r][2]·k + affine[r][3]` (see the module documentation for where it comes from).
    pub affine: [[f64; 4]; 3],
    /// Which header fields gave the affine: `"sform"`, `"qform"` or `"pixdim"`.
    pub affine_source: &'static str,
    /// Whether the affine's 3 × 3 part is not a signed permutation times a diagonal, i.e. the
    /// index axes are not along the world axes ([`is_oblique`]).
    pub oblique: bool,
    /// The datatype stored in the file: `"uint8"`, `"int8"`, `"int16"`, `"uint16"`, `"int32"`,
    /// `"uint32"`, `"float32"` or `"float64"`.
    pub datatype: String,
    /// `nx · ny · nz` values in storage order (`i + nx·(j + ny·k)`), scaled by
    /// `scl_slope`/`scl_inter` when the file asks for it.
    pub values: Vec<f64>,
    /// The header's `descrip` field (up to its first NUL byte, trimmed).
    pub description: String,
}

impl NiftiVolume {
    /// The world position of voxel (0, 0, 0): the affine's translation. Use it as a VTK image's
    /// origin; older VTK readers have no `Direction`, so an image written with this origin
    /// and the spacings is placed correctly only when [`NiftiVolume::direction`] is the
    /// identity (no flip, permutation or rotation).
    pub fn origin(&self) -> [f64; 3] {
        [self.affine[0][3], self.affine[1][3], self.affine[2][3]]
    }

    /// The direction cosines: `direction()[r][c]` is world component `r` of index axis `c`
    /// (the affine's column `c` divided by its length). A negative diagonal entry is an axis
    /// flip (x runs right to left in a typical radiological file); with VTK's `Direction`
    /// attribute in row-major order this is `[d[0][0], d[0][1], d[0][2], d[1][0], …]`.
    pub fn direction(&self) -> [[f64; 3]; 3] {
        direction_of(&self.affine)
    }
}

/// The affine's 3 × 3 part with its columns scaled to unit length (a zero column stays 0).
fn direction_of(affine: &[[f64; 4]; 3]) -> [[f64; 3]; 3] {
    let mut d = [[0.0; 3]; 3];
    for c in 0..3 {
        let norm = column_norm(affine, c);
        for r in 0..3 {
            d[r][c] = if norm > 0.0 { affine[r][c] / norm } else { 0.0 };
        }
    }
    d
}

fn column_norm(affine: &[[f64; 4]; 3], c: usize) -> f64 {
    (0..3).map(|r| affine[r][c] * affine[r][c]).sum::<f64>().sqrt()
}

/// Whether the affine's 3 × 3 part is *not* a signed permutation times a diagonal: some index
/// axis has more than one world component larger than 10⁻⁶ times its length, or two index
/// axes lie along the same world axis.
pub fn is_oblique(affine: &[[f64; 4]; 3]) -> bool {
    let mut used = [false; 3];
    for c in 0..3 {
        let norm = column_norm(affine, c);
        let mut along = (0..3).filter(|&r| affine[r][c].abs() > TOLERANCE * norm);
        match (along.next(), along.next()) {
            (Some(r), None) if !used[r] => used[r] = true,
            _ => return true,
        }
    }
    false
}

/// Reads a 3-D NIfTI-1 volume (`.nii` or `.nii.gz`; see the module documentation). A 4-D file
/// with one frame is read as its 3-D volume; one with several frames is refused (see
/// [`read_nifti_frame`]).
///
/// # Errors
/// Input errors naming the file: not a NIfTI-1 file (a bad `sizeof_hdr` or magic, a NIfTI-2
/// or `.hdr`/`.img` header), corrupt gzip data, truncated data, an unsupported datatype (named),
/// an extent of 0 or more than four dimensions with extent > 1, a NaN, infinite or zero
/// pixdim of a data axis, a bad `vox_offset`, a non-finite or singular affine, a valid slope
/// with a non-finite intercept, a 4-D file with several frames. I/O errors for an unreadable
/// file.
pub fn read_nifti(path: &Path) -> Result<NiftiVolume> {
    read(path, None)
}

/// Reads frame `frame` (0-based) of a 4-D NIfTI-1 file (a time series of volumes), or the
/// volume of a 3-D file when `frame` is 0.
///
/// # Errors
/// As [`read_nifti`], except that several frames are allowed; a frame the file does not have.
pub fn read_nifti_frame(path: &Path, frame: usize) -> Result<NiftiVolume> {
    read(path, Some(frame))
}

fn read(path: &Path, frame: Option<usize>) -> Result<NiftiVolume> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    super::guarded(path, || parse_nifti(&bytes, frame))
}

/// Parses a NIfTI-1 file held in memory (gzip-compressed or not): frame `frame`, or the only
/// frame when `frame` is `None`.
///
/// # Errors
/// As [`read_nifti_frame`] (or [`read_nifti`] for `None`), without the file name.
pub fn parse_nifti(bytes: &[u8], frame: Option<usize>) -> Result<NiftiVolume> {
    let gz = bytes.starts_with(&[0x1f, 0x8b]);
    let mut source: Box<dyn Read + '_> =
        if gz { Box::new(flate2::read::MultiGzDecoder::new(bytes)) } else { Box::new(bytes) };
    let mut head = [0u8; HEADER_SIZE];
    let got = read_up_to(&mut source, &mut head)?;
    let stream = if gz { " (after gzip decompression)" } else { "" };
    if got < HEADER_SIZE {
        return Err(Error::input(format!(
            "not a NIfTI-1 file: {got} bytes{stream}, fewer than the 348 of a NIfTI-1 header"
        )));
    }
    let header = Header::parse(&head)?;
    let g = header.geometry(frame)?;
    // the whole file must be there (every frame), not only the frame read
    let total = g.frame_bytes.checked_mul(g.frames).and_then(|b| g.offset.checked_add(b)).ok_or_else(|| {
        Error::input(format!("the dimensions {} give more data than can be addressed", header.dims_text()))
    })?;
    let data: std::borrow::Cow<[u8]> = if gz {
        let mut all = head.to_vec();
        let rest = (total - HEADER_SIZE) as u64;
        source.take(rest).read_to_end(&mut all).map_err(gzip_error)?;
        all.into()
    } else {
        bytes.into()
    };
    if data.len() < total {
        let present = data.len().saturating_sub(g.offset);
        return Err(Error::input(format!(
            "truncated: the header describes {} of {} {} voxels ({} bytes from byte {}), but the file{stream} has \
             {present} bytes of data",
            plural(g.frames, "frame"),
            header.dims_text(),
            g.type_name,
            total - g.offset,
            g.offset
        )));
    }
    let start = g.offset + g.frame * g.frame_bytes;
    let mut values = decode(&data[start..start + g.frame_bytes], header.h.datatype, header.big);
    header.scale(&mut values)?;
    let (affine, affine_source) = header.affine(g.spacing)?;
    Ok(NiftiVolume {
        dims: g.dims,
        frames: g.frames,
        frame: g.frame,
        spacing: g.spacing,
        oblique: is_oblique(&affine),
        affine,
        affine_source,
        datatype: g.type_name.to_string(),
        values,
        description: header.description(),
    })
}

fn gzip_error(e: std::io::Error) -> Error {
    Error::input(format!("the gzip data are corrupt: {e}"))
}

fn plural(n: usize, what: &str) -> String {
    if n == 1 {
        format!("1 {what}")
    } else {
        format!("{n} {what}s")
    }
}

/// Reads until `buf` is full or the source ends; the number of bytes read.
fn read_up_to(source: &mut dyn Read, buf: &mut [u8]) -> Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match source.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(gzip_error(e)),
        }
    }
    Ok(got)
}

/// The datatypes read: NIfTI code, name, bytes per voxel.
const DATATYPES: [(i16, &str, usize); 8] = [
    (2, "uint8", 1),
    (256, "int8", 1),
    (4, "int16", 2),
    (512, "uint16", 2),
    (8, "int32", 4),
    (768, "uint32", 4),
    (16, "float32", 4),
    (64, "float64", 8),
];

/// A parsed header and its byte order.
struct Header {
    h: ::nifti::NiftiHeader,
    big: bool,
}

/// What the header says about the data to read.
struct Geometry {
    dims: [usize; 3],
    spacing: [f64; 3],
    frames: usize,
    frame: usize,
    offset: usize,
    frame_bytes: usize,
    type_name: &'static str,
}

impl Header {
    /// Checks `sizeof_hdr` (which gives the byte order) and the magic, then parses the fields.
    fn parse(head: &[u8; HEADER_SIZE]) -> Result<Header> {
        let size = [head[0], head[1], head[2], head[3]];
        let (le, be) = (i32::from_le_bytes(size), i32::from_be_bytes(size));
        let big = match (le, be) {
            (348, _) => false,
            (_, 348) => true,
            (540, _) | (_, 540) => {
                return Err(Error::input("a NIfTI-2 file (sizeof_hdr 540): toposmooth reads NIfTI-1 files"))
            }
            _ => {
                return Err(Error::input(format!(
                    "not a NIfTI-1 file: sizeof_hdr (the first 4 bytes) is {le} (byte-swapped {be}), not 348"
                )))
            }
        };
        match &head[344..348] {
            b"n+1\0" => {}
            b"ni1\0" => {
                return Err(Error::input(
                    "a NIfTI-1 header without data (magic `ni1`, the header of a .hdr/.img pair): toposmooth \
                     reads single-file .nii and .nii.gz images",
                ))
            }
            m => {
                return Err(Error::input(format!(
                    "not a NIfTI-1 file: the magic (bytes 344-347) is \"{}\", not \"n+1\"",
                    m.escape_ascii()
                )))
            }
        }
        let dim0 =
            if big { i16::from_be_bytes([head[40], head[41]]) } else { i16::from_le_bytes([head[40], head[41]]) };
        if !(1..=7).contains(&dim0) {
            return Err(Error::input(format!("dim[0] = {dim0}: the number of dimensions must be 1 to 7")));
        }
        let h = ::nifti::NiftiHeader::from_reader(&head[..])
            .map_err(|e| Error::input(format!("not a readable NIfTI-1 header: {e}")))?;
        if (h.endianness == ::nifti::Endianness::Big) != big {
            return Err(Error::internal("the NIfTI header parser chose another byte order than sizeof_hdr gives"));
        }
        Ok(Header { h, big })
    }

    /// The number of dimensions (1 to 7, checked in [`Header::parse`]).
    fn ndim(&self) -> usize {
        usize::from(self.h.dim[0])
    }

    /// Extent along dimension `d` (1-based): `dim[d]` for the file's dimensions, 1 beyond.
    fn extent(&self, d: usize) -> i64 {
        if d <= self.ndim() {
            i64::from(self.h.dim[d] as i16)
        } else {
            1
        }
    }

    fn dims_text(&self) -> String {
        (1..=self.ndim().max(3)).map(|d| self.extent(d).to_string()).collect::<Vec<_>>().join(" × ")
    }

    fn geometry(&self, frame: Option<usize>) -> Result<Geometry> {
        let h = &self.h;
        let n = self.ndim();
        for d in 1..=n {
            let e = self.extent(d);
            if e <= 0 {
                return Err(Error::input(format!(
                    "dim[{d}] = {e} (dimensions {}): every extent must be at least 1",
                    self.dims_text()
                )));
            }
        }
        let beyond: Vec<String> = (5..=7).filter(|&d| self.extent(d) > 1).map(|d| format!("dim[{d}]")).collect();
        if !beyond.is_empty() {
            return Err(Error::input(format!(
                "{n}-D data (dimensions {}, {} > 1): toposmooth reads 3-D volumes, or one frame of a 4-D series",
                self.dims_text(),
                beyond.join(", ")
            )));
        }
        let dims = [1, 2, 3].map(|d| self.extent(d) as usize);
        let frames = self.extent(4) as usize;
        let frame = match frame {
            None if frames > 1 => {
                return Err(Error::input(format!(
                    "a 4-D file with {frames} frames (dim[4] = {frames}, dimensions {}): toposmooth reads one 3-D \
                     volume; choose a frame",
                    self.dims_text()
                )))
            }
            None => 0,
            Some(f) if f >= frames => {
                return Err(Error::input(format!(
                    "frame {f} does not exist: the file has {} (0 to {})",
                    plural(frames, "frame"),
                    frames - 1
                )))
            }
            Some(f) => f,
        };
        let mut spacing = [1.0; 3];
        for (a, s) in spacing.iter_mut().enumerate() {
            let p = f64::from(h.pixdim[a + 1]);
            let axis = ["x", "y", "z"][a];
            if a < n {
                if !p.is_finite() {
                    return Err(Error::input(format!(
                        "pixdim[{}] = {p}: the spacing along {axis} is not finite",
                        a + 1
                    )));
                }
                if p == 0.0 {
                    return Err(Error::input(format!("pixdim[{}] = 0: zero spacing along {axis}", a + 1)));
                }
                *s = p.abs();
            } else if p.is_finite() && p != 0.0 {
                *s = p.abs();
            }
        }
        let Some(&(_, type_name, size)) = DATATYPES.iter().find(|t| t.0 == h.datatype) else {
            let name = match h.data_type() {
                Ok(t) => format!("datatype {}", format!("{t:?}").to_lowercase()),
                Err(_) => "unknown datatype".to_string(),
            };
            return Err(Error::input(format!(
                "unsupported {name} (code {}): toposmooth reads {}",
                h.datatype,
                DATATYPES.map(|t| t.1).join(", ")
            )));
        };
        let v = f64::from(h.vox_offset);
        if !(v.is_finite() && v >= DATA_OFFSET as f64 && v.fract() == 0.0 && v <= 1e15) {
            return Err(Error::input(format!(
                "vox_offset = {v}: the data of a single-file NIfTI-1 image start at a whole byte offset of at least 352"
            )));
        }
        let frame_bytes = dims.iter().try_fold(size, |a, &d| a.checked_mul(d)).ok_or_else(|| {
            Error::input(format!("the dimensions {} give more data than can be addressed", self.dims_text()))
        })?;
        Ok(Geometry { dims, spacing, frames, frame, offset: v as usize, frame_bytes, type_name })
    }

    /// Applies `scl_slope`/`scl_inter`: when the slope is finite and not 0 (not the identity).
    fn scale(&self, values: &mut [f64]) -> Result<()> {
        let (slope, inter) = (f64::from(self.h.scl_slope), f64::from(self.h.scl_inter));
        if !slope.is_finite() || slope == 0.0 || (slope == 1.0 && inter == 0.0) {
            return Ok(());
        }
        if !inter.is_finite() {
            return Err(Error::input(format!(
                "scl_slope = {slope} with scl_inter = {inter}: the intercept is not finite"
            )));
        }
        for v in values {
            *v = *v * slope + inter;
        }
        Ok(())
    }

    /// The voxel-to-world affine and its source (see the module documentation).
    fn affine(&self, spacing: [f64; 3]) -> Result<([[f64; 4]; 3], &'static str)> {
        let h = &self.h;
        let (affine, source) = if h.sform_code > 0 {
            (sform_of(h), "sform")
        } else if h.qform_code > 0 {
            (qform_of(h, spacing), "qform")
        } else {
            let mut a = [[0.0; 4]; 3];
            for (r, row) in a.iter_mut().enumerate() {
                row[r] = spacing[r];
            }
            (a, "pixdim")
        };
        if affine.iter().flatten().any(|v| !v.is_finite()) {
            return Err(Error::input(format!("the {source} affine has a non-finite entry: {affine:?}")));
        }
        if det3(&affine) == 0.0 {
            return Err(Error::input(format!(
                "the {source} affine {affine:?} is singular (determinant 0): it does not place the voxels in 3-D"
            )));
        }
        Ok((affine, source))
    }

    fn description(&self) -> String {
        let d = &self.h.descrip;
        let end = d.iter().position(|&b| b == 0).unwrap_or(d.len());
        String::from_utf8_lossy(&d[..end]).trim().to_string()
    }
}

fn sform_of(h: &::nifti::NiftiHeader) -> [[f64; 4]; 3] {
    [h.srow_x, h.srow_y, h.srow_z].map(|row| row.map(f64::from))
}

/// The qform affine (the standard's method 2, as `nifti_quatern_to_mat44` computes it).
fn qform_of(h: &::nifti::NiftiHeader, spacing: [f64; 3]) -> [[f64; 4]; 3] {
    let (mut b, mut c, mut d) = (f64::from(h.quatern_b), f64::from(h.quatern_c), f64::from(h.quatern_d));
    let mut a = 1.0 - (b * b + c * c + d * d);
    if a < 1e-7 {
        // |(b, c, d)| ≥ 1 up to rounding: a 180° rotation; normalise (b, c, d)
        let s = 1.0 / (b * b + c * c + d * d).sqrt();
        (b, c, d, a) = (b * s, c * s, d * s, 0.0);
    } else {
        a = a.sqrt();
    }
    let r = rotation(a, b, c, d);
    let qfac = if h.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
    let scale = [spacing[0], spacing[1], qfac * spacing[2]];
    let offset = [h.quatern_x, h.quatern_y, h.quatern_z].map(f64::from);
    let mut m = [[0.0; 4]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = r[i][j] * scale[j];
        }
        m[i][3] = offset[i];
    }
    m
}

/// The rotation matrix of the unit quaternion (a, b, c, d).
fn rotation(a: f64, b: f64, c: f64, d: f64) -> [[f64; 3]; 3] {
    [
        [a * a + b * b - c * c - d * d, 2.0 * (b * c - a * d), 2.0 * (b * d + a * c)],
        [2.0 * (b * c + a * d), a * a + c * c - b * b - d * d, 2.0 * (c * d - a * b)],
        [2.0 * (b * d - a * c), 2.0 * (c * d + a * b), a * a + d * d - c * c - b * b],
    ]
}

fn det3(m: &[[f64; 4]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Converts voxels of the NIfTI datatype `code` (one of [`DATATYPES`]) to f64.
fn decode(data: &[u8], code: i16, big: bool) -> Vec<f64> {
    macro_rules! convert {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            data.chunks_exact(N)
                .map(|c| {
                    let b: [u8; N] = c.try_into().expect("chunks of N bytes");
                    f64::from(if big { <$t>::from_be_bytes(b) } else { <$t>::from_le_bytes(b) })
                })
                .collect()
        }};
    }
    match code {
        2 => convert!(u8),
        256 => convert!(i8),
        4 => convert!(i16),
        512 => convert!(u16),
        8 => convert!(i32),
        768 => convert!(u32),
        16 => convert!(f32),
        64 => convert!(f64),
        _ => unreachable!("datatype {code} is checked against DATATYPES before decoding"),
    }
}

/// The quaternion qform of `affine` when its 3 × 3 part is a rotation (proper or not) times
/// `diag(spacing)`: `(b, c, d, qfac)`, as `nifti_mat44_to_quatern` computes it. `None` for any
/// other matrix (a shear, columns whose lengths are not the spacings).
fn quaternion_of(affine: &[[f64; 4]; 3], spacing: [f64; 3]) -> Option<(f64, f64, f64, f64)> {
    let mut u = direction_of(affine);
    for (c, s) in spacing.iter().enumerate() {
        if (column_norm(affine, c) - s).abs() > TOLERANCE * s {
            return None;
        }
    }
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        if (0..3).map(|r| u[r][i] * u[r][j]).sum::<f64>().abs() > TOLERANCE {
            return None;
        }
    }
    let det = u[0][0] * (u[1][1] * u[2][2] - u[1][2] * u[2][1]) - u[0][1] * (u[1][0] * u[2][2] - u[1][2] * u[2][0])
        + u[0][2] * (u[1][0] * u[2][1] - u[1][1] * u[2][0]);
    let qfac = if det < 0.0 { -1.0 } else { 1.0 };
    for row in &mut u {
        row[2] *= qfac;
    }
    let (r11, r12, r13) = (u[0][0], u[0][1], u[0][2]);
    let (r21, r22, r23) = (u[1][0], u[1][1], u[1][2]);
    let (r31, r32, r33) = (u[2][0], u[2][1], u[2][2]);
    let trace = r11 + r22 + r33 + 1.0;
    let (a, mut b, mut c, mut d);
    if trace > 0.5 {
        a = 0.5 * trace.sqrt();
        b = 0.25 * (r32 - r23) / a;
        c = 0.25 * (r13 - r31) / a;
        d = 0.25 * (r21 - r12) / a;
    } else {
        let xd = 1.0 + r11 - (r22 + r33);
        let yd = 1.0 + r22 - (r11 + r33);
        let zd = 1.0 + r33 - (r11 + r22);
        if xd > 1.0 {
            b = 0.5 * xd.sqrt();
            c = 0.25 * (r12 + r21) / b;
            d = 0.25 * (r13 + r31) / b;
            a = 0.25 * (r32 - r23) / b;
        } else if yd > 1.0 {
            c = 0.5 * yd.sqrt();
            b = 0.25 * (r12 + r21) / c;
            d = 0.25 * (r23 + r32) / c;
            a = 0.25 * (r13 - r31) / c;
        } else {
            d = 0.5 * zd.sqrt();
            b = 0.25 * (r13 + r31) / d;
            c = 0.25 * (r23 + r32) / d;
            a = 0.25 * (r21 - r12) / d;
        }
        if a < 0.0 {
            (b, c, d) = (-b, -c, -d);
        }
    }
    // the quaternion must give the matrix back (as the reader computes it from float32 fields)
    let (bf, cf, df) = (f64::from(b as f32), f64::from(c as f32), f64::from(d as f32));
    let af = (1.0 - (bf * bf + cf * cf + df * df)).max(0.0).sqrt();
    let back = rotation(af, bf, cf, df);
    let close = (0..3).all(|i| (0..3).all(|j| (back[i][j] - u[i][j]).abs() <= 1e-5));
    close.then_some((b, c, d, qfac))
}

/// Stages a NIfTI-1 file of float64 voxels (see the module documentation): `dims` = (nx, ny,
/// nz), `values` in storage order (`i + nx·(j + ny·k)`), `spacing` written as pixdim
/// (magnitudes), `affine` as the sform (and the qform when it is a rotation times
/// `diag(spacing)`). Gzip-compressed when the file name ends in `.gz`.
///
/// # Errors
/// Input errors naming the file: `values.len()` is not `nx · ny · nz`, an extent of 0 or
/// above 32767 (NIfTI-1 stores extents as 16-bit integers), a spacing that is 0 or not finite,
/// an affine entry that is not finite or not a finite float32, a singular affine. As
/// [`crate::io::stage`] for the target and the writing.
pub fn stage_nifti(
    path: &Path,
    dims: [usize; 3],
    spacing: [f64; 3],
    affine: &[[f64; 4]; 3],
    values: &[f64],
) -> Result<Staged> {
    let header = header_bytes(dims, spacing, affine, values.len()).map_err(|e| e.in_file(path))?;
    let gz = path.file_name().is_some_and(|n| n.to_string_lossy().to_ascii_lowercase().ends_with(".gz"));
    super::stage(path, |w| {
        if gz {
            let mut z = flate2::write::GzEncoder::new(w, flate2::Compression::default());
            write_body(&mut z, &header, values)?;
            z.finish()?;
            Ok(())
        } else {
            write_body(w, &header, values)
        }
    })
}

/// Writes a NIfTI-1 file of float64 voxels at once: [`stage_nifti`], then commit.
///
/// # Errors
/// As [`stage_nifti`]; I/O errors naming the file when it cannot be put in place.
pub fn write_nifti(
    path: &Path,
    dims: [usize; 3],
    spacing: [f64; 3],
    affine: &[[f64; 4]; 3],
    values: &[f64],
) -> Result<()> {
    stage_nifti(path, dims, spacing, affine, values)?.commit()
}

fn write_body(w: &mut dyn Write, header: &[u8; DATA_OFFSET], values: &[f64]) -> std::io::Result<()> {
    w.write_all(header)?;
    let mut buf = Vec::with_capacity(8 * 8192);
    for chunk in values.chunks(8192) {
        buf.clear();
        for v in chunk {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        w.write_all(&buf)?;
    }
    Ok(())
}

/// The 348-byte little-endian header of a float64 volume and the 4-byte extender (no extensions).
fn header_bytes(dims: [usize; 3], spacing: [f64; 3], affine: &[[f64; 4]; 3], len: usize) -> Result<[u8; DATA_OFFSET]> {
    let count = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
    if count != Some(len) {
        return Err(Error::input(format!(
            "{len} values for a volume of {} × {} × {} voxels",
            dims[0], dims[1], dims[2]
        )));
    }
    let mut dim = [1i16; 8];
    dim[0] = 3;
    for (a, &n) in dims.iter().enumerate() {
        dim[a + 1] = match i16::try_from(n) {
            Ok(n) if n > 0 => n,
            _ => {
                return Err(Error::input(format!(
                    "{n} voxels along {}: a NIfTI-1 extent is 1 to 32767",
                    ["x", "y", "z"][a]
                )))
            }
        };
    }
    let f32_of = |what: &str, v: f64| -> Result<f32> {
        let f = v as f32;
        if f.is_finite() {
            Ok(f)
        } else {
            Err(Error::input(format!("{what} = {v} is not a finite float32 (NIfTI-1 stores geometry as float32)")))
        }
    };
    let mut pixdim = [1.0f32; 8];
    for (a, &s) in spacing.iter().enumerate() {
        if s == 0.0 || !s.is_finite() {
            return Err(Error::input(format!("spacing {s} along {}: it must be finite and not 0", ["x", "y", "z"][a])));
        }
        pixdim[a + 1] = f32_of("a spacing", s.abs())?;
    }
    let mut rows = [[0.0f32; 4]; 3];
    for r in 0..3 {
        for c in 0..4 {
            rows[r][c] = f32_of(&format!("affine[{r}][{c}]"), affine[r][c])?;
        }
    }
    if det3(&rows.map(|row| row.map(f64::from))) == 0.0 {
        return Err(Error::input(format!("the affine {affine:?} is singular (determinant 0)")));
    }
    let magnitudes = spacing.map(f64::abs);
    let qform = quaternion_of(affine, magnitudes);
    let mut h = [0u8; DATA_OFFSET];
    let mut put = |at: usize, bytes: &[u8]| h[at..at + bytes.len()].copy_from_slice(bytes);
    put(0, &(HEADER_SIZE as i32).to_le_bytes());
    put(38, b"r"); // regular, as ANALYZE readers expect
    for (k, d) in dim.iter().enumerate() {
        put(40 + 2 * k, &d.to_le_bytes());
    }
    put(70, &64i16.to_le_bytes()); // datatype float64
    put(72, &64i16.to_le_bytes()); // bitpix
    if let Some((_, _, _, qfac)) = qform {
        pixdim[0] = qfac as f32;
    }
    for (k, p) in pixdim.iter().enumerate() {
        put(76 + 4 * k, &p.to_le_bytes());
    }
    put(108, &(DATA_OFFSET as f32).to_le_bytes()); // vox_offset
    put(112, &1.0f32.to_le_bytes()); // scl_slope
    put(116, &0.0f32.to_le_bytes()); // scl_inter
    put(148, b"toposmooth"); // descrip
    let (qform_code, quatern) = match qform {
        Some((b, c, d, _)) => (1i16, [b as f32, c as f32, d as f32]),
        None => (0, [0.0; 3]),
    };
    put(252, &qform_code.to_le_bytes());
    put(254, &1i16.to_le_bytes()); // sform_code: scanner coordinates
    for (k, q) in quatern.iter().chain(&[rows[0][3], rows[1][3], rows[2][3]]).enumerate() {
        put(256 + 4 * k, &q.to_le_bytes());
    }
    for (k, v) in rows.iter().flatten().enumerate() {
        put(280 + 4 * k, &v.to_le_bytes());
    }
    put(344, b"n+1\0");
    Ok(h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn dir() -> PathBuf {
        let d = std::env::temp_dir().join(format!("toposmooth-nifti-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn fixture() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/mri_anatomical_33x41x25.nii")
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    fn gzip(bytes: &[u8]) -> Vec<u8> {
        let mut z = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(bytes).unwrap();
        z.finish().unwrap()
    }

    /// The header of a file, parsed by the `nifti` crate alone.
    fn crate_header(bytes: &[u8]) -> ::nifti::NiftiHeader {
        ::nifti::NiftiHeader::from_reader(bytes).unwrap()
    }

    fn error_of(name: &str, bytes: &[u8]) -> String {
        let p = dir().join(name);
        std::fs::write(&p, bytes).unwrap();
        let e = read_nifti(&p).unwrap_err();
        assert!(matches!(e, Error::Input { .. }), "{e:?}");
        let e = e.to_string();
        assert!(e.contains(name), "the error names the file: {e}");
        e
    }

    /// A 4 × 3 × 2 volume of awkward doubles: −0.0, a subnormal, NaN, large and small numbers.
    fn small_values() -> Vec<f64> {
        let mut v: Vec<f64> =
            (0..24).map(|k| (k as f64 - 11.5) * std::f64::consts::PI * 1e3f64.powi(k % 5 - 2)).collect();
        v[0] = -0.0;
        v[5] = f64::MIN_POSITIVE / 7.0;
        v[9] = f64::NAN;
        v[17] = 1e300;
        v
    }

    /// x flipped, anisotropic spacing, a translation (all float32 numbers).
    const FLIPPED: [[f64; 4]; 3] = [[-2.5, 0.0, 0.0, 10.25], [0.0, 1.5, 0.0, -3.0], [0.0, 0.0, 3.0, 7.5]];

    #[test]
    fn reads_the_anatomical_fixture() {
        let v = read_nifti(&fixture()).unwrap();
        assert_eq!(v.dims, [33, 41, 25]);
        assert_eq!((v.frames, v.frame), (1, 0));
        // header (read with python's struct module): pixdim = (-1, 2, 2, 2, 0, …), qform_code =
        // sform_code = 2, srow_x = (-2, 0, 0, 32), srow_y = (0, 2, 0, -40), srow_z = (0, 0, 2, -16)
        assert_eq!(v.spacing, [2.0, 2.0, 2.0]);
        assert_eq!(v.datatype, "int16");
        assert_eq!(v.affine_source, "sform");
        assert_eq!(v.affine, [[-2.0, 0.0, 0.0, 32.0], [0.0, 2.0, 0.0, -40.0], [0.0, 0.0, 2.0, -16.0]]);
        assert!(!v.oblique);
        assert_eq!(v.origin(), [32.0, -40.0, -16.0]);
        assert_eq!(v.direction(), [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], "x is flipped");
        assert_eq!(v.description, "spm - 3D normalized");
        // its qform (quaternion (0, 1, 0), qfac −1) is the same affine
        let bytes = std::fs::read(fixture()).unwrap();
        let h = crate_header(&bytes);
        assert_eq!((h.qform_code, h.sform_code), (2, 2));
        assert_eq!(qform_of(&h, v.spacing), v.affine);
        // voxels decoded independently (python3, struct, big-endian int16 at byte 352)
        let at = |i: usize, j: usize, k: usize| v.values[i + 33 * (j + 41 * k)];
        let known = [((0, 0, 0), 10712.0), ((16, 20, 12), 11881.0), ((32, 40, 24), 2971.0), ((5, 30, 7), 5046.0)];
        for ((i, j, k), want) in known {
            assert_eq!(at(i, j, k), want, "voxel ({i}, {j}, {k})");
        }
        assert_eq!(at(20, 3, 19), 12270.0);
        assert_eq!(v.values.len(), 33 * 41 * 25);
        assert_eq!(v.values.iter().sum::<f64>(), 284_166_082.0);
        assert_eq!(v.values.iter().copied().fold(f64::INFINITY, f64::min), -610.0);
        assert_eq!(v.values.iter().copied().fold(f64::NEG_INFINITY, f64::max), 30393.0);
        // gzip-compressed, recognised by content whatever the name
        for name in ["anatomical.nii.gz", "anatomical-gz.nii"] {
            let p = dir().join(name);
            std::fs::write(&p, gzip(&bytes)).unwrap();
            assert_eq!(read_nifti(&p).unwrap(), v, "{name}");
        }
    }

    #[cfg(feature = "io-vtk")]
    #[test]
    fn the_fixture_equals_its_vtk_copy() {
        let v = read_nifti(&fixture()).unwrap();
        let vti = Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/mri_anatomical_33x41x25.vti");
        let ds = crate::io::vtk::read_dataset(&vti).unwrap();
        assert_eq!(ds.image.as_ref().unwrap().dims(), v.dims);
        let t1 = ds.point_data.iter().find(|a| a.name == "t1").unwrap();
        assert_eq!(t1.components, 1);
        assert_eq!(t1.values.len(), v.values.len());
        let differ = (0..v.values.len()).filter(|&i| t1.values[i] != v.values[i]).count();
        assert_eq!(differ, 0, "voxels that differ from the .vti");
    }

    #[test]
    fn round_trip_bit_for_bit() {
        let values = small_values();
        for name in ["small.nii.gz", "small.nii", "SMALL.NII.GZ"] {
            let p = dir().join(name);
            write_nifti(&p, [4, 3, 2], [2.5, 1.5, 3.0], &FLIPPED, &values).unwrap();
            let bytes = std::fs::read(&p).unwrap();
            let gz = name.to_ascii_lowercase().ends_with(".gz");
            assert_eq!(bytes.starts_with(&[0x1f, 0x8b]), gz, "{name}: gzip only when the name ends in .gz");
            let v = read_nifti(&p).unwrap();
            assert_eq!(bits(&v.values), bits(&values), "{name}");
            assert_eq!(v.dims, [4, 3, 2]);
            assert_eq!(v.spacing, [2.5, 1.5, 3.0]);
            assert_eq!(v.affine, FLIPPED);
            assert_eq!((v.affine_source, v.oblique, v.datatype.as_str()), ("sform", false, "float64"));
            assert_eq!(v.origin(), [10.25, -3.0, 7.5]);
            assert_eq!(v.direction()[0][0], -1.0);
            assert_eq!(v.description, "toposmooth");
            // the header as the nifti crate reads it: codes, and a qform equal to the sform
            let raw = if gz {
                let mut out = Vec::new();
                flate2::read::GzDecoder::new(&bytes[..]).read_to_end(&mut out).unwrap();
                out
            } else {
                bytes
            };
            let h = crate_header(&raw);
            assert_eq!((h.sform_code, h.qform_code, h.datatype, h.bitpix), (1, 1, 64, 64));
            assert_eq!(h.pixdim[..4], [-1.0, 2.5, 1.5, 3.0]);
            assert_eq!(h.endianness, ::nifti::Endianness::Little);
            assert_eq!(qform_of(&h, v.spacing), FLIPPED);
            // and the whole file as the crate's object reader reads it
            let obj = ::nifti::InMemNiftiObject::from_reader(&raw[..]).unwrap();
            use ::nifti::NiftiObject;
            let want: Vec<u8> = values.iter().flat_map(|x| x.to_le_bytes()).collect();
            assert_eq!(obj.volume().raw_data(), &want[..]);
        }
    }

    #[test]
    fn geometry_without_sform() {
        // qform only (sform_code 0), then neither (pixdim): patch a written file's header
        let p = dir().join("codes.nii");
        write_nifti(&p, [4, 3, 2], [2.5, 1.5, 3.0], &FLIPPED, &small_values()).unwrap();
        let mut bytes = std::fs::read(&p).unwrap();
        bytes[254..256].copy_from_slice(&0i16.to_le_bytes());
        let v = parse_nifti(&bytes, None).unwrap();
        assert_eq!((v.affine_source, v.affine), ("qform", FLIPPED));
        bytes[252..254].copy_from_slice(&0i16.to_le_bytes());
        let v = parse_nifti(&bytes, None).unwrap();
        assert_eq!(v.affine_source, "pixdim");
        assert_eq!(v.affine, [[2.5, 0.0, 0.0, 0.0], [0.0, 1.5, 0.0, 0.0], [0.0, 0.0, 3.0, 0.0]]);
        // scl_slope 2, scl_inter 1
        bytes[112..116].copy_from_slice(&2.0f32.to_le_bytes());
        bytes[116..120].copy_from_slice(&1.0f32.to_le_bytes());
        let v = parse_nifti(&bytes, None).unwrap();
        assert_eq!(v.values[1], small_values()[1] * 2.0 + 1.0);
        bytes[116..120].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(parse_nifti(&bytes, None).unwrap_err().to_string().contains("intercept"));
        // slope 0: no scaling
        bytes[112..116].copy_from_slice(&0.0f32.to_le_bytes());
        assert_eq!(bits(&parse_nifti(&bytes, None).unwrap().values), bits(&small_values()));
    }

    #[test]
    fn oblique_affines() {
        let (s, c) = 10f64.to_radians().sin_cos();
        let spacing = [2.0, 1.0, 0.5];
        // rotation by 10° about z, times diag(spacing), plus a translation
        let rotated = [
            [c * spacing[0], -s * spacing[1], 0.0, 1.0],
            [s * spacing[0], c * spacing[1], 0.0, 2.0],
            [0.0, 0.0, spacing[2], 3.0],
        ];
        assert!(is_oblique(&rotated));
        // a signed permutation times a diagonal: i → z, j → −x, k → y
        let permuted = [[0.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.5, 0.0], [2.0, 0.0, 0.0, 0.0]];
        assert!(!is_oblique(&permuted));
        assert!(!is_oblique(&FLIPPED));
        // two axes along the same world axis are not a permutation
        assert!(is_oblique(&[[1.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]));
        // through a file: the rotated affine gets a qform too (it is a rotation times a
        // diagonal), within float32
        let values: Vec<f64> = (0..24).map(f64::from).collect();
        let p = dir().join("rotated.nii");
        write_nifti(&p, [4, 3, 2], spacing, &rotated, &values).unwrap();
        let v = read_nifti(&p).unwrap();
        assert!(v.oblique);
        let bytes = std::fs::read(&p).unwrap();
        let h = crate_header(&bytes);
        assert_eq!(h.qform_code, 1);
        let q = qform_of(&h, v.spacing);
        for r in 0..3 {
            for k in 0..4 {
                assert!((q[r][k] - rotated[r][k]).abs() < 1e-6, "qform {q:?} vs {rotated:?}");
                assert!((v.affine[r][k] - rotated[r][k]).abs() < 1e-6);
            }
        }
        let p = dir().join("permuted.nii");
        write_nifti(&p, [4, 3, 2], [2.0, 1.0, 0.5], &permuted, &values).unwrap();
        let v = read_nifti(&p).unwrap();
        assert!(!v.oblique);
        assert_eq!(v.direction(), [[0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]);
        let h = crate_header(&std::fs::read(&p).unwrap());
        assert_eq!((h.qform_code, qform_of(&h, v.spacing)), (1, permuted));
        // a shear is no rotation times a diagonal: sform only
        let sheared = [[1.0, 0.5, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]];
        let p = dir().join("sheared.nii");
        write_nifti(&p, [4, 3, 2], [1.0, 1.0, 1.0], &sheared, &values).unwrap();
        let v = read_nifti(&p).unwrap();
        assert!(v.oblique);
        assert_eq!(v.affine, sheared);
        assert_eq!(crate_header(&std::fs::read(&p).unwrap()).qform_code, 0);
    }

    #[test]
    fn frames_of_a_4d_file() {
        // 4 × 3 × 1 voxels × 2 frames: the same 24 values, dim = (4, 4, 3, 1, 2)
        let values = small_values();
        let p = dir().join("frames.nii");
        write_nifti(&p, [4, 3, 2], [2.5, 1.5, 3.0], &FLIPPED, &values).unwrap();
        let mut bytes = std::fs::read(&p).unwrap();
        for (k, d) in [4i16, 4, 3, 1, 2].iter().enumerate() {
            bytes[40 + 2 * k..42 + 2 * k].copy_from_slice(&d.to_le_bytes());
        }
        let e = error_of("frames.nii", &bytes);
        assert!(e.contains("2 frames") && e.contains("4 × 3 × 1 × 2"), "{e}");
        std::fs::write(&p, &bytes).unwrap();
        let second = read_nifti_frame(&p, 1).unwrap();
        assert_eq!((second.dims, second.frames, second.frame), ([4, 3, 1], 2, 1));
        assert_eq!(bits(&second.values), bits(&values[12..]));
        let e = read_nifti_frame(&p, 2).unwrap_err().to_string();
        assert!(e.contains("frames.nii") && e.contains("frame 2") && e.contains("2 frames"), "{e}");
        // one frame: a 3-D volume
        bytes[48..50].copy_from_slice(&1i16.to_le_bytes());
        bytes[46..48].copy_from_slice(&2i16.to_le_bytes());
        assert_eq!(bits(&parse_nifti(&bytes, None).unwrap().values), bits(&values));
    }

    #[test]
    fn bad_files_name_the_file_and_the_problem() {
        let good = std::fs::read(fixture()).unwrap();
        // truncated data, plain and compressed; a truncated header
        let e = error_of("cut.nii", &good[..good.len() - 100]);
        assert!(e.contains("truncated") && e.contains("33 × 41 × 25") && e.contains("67550 bytes"), "{e}");
        let e = error_of("cut.nii.gz", &gzip(&good[..5000]));
        assert!(e.contains("truncated") && e.contains("after gzip"), "{e}");
        let e = error_of("short.nii", &good[..100]);
        assert!(e.contains("not a NIfTI-1 file") && e.contains("348"), "{e}");
        // a gzip stream cut in the middle
        let z = gzip(&good);
        let e = error_of("corrupt.nii.gz", &z[..z.len() / 2]);
        assert!(e.contains("gzip"), "{e}");
        // wrong magic, sizeof_hdr, NIfTI-2, an .hdr header
        let mut bad = good.clone();
        bad[344..348].copy_from_slice(b"xyz\0");
        let e = error_of("magic.nii", &bad);
        assert!(e.contains("not a NIfTI-1 file") && e.contains("magic") && e.contains("xyz"), "{e}");
        bad[344..348].copy_from_slice(b"ni1\0");
        assert!(error_of("pair.hdr", &bad).contains(".hdr/.img"));
        let e = error_of("text.nii", &[b"hello, this is not an image\n".as_slice(); 20].concat());
        assert!(e.contains("sizeof_hdr"), "{e}");
        let mut two = good.clone();
        two[0..4].copy_from_slice(&540i32.to_be_bytes());
        assert!(error_of("two.nii", &two).contains("NIfTI-2"));
        // the fixture is big-endian: fields below are patched as such
        let patched = |at: usize, field: &[u8]| {
            let mut b = good.clone();
            b[at..at + field.len()].copy_from_slice(field);
            b
        };
        let e = error_of("complex.nii", &patched(70, &32i16.to_be_bytes()));
        assert!(e.contains("unsupported datatype complex64") && e.contains("code 32"), "{e}");
        let e = error_of("code.nii", &patched(70, &7i16.to_be_bytes()));
        assert!(e.contains("unknown datatype") && e.contains("code 7"), "{e}");
        let e = error_of("zero.nii", &patched(44, &0i16.to_be_bytes()));
        assert!(e.contains("dim[2] = 0"), "{e}");
        let mut five = patched(40, &5i16.to_be_bytes());
        five[50..52].copy_from_slice(&2i16.to_be_bytes());
        let e = error_of("five.nii", &five);
        assert!(e.contains("5-D") && e.contains("dim[5]"), "{e}");
        let e = error_of("dim0.nii", &patched(40, &9i16.to_be_bytes()));
        assert!(e.contains("dim[0] = 9"), "{e}");
        let e = error_of("nan.nii", &patched(80, &f32::NAN.to_be_bytes()));
        assert!(e.contains("pixdim[1]") && e.contains("not finite"), "{e}");
        let e = error_of("flat.nii", &patched(88, &0f32.to_be_bytes()));
        assert!(e.contains("pixdim[3] = 0") && e.contains("zero spacing"), "{e}");
        let e = error_of("offset.nii", &patched(108, &100f32.to_be_bytes()));
        assert!(e.contains("vox_offset"), "{e}");
        let e = error_of("singular.nii", &patched(280, &0f32.to_be_bytes()));
        assert!(e.contains("singular"), "{e}");
        // a missing file is an I/O error naming it
        let e = read_nifti(&dir().join("missing.nii")).unwrap_err();
        assert!(matches!(e, Error::Io { .. }) && e.to_string().contains("missing.nii"), "{e}");
    }

    #[test]
    fn bad_arguments_to_the_writer() {
        let p = dir().join("refused.nii");
        let values = vec![0.0; 24];
        let e = write_nifti(&p, [4, 3, 3], [1.0; 3], &FLIPPED, &values).unwrap_err().to_string();
        assert!(e.contains("refused.nii") && e.contains("24 values"), "{e}");
        let e = write_nifti(&p, [4, 3, 2], [1.0, 0.0, 1.0], &FLIPPED, &values).unwrap_err().to_string();
        assert!(e.contains("spacing 0 along y"), "{e}");
        let mut big = FLIPPED;
        big[1][3] = 1e40;
        let e = write_nifti(&p, [4, 3, 2], [1.0; 3], &big, &values).unwrap_err().to_string();
        assert!(e.contains("affine[1][3]") && e.contains("float32"), "{e}");
        let e = write_nifti(&p, [40_000, 1, 1], [1.0; 3], &FLIPPED, &vec![0.0; 40_000]).unwrap_err().to_string();
        assert!(e.contains("32767"), "{e}");
        assert!(!p.exists(), "nothing written");
    }
}
