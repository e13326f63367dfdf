//! ParaView collections (`.pvd`): a list of data set files with their time steps, read to
//! smooth every file of a time series and written to open the outputs as one in ParaView.

use super::xml::{attrs, get};
use crate::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// One `<DataSet>` of a collection.
#[derive(Clone, Debug, PartialEq)]
pub struct CollectionEntry {
    /// Its `timestep` (its position in the collection when absent).
    pub time: f64,
    /// The file, resolved against the collection's directory.
    pub file: PathBuf,
}

/// Reads a `.pvd` collection: its `<DataSet>` entries in file order.
///
/// # Errors
/// Input errors naming the file: unreadable XML, not a `Collection`, an entry without a
/// `file`, a `timestep` that is not a number, no entry at all.
pub fn read_pvd(path: &Path) -> Result<Vec<CollectionEntry>> {
    use quick_xml::events::Event;
    let bytes = std::fs::read(path).map_err(|e| Error::Io { path: path.to_path_buf(), source: e })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut reader = quick_xml::Reader::from_reader(bytes.as_slice());
    let (mut entries, mut collection) = (Vec::new(), false);
    loop {
        let event = reader.read_event().map_err(|e| {
            Error::input(format!("malformed XML near byte {}: {e}", reader.error_position())).in_file(path)
        })?;
        match event {
            Event::Start(e) | Event::Empty(e) => {
                let a = attrs(&e).map_err(|err| err.in_file(path))?;
                match e.name().as_ref() {
                    b"VTKFile" => collection = get(&a, "type") == Some("Collection"),
                    b"DataSet" => {
                        let file = get(&a, "file").ok_or_else(|| {
                            Error::input(format!("<DataSet> {} has no `file`", entries.len())).in_file(path)
                        })?;
                        let time = match get(&a, "timestep") {
                            None => entries.len() as f64,
                            Some(t) => t.trim().parse::<f64>().ok().filter(|t| t.is_finite()).ok_or_else(|| {
                                Error::input(format!("<DataSet> {} has timestep `{t}`, not a number", entries.len()))
                                    .in_file(path)
                            })?,
                        };
                        entries.push(CollectionEntry { time, file: dir.join(file) });
                    }
                    _ => {}
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if !collection {
        return Err(Error::input("not a ParaView collection (<VTKFile type=\"Collection\">)").in_file(path));
    }
    if entries.is_empty() {
        return Err(Error::input("the collection lists no <DataSet>").in_file(path));
    }
    Ok(entries)
}

/// Stages a `.pvd` collection of `entries`, their files written relative to the collection's
/// directory when they lie inside it.
///
/// # Errors
/// I/O errors naming the file.
pub fn stage_pvd(path: &Path, entries: &[CollectionEntry]) -> Result<crate::io::Staged> {
    let dir = path.parent().unwrap_or(Path::new(""));
    crate::io::stage(path, |w: &mut dyn Write| {
        writeln!(w, "<?xml version=\"1.0\"?>")?;
        writeln!(w, "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">")?;
        writeln!(w, "  <Collection>")?;
        for e in entries {
            let file = e.file.strip_prefix(dir).unwrap_or(&e.file);
            let shown = file.to_string_lossy().replace('&', "&amp;").replace('"', "&quot;").replace('<', "&lt;");
            writeln!(
                w,
                "    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{shown}\"/>",
                crate::io::format_f64(e.time)
            )?;
        }
        writeln!(w, "  </Collection>")?;
        writeln!(w, "</VTKFile>")?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_collection_reads_back_as_written() {
        let dir = std::env::temp_dir().join(format!("toposmooth-pvd-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let entries: Vec<CollectionEntry> = [0.0, 0.5, 2.25]
            .iter()
            .enumerate()
            .map(|(k, &t)| CollectionEntry { time: t, file: dir.join(format!("step \"{k}\".vti")) })
            .collect();
        let path = dir.join("c.pvd");
        stage_pvd(&path, &entries).unwrap().commit().unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("file=\"step &quot;1&quot;.vti\""), "relative and escaped: {text}");
        assert_eq!(read_pvd(&path).unwrap(), entries);
        std::fs::write(&path, "<VTKFile type=\"ImageData\"><DataSet file=\"a.vti\"/></VTKFile>").unwrap();
        assert!(read_pvd(&path).unwrap_err().to_string().contains("not a ParaView collection"));
        std::fs::write(
            &path,
            "<VTKFile type=\"Collection\"><Collection><DataSet timestep=\"x\" file=\"a\"/></Collection></VTKFile>",
        )
        .unwrap();
        let e = read_pvd(&path).unwrap_err().to_string();
        assert!(e.contains("c.pvd") && e.contains("timestep `x`"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
