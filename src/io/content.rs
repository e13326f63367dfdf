//! What a file's first bytes say it is: a reader given a file whose content does not match
//! its extension says which format it tried and what the file starts with
//! (`a.png: not a PNG image (starts with `x,y,…`): it looks like text`), instead of a
//! decoder's error about the wrong format.

use crate::error::{Error, Result};
use std::io::Read;
use std::path::Path;

/// What a file's first bytes look like.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Content {
    /// `\x89PNG\r\n\x1a\n`.
    Png,
    /// `II*\0` or `MM\0*` (and BigTIFF).
    Tiff,
    /// A zip archive (`PK\x03\x04`, or an empty one): what `numpy.savez` writes.
    Zip,
    /// `\x93NUMPY`.
    Npy,
    /// gzip data.
    Gzip,
    /// XML (VTK's XML formats start with `<?xml` or `<VTKFile`).
    Xml,
    /// `# vtk DataFile`.
    VtkLegacy,
    /// `ply` on the first line.
    Ply,
    /// Other UTF-8 text.
    Text,
    /// Anything else.
    Binary,
}

impl Content {
    /// The content in words, for messages.
    pub fn describe(self) -> &'static str {
        match self {
            Content::Png => "a PNG image",
            Content::Tiff => "a TIFF image",
            Content::Zip => "a zip archive (such as a NumPy .npz)",
            Content::Npy => "a NumPy .npy array",
            Content::Gzip => "gzip-compressed data",
            Content::Xml => "XML",
            Content::VtkLegacy => "a legacy VTK file",
            Content::Ply => "a PLY file",
            Content::Text => "text",
            Content::Binary => "binary data",
        }
    }

    fn is_text(self) -> bool {
        matches!(self, Content::Xml | Content::VtkLegacy | Content::Ply | Content::Text)
    }
}

/// Classifies a file from its first bytes (a few hundred are enough).
pub fn detect(head: &[u8]) -> Content {
    let starts = |m: &[u8]| head.starts_with(m);
    if starts(b"\x89PNG\r\n\x1a\n") {
        return Content::Png;
    }
    if starts(b"II*\0") || starts(b"MM\0*") || starts(b"II+\0") || starts(b"MM\0+") {
        return Content::Tiff;
    }
    if starts(b"PK\x03\x04") || starts(b"PK\x05\x06") {
        return Content::Zip;
    }
    if starts(b"\x93NUMPY") {
        return Content::Npy;
    }
    if starts(b"\x1f\x8b") {
        return Content::Gzip;
    }
    let body = head.strip_prefix(b"\xef\xbb\xbf".as_slice()).unwrap_or(head);
    // text headers that may be followed by binary data (binary PLY, legacy VTK, appended XML)
    let lead = &body[body.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(body.len())..];
    if lead.starts_with(b"<?xml") || lead.starts_with(b"<VTKFile") || lead.starts_with(b"<!--") {
        return Content::Xml;
    }
    if lead.starts_with(b"# vtk DataFile") {
        return Content::VtkLegacy;
    }
    if body.starts_with(b"ply\n") || body.starts_with(b"ply\r\n") || body == b"ply" {
        return Content::Ply;
    }
    // the first bytes may end inside a character: only what precedes it must be UTF-8
    let text = match std::str::from_utf8(body) {
        Ok(t) => t,
        Err(e) if e.error_len().is_none() => std::str::from_utf8(&body[..e.valid_up_to()]).unwrap_or(""),
        Err(_) => return Content::Binary,
    };
    if text.contains('\0') {
        Content::Binary
    } else {
        Content::Text
    }
}

/// The first bytes of a file for a message: up to 24 characters, control and non-ASCII
/// bytes escaped (`\x89PNG\r\n\x1a\n`), `…` when there is more.
pub fn preview(head: &[u8]) -> String {
    let mut out = String::new();
    for &b in head.iter().take(24) {
        match b {
            b'\n' => out.push_str("\\n"),
            b'\r' => out.push_str("\\r"),
            b'\t' => out.push_str("\\t"),
            b'`' => out.push('\''),
            0x20..=0x7e => out.push(b as char),
            _ => out.push_str(&format!("\\x{b:02x}")),
        }
    }
    if head.len() > 24 {
        out.push('…');
    }
    out
}

fn mismatch(path: &Path, head: &[u8], expected: &str) -> Error {
    let found = detect(head);
    let what =
        if head.is_empty() { "the file is empty".to_string() } else { format!("it looks like {}", found.describe()) };
    Error::input(format!("not {expected} (starts with `{}`): {what}", preview(head))).in_file(path)
}

/// An input error unless `head` (a file's first bytes) is text: `expected` names the format
/// the reader wanted (`CSV text`).
///
/// # Errors
/// The file is a PNG, TIFF, zip, NumPy or gzip file, or other binary data.
pub fn expect_text(path: &Path, head: &[u8], expected: &str) -> Result<()> {
    let head = &head[..head.len().min(512)];
    if detect(head).is_text() || head.is_empty() {
        return Ok(());
    }
    Err(mismatch(path, head, expected))
}

/// The first (up to 512) bytes of a file.
///
/// # Errors
/// The file cannot be read.
pub fn head(path: &Path) -> Result<Vec<u8>> {
    let io = |source| Error::Io { path: path.to_path_buf(), source };
    let mut head = Vec::with_capacity(512);
    std::fs::File::open(path).map_err(io)?.take(512).read_to_end(&mut head).map_err(io)?;
    Ok(head)
}

/// What a file with this extension holds, and its name for messages (`None`: no fixed
/// content, as for an unknown extension).
pub fn expected_for(path: &Path) -> Option<(&'static [Content], &'static str)> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    Some(match ext.as_str() {
        "png" => (&[Content::Png], "a PNG image"),
        "tif" | "tiff" => (&[Content::Tiff], "a TIFF image"),
        "npy" => (&[Content::Npy], "a NumPy .npy array"),
        "npz" => (&[Content::Zip], "a NumPy .npz archive (zip)"),
        "vti" | "vtu" | "vtp" => (&[Content::Xml], "a VTK XML file"),
        "vtk" => (&[Content::VtkLegacy], "a legacy VTK file (`# vtk DataFile`)"),
        "ply" => (&[Content::Ply], "a PLY file"),
        "csv" | "tsv" | "txt" | "obj" | "off" => {
            (&[Content::Text, Content::Xml, Content::VtkLegacy, Content::Ply], "text")
        }
        _ => return None,
    })
}

/// Checks that a file's first bytes match what its extension names (PNG, TIFF, NumPy,
/// VTK, PLY, text): an input error naming the format tried and what the file starts with.
///
/// # Errors
/// The content does not match; the file cannot be read.
pub fn check_extension(path: &Path) -> Result<()> {
    let Some((allowed, expected)) = expected_for(path) else {
        return Ok(());
    };
    let head = head(path)?;
    if allowed.contains(&detect(&head)) {
        return Ok(());
    }
    let expected = if expected == "text" { "text (CSV, OBJ or OFF)" } else { expected };
    Err(mismatch(path, &head, expected))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn magic_bytes_and_text() {
        assert_eq!(detect(b"\x89PNG\r\n\x1a\n\0\0"), Content::Png);
        assert_eq!(detect(b"II*\0abc"), Content::Tiff);
        assert_eq!(detect(b"PK\x03\x04\x14"), Content::Zip);
        assert_eq!(detect(b"\x93NUMPY\x01\x00"), Content::Npy);
        assert_eq!(detect(b"\xef\xbb\xbfx,y\n1,2\n"), Content::Text);
        assert_eq!(detect(b"  <?xml version=\"1.0\"?>\n<VTKFile"), Content::Xml);
        assert_eq!(detect(b"# vtk DataFile Version 4.2\n"), Content::VtkLegacy);
        assert_eq!(detect(b"ply\nformat ascii 1.0\n"), Content::Ply);
        assert_eq!(detect(b"a\0b"), Content::Binary);
        assert_eq!(detect(b"ply\nformat binary_little_endian 1.0\nend_header\n\xff\x00\x93"), Content::Ply);
        assert_eq!(detect(b"# vtk DataFile Version 5.1\nx\nBINARY\n\xff\xfe\x00"), Content::VtkLegacy);
        assert_eq!(detect(b"<VTKFile type=\"ImageData\"><AppendedData>_\xff\x00"), Content::Xml);
        assert_eq!(detect(b"caf\xc3"), Content::Text, "a character cut at the end of the head");
        assert_eq!(preview(b"\x89PNG\r\n\x1a\n"), "\\x89PNG\\r\\n\\x1a\\n");
        assert_eq!(preview(b"x,y,z,0123456789012345678901"), "x,y,z,012345678901234567…");
    }

    #[test]
    fn extension_and_content_disagree() {
        let d = std::env::temp_dir().join(format!("toposmooth-content-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let png = d.join("a.png");
        std::fs::write(&png, "x,y,z\n1,2,3\n").unwrap();
        let e = check_extension(&png).unwrap_err();
        assert_eq!(e.exit_code(), 3);
        let msg = e.to_string();
        assert!(msg.contains("a.png: not a PNG image (starts with `x,y,z\\n1,2,3\\n`): it looks like text"), "{msg}");
        let csv = d.join("b.csv");
        std::fs::write(&csv, b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR").unwrap();
        let msg = check_extension(&csv).unwrap_err().to_string();
        assert!(msg.contains("b.csv: not text") && msg.contains("a PNG image"), "{msg}");
        let npz = d.join("c.npz");
        std::fs::write(&npz, b"\x93NUMPY\x01\x00").unwrap();
        assert!(check_extension(&npz).unwrap_err().to_string().contains("not a NumPy .npz archive (zip)"));
        std::fs::write(d.join("ok.csv"), "1,2\n").unwrap();
        assert!(check_extension(&d.join("ok.csv")).is_ok());
        assert!(check_extension(&d.join("whatever.dat")).is_ok(), "no fixed content");
        let empty = d.join("e.png");
        std::fs::write(&empty, "").unwrap();
        assert!(check_extension(&empty).unwrap_err().to_string().contains("the file is empty"));
    }
}
