//! The verifiable output of `smooth` on a series (SPEC.md "Formats"): the CSV
//! `X,input,output,u,role`, X the input's x column name (`x` when it has none), plus a last
//! column `filled` when missing samples were filled; and reading it back for `verify`.

use crate::error::{Error, Location, Result};
use crate::topology::Role;
use std::path::Path;

/// The x column's text per sample, written back out: the sample index when the series has no
/// x column or one of the indices themselves (made when asked: at 10⁷ samples a string each
/// held 0.5 GB), else the file's text.
#[derive(Clone, Debug, PartialEq)]
pub enum XText {
    /// `0, 1, …, n − 1`.
    Index(usize),
    /// The text of each row.
    Text(Texts),
}

/// Texts one after another in one string, with where each ends: at 10⁷ dates a `String` each
/// took 310 MB and ten million allocations, these 190 MB and two.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Texts {
    text: String,
    ends: Vec<usize>,
}

impl Texts {
    /// No text, room for `n`.
    #[must_use]
    pub fn with_capacity(n: usize) -> Texts {
        Texts { text: String::new(), ends: Vec::with_capacity(n) }
    }

    /// Appends one text.
    pub fn push(&mut self, s: &str) {
        self.text.push_str(s);
        self.ends.push(self.text.len());
    }

    /// The number of texts.
    #[must_use]
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// Whether there is no text.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }

    /// Text `i`.
    ///
    /// # Panics
    /// If `i` is out of range.
    #[must_use]
    pub fn get(&self, i: usize) -> &str {
        let start = if i == 0 { 0 } else { self.ends[i - 1] };
        &self.text[start..self.ends[i]]
    }
}

impl<S: AsRef<str>> FromIterator<S> for Texts {
    fn from_iter<I: IntoIterator<Item = S>>(iter: I) -> Texts {
        let mut t = Texts::default();
        iter.into_iter().for_each(|s| t.push(s.as_ref()));
        t
    }
}

impl XText {
    /// The number of samples.
    #[must_use]
    pub fn len(&self) -> usize {
        match self {
            XText::Index(n) => *n,
            XText::Text(t) => t.len(),
        }
    }

    /// Whether there is no sample.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The text of sample `i`.
    ///
    /// # Panics
    /// If `i` is out of range.
    #[must_use]
    pub fn get(&self, i: usize) -> std::borrow::Cow<'_, str> {
        match self {
            XText::Index(n) => {
                assert!(i < *n, "sample {i} of {n}");
                i.to_string().into()
            }
            XText::Text(t) => t.get(i).into(),
        }
    }

    /// The stored texts, `None` for the index.
    #[must_use]
    pub fn as_text(&self) -> Option<&Texts> {
        match self {
            XText::Index(_) => None,
            XText::Text(t) => Some(t),
        }
    }

    /// Every sample's text.
    #[must_use]
    pub fn to_vec(&self) -> Vec<String> {
        (0..self.len()).map(|i| self.get(i).into_owned()).collect()
    }
}

/// The verifiable output of `smooth` on a series.
#[derive(Clone, Debug, PartialEq)]
pub struct SeriesOutput {
    /// The x column's header.
    pub x_name: String,
    /// x as text (dates stay dates).
    pub x_text: XText,
    /// The input values actually smoothed (after filling).
    pub input: Vec<f64>,
    /// The certified output.
    pub output: Vec<f64>,
    /// The representative function.
    pub u: Vec<f64>,
    /// Role per sample.
    pub roles: Vec<Role>,
    /// Samples filled by `--fill-missing` (true), when any were.
    pub filled: Option<Vec<bool>>,
}

/// The columns after X.
const COLUMNS: [&str; 4] = ["input", "output", "u", "role"];

/// The columns of [`SeriesOutput`] as written, borrowed from the run's results (at 10⁷
/// samples copies of them held 1.5 GB).
#[derive(Clone, Copy, Debug)]
pub struct SeriesColumns<'a> {
    /// The x column's header.
    pub x_name: &'a str,
    /// x as text.
    pub x_text: &'a XText,
    /// The input values actually smoothed (after filling).
    pub input: &'a [f64],
    /// The certified output.
    pub output: &'a [f64],
    /// The representative function.
    pub u: &'a [f64],
    /// Role per sample.
    pub roles: &'a [Role],
    /// Samples filled by `--fill-missing` (true), when any were.
    pub filled: Option<&'a [bool]>,
}

impl SeriesOutput {
    /// Its columns, borrowed.
    #[must_use]
    pub fn columns(&self) -> SeriesColumns<'_> {
        SeriesColumns {
            x_name: &self.x_name,
            x_text: &self.x_text,
            input: &self.input,
            output: &self.output,
            u: &self.u,
            roles: &self.roles,
            filled: self.filled.as_deref(),
        }
    }
}

/// Writes `X,input,output,u,role[,filled]` atomically, doubles in shortest round-trip form.
pub fn write_series_output(path: &Path, out: &SeriesOutput) -> Result<()> {
    stage_series_output(path, &out.columns())?.commit()
}

/// Rows formatted per block: blocks are formatted on every allowed thread at once and
/// written in order (at 10⁷ samples the formatting was 4 CPU s on one thread).
const ROWS_PER_BLOCK: usize = 1 << 15;

/// Stages the file of [`write_series_output`] (see [`super::Staged`]).
pub fn stage_series_output(path: &Path, out: &SeriesColumns<'_>) -> Result<super::Staged> {
    let filled = out.filled.filter(|f| f.iter().any(|&b| b));
    let n = out.input.len();
    let threads = crate::parallel::threads().max(1);
    super::stage(path, |w| {
        writeln!(w, "{},{}{}", csv_cell(out.x_name), COLUMNS.join(","), if filled.is_some() { ",filled" } else { "" })?;
        // one text per thread, reused: a block of about 2 MB each in memory at a time
        let mut texts = vec![String::new(); threads];
        let mut start = 0;
        while start < n {
            let ends: Vec<usize> = (0..threads).map(|t| (start + (t + 1) * ROWS_PER_BLOCK).min(n)).collect();
            let format = |t: usize, text: &mut String| {
                let lo = (start + t * ROWS_PER_BLOCK).min(n);
                format_rows(out, filled, lo..ends[t], text);
            };
            if threads == 1 {
                format(0, &mut texts[0]);
            } else {
                std::thread::scope(|scope| {
                    let (first, rest) = texts.split_first_mut().expect("one text per thread");
                    for (t, text) in rest.iter_mut().enumerate() {
                        let format = &format;
                        scope.spawn(move || format(t + 1, text));
                    }
                    format(0, first);
                });
            }
            for text in &texts {
                w.write_all(text.as_bytes())?;
            }
            start = ends[threads - 1];
        }
        Ok(())
    })
}

/// The rows `range` of the file, appended to `text` after clearing it.
fn format_rows(out: &SeriesColumns<'_>, filled: Option<&[bool]>, range: std::ops::Range<usize>, text: &mut String) {
    use std::fmt::Write as _;
    text.clear();
    let x = out.x_text.as_text();
    for i in range {
        match x {
            Some(t) => text.push_str(&csv_cell(t.get(i))),
            None => {
                let _ = write!(text, "{i}");
            }
        }
        for v in [out.input[i], out.output[i], out.u[i]] {
            text.push(',');
            super::push_f64(text, v);
        }
        text.push(',');
        text.push_str(out.roles[i].label());
        if let Some(f) = filled {
            text.push_str(if f[i] { ",1" } else { ",0" });
        }
        text.push('\n');
    }
}

fn csv_cell(s: &str) -> std::borrow::Cow<'_, str> {
    if s.contains([',', '"', '\n', '\r']) || s.trim() != s {
        format!("\"{}\"", s.replace('"', "\"\"")).into()
    } else {
        s.into()
    }
}

/// The positions of X (if any), input, output, u, role and filled (if any) in a header:
/// X first and the others after it in SPEC's order, else by name (X then the column `x`).
fn positions(header: &csv::StringRecord) -> Option<(Option<usize>, [usize; 4], Option<usize>)> {
    let cells: Vec<&str> = header.iter().collect();
    if cells.len() >= 5 && cells[1..5] == COLUMNS {
        let filled = (cells.get(5) == Some(&"filled")).then_some(5);
        return Some((Some(0), [1, 2, 3, 4], filled));
    }
    let at = |name: &str| cells.iter().position(|h| *h == name);
    let [i, o, u, r] = COLUMNS.map(at);
    Some((at("x"), [i?, o?, u?, r?], at("filled")))
}

/// Reads a file written by [`write_series_output`].
///
/// # Errors
/// Input errors naming the file and line: missing columns, unparsable numbers, unknown roles,
/// a `filled` cell that is not 0 or 1.
pub fn read_series_output(path: &Path) -> Result<SeriesOutput> {
    read_series_output_with(path, true)
}

/// [`read_series_output`]; without `with_x` the x column's text is not kept (`x_text` is the
/// index): the read-back check of a written file compares the values only.
pub(crate) fn read_series_output_with(path: &Path, with_x: bool) -> Result<SeriesOutput> {
    let err = |msg: String| Error::input(msg).in_file(path);
    super::content::expect_text(path, &super::content::head(path)?, "a series CSV (X,input,output,u,role)")?;
    // streamed: the written file is read back after every run (at 10⁷ samples a copy of it in
    // memory was 0.7 GB of fresh pages)
    let file = std::fs::File::open(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::Headers)
        .from_reader(std::io::BufReader::with_capacity(1 << 20, file));
    let header = reader.headers().map_err(|e| err(format!("malformed CSV: {e}")))?.clone();
    let (cx, [ci, co, cu, cr], cf) = positions(&header).ok_or_else(|| {
        err(format!(
            "the header `{}` is not a verifiable series file's X,input,output,u,role",
            header.iter().collect::<Vec<_>>().join(",")
        ))
    })?;
    let x_name = cx.and_then(|c| header.get(c)).unwrap_or("x").to_string();
    let mut out = SeriesOutput {
        x_name,
        x_text: XText::Text(Texts::default()),
        input: vec![],
        output: vec![],
        u: vec![],
        roles: vec![],
        filled: None,
    };
    let mut x_text = Texts::default();
    let mut filled = Vec::new();
    // byte records, each cell checked as UTF-8 and trimmed where it is used (the read-back of
    // every run's output: string records validated and trimmed every cell of 10⁷ rows)
    let mut rec = csv::ByteRecord::new();
    while reader.read_byte_record(&mut rec).map_err(|e| err(format!("malformed CSV: {e}")))? {
        let line = rec.position().map(|p| p.line()).unwrap_or(0);
        let bad = |msg: String| err(format!("line {line}: {msg}")).at(Location::Line(line as usize));
        let text = |c: usize, name: &str| -> Result<&str> {
            std::str::from_utf8(rec.get(c).unwrap_or(b""))
                .map(str::trim)
                .map_err(|_| bad(format!("column `{name}` is not UTF-8 text")))
        };
        let num = |c: usize, name: &str| -> Result<f64> {
            let cell = text(c, name)?;
            cell.parse::<f64>().map_err(|_| bad(format!("`{cell}` in column `{name}` is not a number")))
        };
        out.input.push(num(ci, "input")?);
        out.output.push(num(co, "output")?);
        out.u.push(num(cu, "u")?);
        let role = text(cr, "role")?;
        out.roles.push(
            Role::from_label(role)
                .ok_or_else(|| bad(format!("unknown role `{role}` (min, max, fixed, end or empty)")))?,
        );
        if with_x {
            x_text.push(cx.map_or(Ok(""), |c| text(c, "x"))?);
        }
        if let Some(c) = cf {
            filled.push(match text(c, "filled")? {
                "1" => true,
                "0" => false,
                other => return Err(bad(format!("`{other}` in column `filled` is not 0 or 1"))),
            });
        }
    }
    if out.input.len() < 2 {
        return Err(err(format!("a series needs at least 2 samples, found {}", out.input.len())));
    }
    out.filled = cf.map(|_| filled);
    out.x_text = if with_x { XText::Text(x_text) } else { XText::Index(out.input.len()) };
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir() -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("toposmooth-series-out-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn sample(x_name: &str, filled: Option<Vec<bool>>) -> SeriesOutput {
        SeriesOutput {
            x_name: x_name.into(),
            x_text: XText::Text(["2010-01-01", "2010-01-04", "a,b"].into_iter().collect()),
            input: vec![0.1, 1.0 / 3.0, -7e-300],
            output: vec![0.1, 0.2 + 0.1, -7e-300],
            u: vec![0.1, 0.5, -1.0],
            roles: vec![Role::Min, Role::Other, Role::End],
            filled,
        }
    }

    #[test]
    fn blocks_formatted_on_several_threads_make_the_one_thread_file() {
        // more rows than three threads' blocks, the last round partial
        let n = 3 * ROWS_PER_BLOCK + ROWS_PER_BLOCK / 3 + 7;
        let value = |i: usize, k: f64| ((i as f64) * k).sin() * 10f64.powi((i % 7) as i32 - 3);
        let out = SeriesOutput {
            x_name: "x".into(),
            x_text: XText::Index(n),
            input: (0..n).map(|i| value(i, 0.37)).collect(),
            output: (0..n).map(|i| value(i, 0.11)).collect(),
            u: (0..n).map(|i| i as f64 / n as f64).collect(),
            roles: (0..n).map(|i| if i % 1000 == 0 { Role::Max } else { Role::Other }).collect(),
            filled: Some((0..n).map(|i| i % 5 == 0).collect()),
        };
        let files: Vec<Vec<u8>> = [1, 2, 3]
            .iter()
            .map(|&t| {
                let p = dir().join(format!("threads-{t}.csv"));
                crate::parallel::with_threads(t, || write_series_output(&p, &out)).unwrap();
                std::fs::read(&p).unwrap()
            })
            .collect();
        assert_eq!(files[0], files[1]);
        assert_eq!(files[0], files[2]);
        let back = read_series_output(&dir().join("threads-2.csv")).unwrap();
        assert_eq!(back.input.len(), n);
        assert!(back.input.iter().zip(&out.input).all(|(a, b)| a.to_bits() == b.to_bits()));
        assert!(back.output.iter().zip(&out.output).all(|(a, b)| a.to_bits() == b.to_bits()));
        assert_eq!(back.roles, out.roles);
        assert_eq!(back.x_text.get(n - 1), (n - 1).to_string());
        assert_eq!(back.filled, out.filled);
    }

    #[test]
    fn output_round_trips_bit_for_bit() {
        let p = dir().join("out.csv");
        for out in [
            sample("date", None),
            sample("x", Some(vec![false, true, false])),
            sample("u", None),
            sample("a \"b\", c", None),
        ] {
            write_series_output(&p, &out).unwrap();
            assert_eq!(read_series_output(&p).unwrap(), out);
        }
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(text.starts_with("\"a \"\"b\"\", c\",input,output,u,role\n"), "{text}");
        write_series_output(&p, &sample("when", Some(vec![false, true, false]))).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(text.starts_with("when,input,output,u,role,filled\n2010-01-01,0.1,0.1,0.1,min,0\n"), "{text}");
        // nothing filled: no column
        write_series_output(&p, &sample("when", Some(vec![false; 3]))).unwrap();
        let back = read_series_output(&p).unwrap();
        assert_eq!(back.filled, None);
        assert!(std::fs::read_to_string(&p).unwrap().starts_with("when,input,output,u,role\n"));
    }

    #[test]
    fn an_index_axis_is_written_as_numbers_and_read_back_as_text() {
        let p = dir().join("index.csv");
        let out = SeriesOutput { x_text: XText::Index(3), ..sample("x", None) };
        write_series_output(&p, &out).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(text.starts_with("x,input,output,u,role\n0,0.1,0.1,0.1,min\n1,"), "{text}");
        assert!(text.contains("\n2,-7e-300,"), "{text}");
        let back = read_series_output(&p).unwrap();
        assert_eq!(back.x_text, XText::Text(["0", "1", "2"].into_iter().collect()));
        assert_eq!(back.x_text.to_vec(), out.x_text.to_vec());
        // the read-back check keeps the values only
        let values = read_series_output_with(&p, false).unwrap();
        assert_eq!((values.x_text, values.output), (XText::Index(3), out.output));
    }

    #[test]
    fn older_and_bad_files() {
        let p = dir().join("old.csv");
        std::fs::write(&p, "input,output,u,role\n0,0,0,min\n1,1,1,max\n").unwrap();
        let back = read_series_output(&p).unwrap();
        assert_eq!((back.x_name.as_str(), back.x_text.clone()), ("x", XText::Text(["", ""].into_iter().collect())));
        std::fs::write(&p, "t,input,output,u,role,filled\n0,0,0,0,min,0\n1,1,1,1,max,2\n").unwrap();
        let e = read_series_output(&p).unwrap_err().to_string();
        assert!(e.contains("old.csv") && e.contains("line 3") && e.contains("not 0 or 1"), "{e}");
        std::fs::write(&p, "a,b\n1,2\n").unwrap();
        let e = read_series_output(&p).unwrap_err().to_string();
        assert!(e.contains("old.csv") && e.contains("X,input,output,u,role"), "{e}");
        // cells are trimmed where they are used, and checked as UTF-8 text
        std::fs::write(&p, "x,input,output,u,role\n a , 0.5 ,1,0, min\n1,1,1,1,max \n").unwrap();
        let back = read_series_output(&p).unwrap();
        assert_eq!((back.x_text.get(0), back.input[0], back.roles[0]), ("a".into(), 0.5, Role::Min));
        // past the head the content check reads: the cell's own check
        let mut bytes = b"x,input,output,u,role\n".to_vec();
        for i in 0..100_000 {
            bytes.extend_from_slice(format!("{i},0,0,0,\n").as_bytes());
        }
        bytes.extend_from_slice(b"100000,\xff1,1,1,max\n");
        std::fs::write(&p, bytes).unwrap();
        let e = read_series_output(&p).unwrap_err().to_string();
        assert!(e.contains("line 100002") && e.contains("`input` is not UTF-8"), "{e}");
    }
}
