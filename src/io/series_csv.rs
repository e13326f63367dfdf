//! Series as CSV: the input (header optional, value column by name or index, optional x
//! column of numbers or ISO dates) and the verifiable output `x,input,output,u,role`.

use super::format_f64;
use crate::error::{Error, Result};
use crate::topology::Role;
use chrono::{NaiveDate, NaiveDateTime};
use std::path::Path;

/// How the x coordinate was obtained.
#[derive(Clone, Debug, PartialEq)]
pub enum XSource {
    /// No x column: x = sample index.
    Index,
    /// A numeric column.
    Numeric(String),
    /// A date column, turned into days since the first date.
    Dates(String, NaiveDate),
}

/// A series read from CSV.
#[derive(Clone, Debug, PartialEq)]
pub struct SeriesCsv {
    /// Name of the value column (or its index as text when the file has no header).
    pub column: String,
    /// The values, in file order.
    pub values: Vec<f64>,
    /// x coordinates (days for dates, index without an x column).
    pub x: Vec<f64>,
    /// The x column's original text per row (index without an x column), written back out.
    pub x_text: Vec<String>,
    /// Where x came from.
    pub x_source: XSource,
}

/// Options for [`read_series`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeriesCsvOptions {
    /// Value column: a header name, or a 0-based index. Default: the last numeric column.
    pub column: Option<String>,
    /// x column: a header name or index, or `none`. Default: the first column if it holds
    /// dates or is named x, t, time or date.
    pub x_column: Option<String>,
}

fn parse_number(s: &str) -> Option<f64> {
    let t = s.trim();
    if t.is_empty() {
        return None;
    }
    t.parse::<f64>().ok()
}

/// Days since 1970-01-01 of an ISO date or date-time (`2010-03-01`, `2010-03-01T12:00:00`).
pub fn parse_date_days(s: &str) -> Option<f64> {
    let t = s.trim();
    let epoch = NaiveDate::from_ymd_opt(1970, 1, 1)?;
    if let Ok(d) = NaiveDate::parse_from_str(t, "%Y-%m-%d") {
        return Some((d - epoch).num_days() as f64);
    }
    for fmt in ["%Y-%m-%dT%H:%M:%S", "%Y-%m-%d %H:%M:%S", "%Y-%m-%dT%H:%M", "%Y-%m-%d %H:%M"] {
        if let Ok(dt) = NaiveDateTime::parse_from_str(t, fmt) {
            let secs = (dt - epoch.and_hms_opt(0, 0, 0)?).num_seconds();
            return Some(secs as f64 / 86400.0);
        }
    }
    None
}

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Number,
    Date,
    Text,
    Empty,
}

fn kind(s: &str) -> Kind {
    let t = s.trim();
    if t.is_empty() {
        Kind::Empty
    } else if parse_number(t).is_some() {
        Kind::Number
    } else if parse_date_days(t).is_some() {
        Kind::Date
    } else {
        Kind::Text
    }
}

/// Reads a series from a CSV file.
///
/// # Errors
/// Input errors naming the file and the line: unreadable file, empty file, ragged rows, an
/// unknown column, no numeric column, a missing or non-numeric value, NaN or infinity, x
/// values that do not strictly increase, fewer than 2 samples.
pub fn read_series(path: &Path, options: &SeriesCsvOptions) -> Result<SeriesCsv> {
    let err = |msg: String| Error::input(msg).in_file(path);
    let rows = read_rows(path)?;
    let ncols = rows[0].1.len();
    // a header: a cell that is text where the next row holds a number or a date
    let has_header = rows.len() >= 2
        && (0..ncols)
            .any(|c| kind(&rows[0].1[c]) == Kind::Text && matches!(kind(&rows[1].1[c]), Kind::Number | Kind::Date));
    let names: Vec<String> = if has_header { rows[0].1.clone() } else { (0..ncols).map(|c| c.to_string()).collect() };
    let data = if has_header { &rows[1..] } else { &rows[..] };
    if data.is_empty() {
        return Err(err("the file has a header but no data rows".into()));
    }
    let column_kind = |c: usize| -> Kind {
        let mut k = Kind::Empty;
        for (_, r) in data {
            match (k, kind(&r[c])) {
                (_, Kind::Empty) => {}
                (Kind::Empty, x) => k = x,
                (a, b) if a == b => {}
                (Kind::Number, Kind::Text) | (Kind::Text, Kind::Number) => {
                    // NaN / inf spelled as text count as numbers; anything else makes it text
                    return Kind::Text;
                }
                _ => return Kind::Text,
            }
        }
        k
    };
    let kinds: Vec<Kind> = (0..ncols).map(column_kind).collect();
    let find = |spec: &str| -> Result<usize> {
        if let Some(c) = names.iter().position(|n| n == spec) {
            return Ok(c);
        }
        match spec.parse::<usize>() {
            Ok(c) if c < ncols => Ok(c),
            _ => Err(err(format!("no column `{spec}` (columns: {})", names.join(", ")))),
        }
    };
    let explicit_x = match options.x_column.as_deref() {
        Some("none") | None => None,
        Some(spec) => Some(find(spec)?),
    };
    let value_col = match &options.column {
        Some(spec) => find(spec)?,
        None => (0..ncols).rev().find(|&c| kinds[c] == Kind::Number && Some(c) != explicit_x).ok_or_else(|| {
            err(format!("no numeric column (columns: {}); choose the value column by name or index", names.join(", ")))
        })?,
    };
    let x_col = match options.x_column.as_deref() {
        Some("none") => None,
        Some(spec) => Some(find(spec)?),
        None => {
            let named = ["x", "t", "time", "date"].contains(&names[0].to_ascii_lowercase().as_str()) && has_header;
            (value_col != 0 && (kinds[0] == Kind::Date || (named && kinds[0] == Kind::Number))).then_some(0)
        }
    };
    if x_col == Some(value_col) {
        return Err(err(format!("the x column and the value column are both `{}`", names[value_col])));
    }
    let values = values_of(path, data, value_col, &names[value_col])?;
    let (x, x_text, x_source) = match x_col {
        None => (
            (0..values.len()).map(|i| i as f64).collect(),
            (0..values.len()).map(|i| i.to_string()).collect(),
            XSource::Index,
        ),
        Some(c) => x_of(path, data, &names[c], c, kinds[c] == Kind::Date)?,
    };
    if values.len() < 2 {
        return Err(err(format!("a series needs at least 2 samples, found {}", values.len())));
    }
    Ok(SeriesCsv { column: names[value_col].clone(), values, x, x_text, x_source })
}

/// One CSV row: its line in the file and its cells.
type Row = (u64, Vec<String>);

/// The non-empty rows of a CSV file (UTF-8, a byte-order mark dropped), with their lines.
fn read_rows(path: &Path) -> Result<Vec<Row>> {
    let err = |msg: String| Error::input(msg).in_file(path);
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let text =
        String::from_utf8(bytes).map_err(|e| err(format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to())))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let mut reader = csv::ReaderBuilder::new().has_headers(false).trim(csv::Trim::All).from_reader(text.as_bytes());
    let mut rows: Vec<Row> = Vec::new();
    for rec in reader.records() {
        let rec = rec.map_err(|e| err(format!("malformed CSV: {e}")))?;
        let line = rec.position().map(|p| p.line()).unwrap_or(0);
        if rec.iter().all(|c| c.is_empty()) {
            continue;
        }
        rows.push((line, rec.iter().map(str::to_string).collect()));
    }
    if rows.is_empty() {
        return Err(err("the file is empty".into()));
    }
    Ok(rows)
}

/// The values of column `col` (named `name`): numbers, finite.
fn values_of(path: &Path, data: &[Row], col: usize, name: &str) -> Result<Vec<f64>> {
    let err = |msg: String| Error::input(msg).in_file(path);
    let mut values = Vec::with_capacity(data.len());
    for (line, r) in data {
        let cell = &r[col];
        let v = parse_number(cell).ok_or_else(|| {
            if cell.trim().is_empty() {
                err(format!("line {line}: missing value in column `{}`", name))
                    .at(crate::error::Location::Line(*line as usize))
            } else {
                err(format!("line {line}: `{cell}` in column `{}` is not a number", name))
                    .at(crate::error::Location::Line(*line as usize))
            }
        })?;
        if !v.is_finite() {
            return Err(err(format!("line {line}: value {v} in column `{}` is not finite", name))
                .at(crate::error::Location::Line(*line as usize)));
        }
        values.push(v);
    }
    Ok(values)
}

/// The x axis from column `c` (named `name`): dates (days since 1970) or numbers, strictly
/// increasing, with their text.
fn x_of(path: &Path, data: &[Row], name: &str, c: usize, dates: bool) -> Result<(Vec<f64>, Vec<String>, XSource)> {
    let err = |msg: String| Error::input(msg).in_file(path);
    let mut x = Vec::with_capacity(data.len());
    let mut text = Vec::with_capacity(data.len());
    for (line, r) in data {
        let cell = r[c].trim();
        let v = if dates { parse_date_days(cell) } else { parse_number(cell) }.filter(|v| v.is_finite());
        let v = v.ok_or_else(|| {
            err(format!(
                "line {line}: `{cell}` in x column `{}` is not a {}",
                name,
                if dates { "date" } else { "finite number" }
            ))
        })?;
        x.push(v);
        text.push(cell.to_string());
    }
    if let Some(i) = (1..x.len()).find(|&i| x[i] <= x[i - 1]) {
        return Err(err(format!(
            "line {}: x column `{}` must strictly increase, but `{}` follows `{}`",
            data[i].0,
            name,
            text[i],
            text[i - 1]
        )));
    }
    let source = if dates {
        let first = NaiveDate::from_ymd_opt(1970, 1, 1).expect("valid") + chrono::Duration::days(x[0].floor() as i64);
        XSource::Dates(name.to_string(), first)
    } else {
        XSource::Numeric(name.to_string())
    };
    Ok((x, text, source))
}

/// The verifiable output of `smooth` on a series.
#[derive(Clone, Debug, PartialEq)]
pub struct SeriesOutput {
    /// x as text (dates stay dates).
    pub x_text: Vec<String>,
    /// The input values actually smoothed.
    pub input: Vec<f64>,
    /// The certified output.
    pub output: Vec<f64>,
    /// The representative function.
    pub u: Vec<f64>,
    /// Role per sample.
    pub roles: Vec<Role>,
}

/// Writes `x,input,output,u,role` atomically, doubles in shortest round-trip form.
pub fn write_series_output(path: &Path, out: &SeriesOutput) -> Result<()> {
    stage_series_output(path, out)?.commit()
}

/// Stages the file of [`write_series_output`] (see [`super::Staged`]).
pub fn stage_series_output(path: &Path, out: &SeriesOutput) -> Result<super::Staged> {
    super::stage(path, |w| {
        writeln!(w, "x,input,output,u,role")?;
        for i in 0..out.input.len() {
            writeln!(
                w,
                "{},{},{},{},{}",
                csv_cell(&out.x_text[i]),
                format_f64(out.input[i]),
                format_f64(out.output[i]),
                format_f64(out.u[i]),
                out.roles[i].label()
            )?;
        }
        Ok(())
    })
}

fn csv_cell(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Reads a file written by [`write_series_output`].
///
/// # Errors
/// Input errors naming the file and line: missing columns, unparsable numbers, unknown roles.
pub fn read_series_output(path: &Path) -> Result<SeriesOutput> {
    let err = |msg: String| Error::input(msg).in_file(path);
    let file = std::fs::File::open(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let mut reader = csv::ReaderBuilder::new().has_headers(true).trim(csv::Trim::All).from_reader(file);
    let header = reader.headers().map_err(|e| err(format!("malformed CSV: {e}")))?.clone();
    let col = |name: &str| {
        header.iter().position(|h| h == name).ok_or_else(|| {
            err(format!("no `{name}` column: a verifiable series file has the header x,input,output,u,role"))
        })
    };
    let (ci, co, cu, cr) = (col("input")?, col("output")?, col("u")?, col("role")?);
    let cx = header.iter().position(|h| h == "x");
    let mut out = SeriesOutput { x_text: vec![], input: vec![], output: vec![], u: vec![], roles: vec![] };
    for rec in reader.records() {
        let rec = rec.map_err(|e| err(format!("malformed CSV: {e}")))?;
        let line = rec.position().map(|p| p.line()).unwrap_or(0);
        let num = |c: usize, name: &str| -> Result<f64> {
            let cell = rec.get(c).unwrap_or("");
            cell.parse::<f64>().map_err(|_| {
                err(format!("line {line}: `{cell}` in column `{name}` is not a number"))
                    .at(crate::error::Location::Line(line as usize))
            })
        };
        out.input.push(num(ci, "input")?);
        out.output.push(num(co, "output")?);
        out.u.push(num(cu, "u")?);
        let role = rec.get(cr).unwrap_or("");
        out.roles.push(Role::from_label(role).ok_or_else(|| {
            err(format!("line {line}: unknown role `{role}` (min, max, fixed, end or empty)"))
                .at(crate::error::Location::Line(line as usize))
        })?);
        out.x_text.push(cx.and_then(|c| rec.get(c)).unwrap_or("").to_string());
    }
    if out.input.len() < 2 {
        return Err(err(format!("a series needs at least 2 samples, found {}", out.input.len())));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str, content: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("toposmooth-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, content).unwrap();
        p
    }

    #[test]
    fn dates_headers_and_default_column() {
        let p = tmp("a.csv", "date,a,b,label\n2010-03-01,1,10,x\n2010-03-02,2,20,y\n2010-03-05,3,30,z\n");
        let s = read_series(&p, &SeriesCsvOptions::default()).unwrap();
        assert_eq!(s.column, "b");
        assert_eq!(s.values, vec![10.0, 20.0, 30.0]);
        assert_eq!(s.x[1] - s.x[0], 1.0);
        assert_eq!(s.x[2] - s.x[1], 3.0);
        assert!(matches!(s.x_source, XSource::Dates(_, d) if d == NaiveDate::from_ymd_opt(2010, 3, 1).unwrap()));
        let s = read_series(&p, &SeriesCsvOptions { column: Some("a".into()), ..Default::default() }).unwrap();
        assert_eq!(s.values, vec![1.0, 2.0, 3.0]);
        let s = read_series(&p, &SeriesCsvOptions { column: Some("1".into()), x_column: Some("none".into()) }).unwrap();
        assert_eq!((s.values.clone(), s.x_source), (vec![1.0, 2.0, 3.0], XSource::Index));
    }

    #[test]
    fn headerless_single_column() {
        let p = tmp("b.csv", "1.5\n-2\n3e-3\n");
        let s = read_series(&p, &SeriesCsvOptions::default()).unwrap();
        assert_eq!(s.values, vec![1.5, -2.0, 3e-3]);
        assert_eq!(s.x, vec![0.0, 1.0, 2.0]);
    }

    #[test]
    fn errors_name_file_and_line() {
        let cases = [
            ("empty.csv", "", "empty"),
            ("nan.csv", "v\n1\nNaN\n3\n", "line 3"),
            ("missing.csv", "v,w\n1,2\n3,\n4,5\n", "line 3"),
            ("ragged.csv", "a,b\n1,2\n3\n", "malformed"),
            ("dup.csv", "date,v\n2010-01-01,1\n2010-01-01,2\n", "strictly increase"),
            ("one.csv", "v\n1\n", "at least 2"),
            ("text.csv", "a,b\nx,y\nz,w\n", "no numeric column"),
        ];
        for (name, content, needle) in cases {
            let p = tmp(name, content);
            let e = read_series(&p, &SeriesCsvOptions::default()).unwrap_err();
            let msg = e.to_string();
            assert!(msg.contains(name) && msg.contains(needle), "{name}: {msg}");
            assert_eq!(e.exit_code(), 3);
            if needle == "line 3" {
                assert_eq!(e.location(), Some(crate::error::Location::Line(3)), "{name}");
            }
        }
        let p = tmp("c.csv", "a\n1\n2\n");
        let e = read_series(&p, &SeriesCsvOptions { column: Some("zz".into()), ..Default::default() }).unwrap_err();
        assert!(e.to_string().contains("no column `zz`"));
    }

    #[test]
    fn output_round_trips_bit_for_bit() {
        let out = SeriesOutput {
            x_text: vec!["2010-01-01".into(), "2010-01-04".into(), "a,b".into()],
            input: vec![0.1, 1.0 / 3.0, -7e-300],
            output: vec![0.1, 0.2 + 0.1, -7e-300],
            u: vec![0.1, 0.5, -1.0],
            roles: vec![Role::Min, Role::Other, Role::End],
        };
        let dir = std::env::temp_dir().join(format!("toposmooth-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("out.csv");
        write_series_output(&p, &out).unwrap();
        let back = read_series_output(&p).unwrap();
        assert_eq!(back, out);
    }
}
